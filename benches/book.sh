#!/usr/bin/env bash
# Times hitkit's examples against the book's own C++ ("Ray Tracing: The Next Week" and "The
# Rest of Your Life"), built from a checkout of its repository, in one run and in
# alternation (book, hitkit on one thread, hitkit on every core, then the next scene, round
# after round), and prints a Markdown table of medians and per-round ratios.
#
#   benches/book.sh BOOK
#
# BOOK is a checkout of https://github.com/RayTracing/raytracing.github.io, or its bare git
# directory. Nothing of the book's code enters this repository: its sources are copied into
# a temporary directory, the scene is picked there (The Next Week's main() renders the scene
# its `switch` names), and built with `g++ -O3`. The image sizes, samples and depths are
# read from the book's scene functions and passed to hitkit's examples, so both render the
# same image. The book's renderer runs on one thread.
#
# Scenes:
# - quads: The Next Week's quads() against `--example quads --roulette no` (the book
#   ends paths at the depth limit alone).
# - Cornell, like for like: The Rest of Your Life's main() (a tall box and a glass sphere,
#   the lamp and the sphere sampled as lights, no Russian roulette) against
#   `--example cornell_book`.
# - Cornell, hitkit's own: `--example cornell` (two boxes, the lamp sampled, Russian
#   roulette) at the same size, beside the book's main() again: not the same scene or
#   the same number of rays, so its ratio says what hitkit's choices buy, not who is faster.
#
# Environment: ROUNDS (default 3), CXX (default g++), CXXFLAGS (default -O3).
set -euo pipefail

