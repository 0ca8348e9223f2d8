#!/bin/bash
# The instructions a software driver (lavapipe) runs for one benchmark case: a count that
# does not depend on how busy the machine is, for A/B trials of kernel variants where the
# wall clock and even the CPU time of a shared machine wander by 10–30% between runs.
#
#   benches/instructions.sh [-s SIZE] [-d KERNEL_DIR]... CASE
#
# Runs `examples/kernel_wall --exact --no-copy --repeat 1 --sizes SIZE CASE` (two warm-up
# runs and one timed: three runs of the case's plan) under valgrind's callgrind, once for each
# -d folder of `.wgsl` replacements (as SHADOWGRAPH_KERNEL_DIR reads one; `shipped`, the
# default, for the embedded kernels), two at a time, and prints the instructions of the code
# llvmpipe compiled (the functions callgrind finds in no object file: the kernels, the only
# JIT code a compute dispatch runs), per output texel (÷ 3·SIZE²), and each variant's ratio
# to the first. Needs valgrind (`apt-get install valgrind`); about a minute a variant, most of
# it LLVM compiling the kernels under valgrind. An instruction count is no time: memory
# stalls and the CPU's parallelism are not in it, so confirm a win with `kernel_wall --cpu
# --min` rounds alternated (benches/RESULTS.md, 2026-11-28: −17% instructions and
# 1.11–1.23× less CPU time for the VSM strips).
set -euo pipefail
size=512
dirs=()
while getopts "s:d:" opt; do
    case $opt in
        s) size=$OPTARG ;;
        d) dirs+=("$OPTARG") ;;
        *) echo "usage: $0 [-s SIZE] [-d KERNEL_DIR]... CASE" >&2; exit 2 ;;
    esac
done
shift $((OPTIND - 1))
if [ $# -ne 1 ]; then
    echo "usage: $0 [-s SIZE] [-d KERNEL_DIR]... CASE (one case, named exactly)" >&2
    exit 2
fi
case_name=$1
[ ${#dirs[@]} -gt 0 ] || dirs=(shipped)
command -v valgrind > /dev/null || { echo "$0: valgrind is not installed" >&2; exit 1; }
cd "$(dirname "$0")/.."
cargo build --release --example kernel_wall --quiet
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

count() { # index folder
    local out="$work/$1"
    if [ "$2" = shipped ]; then
        env -u SHADOWGRAPH_KERNEL_DIR valgrind --tool=callgrind --smc-check=all-non-file \
            --callgrind-out-file="$out.cg" ./target/release/examples/kernel_wall --exact \
            --no-copy --repeat 1 --sizes "$size" "$case_name" > "$out.log" 2>&1
    else
        SHADOWGRAPH_KERNEL_DIR=$2 valgrind --tool=callgrind --smc-check=all-non-file \
            --callgrind-out-file="$out.cg" ./target/release/examples/kernel_wall --exact \
            --no-copy --repeat 1 --sizes "$size" "$case_name" > "$out.log" 2>&1
    fi || { echo "$0: $2: kernel_wall failed: $(grep -m1 '^error' "$out.log")" >&2; return 1; }
    callgrind_annotate --inclusive=no --threshold=100 "$out.cg" \
        | awk '/\[\?\?\?\]$/ { gsub(",", "", $1); n += $1 } END { printf "%.0f\n", n }' > "$out.n"
}

for i in "${!dirs[@]}"; do
    count "$i" "${dirs[$i]}" &
    if (( i % 2 == 1 )); then wait; fi
done
wait
for i in "${!dirs[@]}"; do
    [ -s "$work/$i.n" ] || exit 1
done

texels=$(( 3 * size * size ))
first=$(cat "$work/0.n")
printf '%-40s %16s %12s %8s\n' "kernels ($case_name, $size², 3 runs)" "instructions" "per texel" "ratio"
for i in "${!dirs[@]}"; do
    n=$(cat "$work/$i.n")
    awk -v d="${dirs[$i]}" -v n="$n" -v t="$texels" -v f="$first" \
        'BEGIN { printf "%-40s %16.0f %12.1f %8.3f\n", d, n, n / t, n / f }'
done
