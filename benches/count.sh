#!/usr/bin/env bash
# Instructions a ray, by callgrind (deterministic, unlike a time on a shared machine): each
# library of the triad traces each ray set once (`hitkit-peers --triad --count`), and
# callgrind counts only inside the functions that trace the sets.
#
#   benches/count.sh [LIBRARY...] [-- peers options...]
#
#   SCENES="bunny skylight" benches/count.sh "hitkit TriangleMesh" Embree -- --side 200
#
# LIBRARY is text in a library's name, as `--only` takes it (default: hitkit's mesh and its
# generic tree, obvhs on its own triangles, and Embree where the build has it). Prints a
# Markdown table: scene, library, then instructions a ray for primary, bounce and shadow
# rays, and for the camera's rays turned around, which miss the scene's box: what a query
# costs before its walk (its fixed cost). SCENES (default "bunny skylight") names the scenes, each text in one scene's name
# (as `--scene` takes it), each counted in a run of its own. Needs valgrind; the Embree rows need `apt-get install libembree-dev` (the bench is
# then built with `--features embree`).
set -euo pipefail

libs=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    libs+=("$1")
    shift
done
[ "${1:-}" = "--" ] && shift
options=("$@")
features=()
if [ -e /usr/include/embree3/rtcore.h ]; then
    features=(--features embree)
fi
if [ ${#libs[@]} -eq 0 ]; then
    libs=("hitkit TriangleMesh" "hitkit Bvh" "obvhs 0.4 CWBVH medium, own" )
    [ ${#features[@]} -gt 0 ] && libs+=("Embree")
fi
top=$(git rev-parse --show-toplevel)
cd "$top"
cargo build --release -p hitkit-peers "${features[@]}" >&2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| scene | library | primary | bounce | shadow | missing the scene |"
echo "|---|---|---:|---:|---:|---:|"
for scene in ${SCENES:-bunny skylight}; do
for lib in "${libs[@]}"; do
    out="$work/callgrind.out"
    valgrind --tool=callgrind --callgrind-out-file="$out" \
        --toggle-collect='*count_primary*' --toggle-collect='*count_bounce*' \
        --toggle-collect='*count_shadow*' --toggle-collect='*count_miss*' \
        target/release/hitkit-peers --triad --count --only "$lib" --sphere 0 --crowd 0 \
        --scene "$scene" "${options[@]}" 2> "$work/log" > /dev/null || { cat "$work/log" >&2; exit 1; }
    # Rays per set and scene, as the bench printed them while it ran.
    callgrind_annotate --inclusive=yes --threshold=100 "$out" > "$work/annotated"
    python3 - "$work/log" "$work/annotated" "$lib" <<'EOF'
import re, sys
log, annotated, lib = sys.argv[1:]
# The bench prints "counting<TAB>scene<TAB>library<TAB>p b s" before each scene's passes;
# callgrind's totals are per function over all scenes, so one scene a run is counted.
scenes = [l.rstrip("\n").split("\t")[1:] for l in open(log) if l.startswith("counting\t")]
costs = {}
for line in open(annotated):
    found = re.match(r"\s*([\d,]+) \([^)]*\)\s+\*?\s*\S*::(count_\w+)\b", line)
    if found:
        costs[found.group(2)] = int(found.group(1).replace(",", ""))
if len(scenes) != 1:
    sys.exit(f"count.sh: one scene a run, please (--scene); this run had {len(scenes)}")
name, lib, rays = scenes[0]
p, b, s, m = (int(x) for x in rays.split())
cells = [costs.get(f, 0) / max(n, 1) for f, n in
         (("count_primary", p), ("count_bounce", b), ("count_shadow", s), ("count_miss", m))]
print(f"| {name} | {lib} | " + " | ".join(f"{c:,.0f}" for c in cells) + " |")
EOF
done
done