if [ $# -ne 1 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,26p' "$0" | sed 's/^# \{0,1\}//'
    [ $# -eq 1 ] && exit 0 || exit 2
fi
book="$1"
rounds="${ROUNDS:-3}"
cxx="${CXX:-g++}"
cxxflags="${CXXFLAGS:--O3}"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

die() {
    echo "book.sh: $*" >&2
    exit 1
}

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# The book's sources and commit, from a work tree or a git directory.
if [ -d "$book/src/TheNextWeek" ]; then
    cp -r "$book/src" "$work/src"
    commit="$(git -C "$book" rev-parse --short HEAD 2>/dev/null || echo "unknown commit")"
elif git --git-dir="$book" rev-parse --verify -q HEAD >/dev/null 2>&1; then
    git --git-dir="$book" archive HEAD src | tar -x -C "$work"
    commit="$(git --git-dir="$book" rev-parse --short HEAD)"
else
    die "$book is neither a checkout of raytracing.github.io nor its git directory"
fi
next="$work/src/TheNextWeek"
rest="$work/src/TheRestOfYourLife"
[ -f "$next/main.cc" ] && [ -f "$rest/main.cc" ] || die "no src/TheNextWeek or src/TheRestOfYourLife in $book"

# `setting FILE FUNCTION NAME`: the number the book assigns to `cam.NAME` in FUNCTION.
setting() {
    awk -v fn="$2" -v name="$3" '
        $0 ~ "^(void|int) " fn "\\(" { inside = 1 }
        inside && $0 ~ "cam\\." name " *=" {
            sub(/.*= */, ""); sub(/;.*/, ""); print; exit
        }
        inside && /^}/ { inside = 0 }
    ' "$1"
}

# The Next Week renders the scene its main() switches on: pick quads().
case_number="$(sed -n 's/^ *case \([0-9]*\): *quads(); *break;.*/\1/p' "$next/main.cc")"
[ -n "$case_number" ] || die "cannot find quads() among The Next Week's scenes"
sed -i "s/switch *([0-9]*)/switch ($case_number)/" "$next/main.cc"
grep -q "switch ($case_number)" "$next/main.cc" || die "cannot select quads() in The Next Week's main()"

echo "Building the book ($commit) with $cxx $cxxflags ..." >&2
"$cxx" $cxxflags -I"$work/src" -o "$work/book_quads" "$next/main.cc"
"$cxx" $cxxflags -I"$work/src" -o "$work/book_cornell" "$rest/main.cc"
echo "Building hitkit's examples ..." >&2
(cd "$repo" && cargo build --release --quiet --example quads --example cornell_book --example cornell)
examples="$repo/target/release/examples"

# The book's settings, passed to hitkit's examples.
q_width="$(setting "$next/main.cc" quads image_width)"
q_samples="$(setting "$next/main.cc" quads samples_per_pixel)"
q_depth="$(setting "$next/main.cc" quads max_depth)"
c_width="$(setting "$rest/main.cc" main image_width)"
c_samples="$(setting "$rest/main.cc" main samples_per_pixel)"
c_depth="$(setting "$rest/main.cc" main max_depth)"
for v in "$q_width" "$q_samples" "$q_depth" "$c_width" "$c_samples" "$c_depth"; do
    [[ "$v" =~ ^[0-9]+$ ]] || die "cannot read the book's camera settings (got '$v')"
done
quads_args=(--width "$q_width" --samples "$q_samples" --depth "$q_depth" --roulette no)
cornell_args=(--width "$c_width" --samples "$c_samples" --depth "$c_depth")

# `seconds COMMAND...`: runs it (output discarded) and prints its wall time in seconds.
seconds() {
    local start end
    start="$(date +%s.%N)"
    "$@" >/dev/null 2>&1 || die "failed: $*"
    end="$(date +%s.%N)"
    awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f\n", b - a }'
}

declare -A times
runs=(
    "quads/book" "quads/hitkit1" "quads/hitkit"
    "cornell/book" "cornell/hitkit1" "cornell/hitkit"
    "own/hitkit1" "own/hitkit"
)
for run in "${runs[@]}"; do times[$run]=""; done
image="$work/image"
for round in $(seq 1 "$rounds"); do
    echo "Round $round of $rounds ..." >&2
    times[quads/book]+=" $(seconds sh -c "'$work/book_quads' > '$image.ppm'")"
    times[quads/hitkit1]+=" $(seconds "$examples/quads" "${quads_args[@]}" --threads 1 --output "$image.png")"
    times[quads/hitkit]+=" $(seconds "$examples/quads" "${quads_args[@]}" --output "$image.png")"
    times[cornell/book]+=" $(seconds sh -c "'$work/book_cornell' > '$image.ppm'")"
    times[cornell/hitkit1]+=" $(seconds "$examples/cornell_book" "${cornell_args[@]}" --threads 1 --output "$image.png")"
    times[cornell/hitkit]+=" $(seconds "$examples/cornell_book" "${cornell_args[@]}" --output "$image.png")"
    times[own/hitkit1]+=" $(seconds "$examples/cornell" "${cornell_args[@]}" --threads 1 --output "$image.png")"
    times[own/hitkit]+=" $(seconds "$examples/cornell" "${cornell_args[@]}" --output "$image.png")"
done

# `median LIST`: the median of whitespace-separated numbers.
median() {
    tr ' ' '\n' <<<"$1" | sed '/^$/d' | sort -g | awk '{ v[NR] = $1 } END {
        if (NR % 2) printf "%.2f", v[(NR + 1) / 2]; else printf "%.2f", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}
# `ratios A B`: the per-round ratios A[i] / B[i], space-separated.
ratios() {
    paste <(tr ' ' '\n' <<<"$1" | sed '/^$/d') <(tr ' ' '\n' <<<"$2" | sed '/^$/d') |
        awk '{ printf " %.3f", $1 / $2 }'
}
row() {
    local name="$1" key="$2" book_key="$3"
    local book_times="${times[$book_key/book]}"
    local one="${times[$key/hitkit1]}" all="${times[$key/hitkit]}"
    local r1 rall
    r1="$(ratios "$one" "$book_times")"
    rall="$(ratios "$all" "$book_times")"
    printf '| %s | %s s (%s) | %s s (%s) | %s | %s s (%s) | %s |\n' \
        "$name" \
        "$(median "$book_times")" "$(echo $book_times | sed 's/ /, /g')" \
        "$(median "$one")" "$(echo $one | sed 's/ /, /g')" \
        "$(median "$r1")" \
        "$(median "$all")" "$(echo $all | sed 's/ /, /g')" \
        "$(median "$rall")"
}

cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
cores="$(nproc)"
hitkit_rev="$(git -C "$repo" rev-parse --short HEAD)$(git -C "$repo" diff --quiet HEAD -- . 2>/dev/null || echo '+changes')"
echo
echo "$cpu, $cores cores; the book at $commit ($cxx $cxxflags, one thread), hitkit at $hitkit_rev; $rounds rounds in alternation; medians (each run's time in brackets); ratios are medians of the per-round hitkit/book ratios."
echo
echo "| scene | book, 1 thread | hitkit, \`--threads 1\` | hitkit/book | hitkit, $cores threads | hitkit/book |"
echo "|---|---:|---:|---:|---:|---:|"
row "quads, ${q_width}x${q_width}, $q_samples spp, depth $q_depth, no roulette" quads quads
row "Cornell like for like (the book's final scene, no roulette), ${c_width}x${c_width}, $c_samples spp, depth $c_depth" cornell cornell
row "Cornell, hitkit's own (two boxes, roulette) against the book's final scene: not like for like" own cornell
