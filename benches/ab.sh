#!/usr/bin/env bash
# Builds one program at two revisions of this repository and runs the two builds in
# alternation, A B A B ..., so that both see the same state of a shared, noisy machine.
#
#   benches/ab.sh REV_A REV_B peers [peers options...]
#       the peers comparison (benches/peers); prints each run's rows of hitkit's two trees
#       (with --triad, each run's rows of hitkit's libraries in the speed table)
#       (`hitkit`, the generic `Bvh`, and `hitkit TriangleMesh`)
#   benches/ab.sh REV_A REV_B EXAMPLE [example options...]
#       an example (quads, cornell, ...); prints each run's wall time in seconds
#
#   ROUNDS=3 benches/ab.sh 2a10e80 HEAD quads --threads 1
#
# ROUNDS (default 3) is how many times each build runs. Both builds happen before the first
# run, in worktrees under a temporary directory removed at the end; nothing else should
# compile or run meanwhile if the figures are to mean anything. Example output images go to
# that directory too.
set -euo pipefail

if [ $# -lt 3 ]; then
    sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
a=$1
b=$2
what=$3
shift 3
rounds=${ROUNDS:-3}
top=$(git rev-parse --show-toplevel)
work=$(mktemp -d)
trap 'git -C "$top" worktree remove --force "$work/a" >/dev/null 2>&1 || true;
      git -C "$top" worktree remove --force "$work/b" >/dev/null 2>&1 || true;
      rm -rf "$work"' EXIT

for side in a b; do
    rev=$a
    [ "$side" = b ] && rev=$b
    git -C "$top" worktree add --detach "$work/$side" "$rev" >/dev/null 2>&1
    echo "building $what at $rev" >&2
    if [ "$what" = peers ]; then
        (cd "$work/$side" && cargo build --release --quiet -p hitkit-peers)
    else
        (cd "$work/$side" && cargo build --release --quiet --example "$what")
    fi
done

for round in $(seq 1 "$rounds"); do
    for side in a b; do
        rev=$a
        [ "$side" = b ] && rev=$b
        if [ "$what" = peers ]; then
            echo "round $round, $rev:"
            "$work/$side/target/release/hitkit-peers" \
                --obj "$top/../shared/data/stanford-bunny.obj" "$@" 2>/dev/null |
                grep -E '^\| [^|]+\| ([0-9]+ \| hitkit( TriangleMesh)? \||hitkit[^|]*\|( [0-9.]+( \([^)]*\))? \|){3}$)' || true
        else
            start=$(date +%s.%N)
            "$work/$side/target/release/examples/$what" "$@" --output "$work/$what-$side.png" >/dev/null 2>&1
            end=$(date +%s.%N)
            echo "round $round, $rev: $(echo "$end - $start" | bc) s"
        fi
    done
done
