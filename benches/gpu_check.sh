#!/bin/bash
# The device checks to run first when a GPU is lent, in one call of at most about 450 s (the
# machine's start, about 50 s, included): the evaluation's fronts, then the kernel decisions.
# From the repository root, after `cargo build --release`:
#
#   benches/gpu_check.sh [BINARY] [OUT]     # defaults: target/release/shadowgraph, gpu-out
#
# Each step runs under its own time box (`timeout`) and appends to a file of OUT (env, steps,
# evaluate, kernels, buffers, checks: six, the device tool brings back eight), so a call cut
# off by its end still returns what ran; steps.txt says how long each took and its status.
# Older steps (the soft table, shading shapes, kernel-folder variants, workgroup memory zeroed,
# timer cross-checks, cascades, a second binary) are benches/gpu_more.sh, for a second call.
#
# In order, with their boxes (381 s of steps at most, env included):
#   a. `evaluate` at 1920×1080 on three scenes (sphere_on_plane, bunny, colonnade), one map
#      size (2048²), the techniques hard, pcss, vsm, msm, vssm, msm_soft (the fronts' main
#      rows; the other techniques are evaluated by gpu_more.sh), 37 s a scene: 111 s.
#   b. the kernel decisions, 235 s: every benchmark case in the `gpu` and `redesign` kernel
#      layouts side by side (`bench --layouts gpu,redesign --passes`: the redesigned
#      encodings, blur row pass, mip chain, summed-area tables and fused encode+blur all run
#      in both), each size its own process, the buffer copy and both texture copies first in
#      each (the roofline rows): 4096² (80 s), then 8192² (125 s); then the intermediates in
#      storage buffers against textures (`--layouts redesign,redesign-textures`, the blurs'
#      two passes and the tables' edges and carries, 4096²: 25 s); then the shader modules
#      with and without wgpu's runtime checks (`--kernel-dirs shipped,unchecked` in the
#      redesign layout, 4096², the encodings, blurs, mips and tables: 15 s).
#   c. the redesign's maps against the GPU layout's on this device, bit for bit (five
#      technique scenes dumped in both layouts: 15 s). The kernel decisions, b and c: 260 s.
#
# A dry run on a CPU driver (every step at small sizes, to check that each one works):
#
#   SIZES=256,512 nice -n 19 benches/gpu_check.sh target/release/shadowgraph /tmp/dry
#
# SIZES replaces 4096,8192 (first the 80 s step's, then the 125 s step's size); with SIZES
# set, `evaluate` runs `--quick` (its own small image and map) and the kernel steps repeat 2
# times, each box BOX_SCALE (default 4) times longer, for a CPU driver's speed.
#
# Reading the results (decided before the run, so that a lent GPU's time goes to the change):
# - evaluate.txt, the soft target: per scene, `vssm`'s prefilter passes (its 2048² table
#   build, redone every frame for a moving light) plus its `shade` pass against `pcss 16+32`'s
#   `shade` pass, at 1920×1080: met where the sum is the smaller in all three scenes (the
#   reports' per-pass medians; a configuration the clock check flags is read from its
#   second measurement).
# - Roofline (kernels.txt, every row's `roof`: its minimal traffic, one read of its inputs and
#   one write of its outputs, at the buffer copy's GB/s over its time; 1.00 = the buffer
#   copy's speed). The targets: every encode, blur pass, fused chain and mip chain ≥ 0.70 at
#   4096² and 8192², the summed-area tables ≥ 0.50. A row below its target at both sizes in
#   both layouts is the next kernel to redesign.
# - `copy texture x4` against `copy texture x1` (same format, same size): x4 ≥ 0.70 roof
#   (r32float, rgba32float) says the texture path reaches the memory's speed with loads in
#   flight, and the one-texel kernels are latency-bound: every kernel's redesign gives an
#   invocation several texels. x4 < 0.50 says the texture path itself is the limit: the maps
#   move to storage buffers (a kernel's roofline is then the buffer copy's, not x4's).
# - `<case> [redesign]` against `<case> [gpu]`, per case, at both sizes: a redesign ships into
#   `exec::KernelLayout::Gpu` (its REDESIGN branch becomes the GPU_LAYOUT one) where it is
#   faster by 3% or more at 4096² and at 8192² in every case that runs its kernel (the
#   encodings: linearize, vsm, evsm4, esm, msm, csm and the `chain … (depth → …)` rows;
#   the blur row pass: `blur …`; the mip chain: `mips`; the tables: `sat …`, `chain … table`;
#   the fused blurs: `…_blur …`), and its roof reaches the target where the shipped kernel's
#   did not, or gains 0.05; slower in any of them: it stays in the redesign layout.
#   Within 3% either way: the simpler kernel stays (the shipped one).
# - buffers.txt, `<case> [redesign]` (intermediates in row-major storage buffers: the blur's
#   row output, the tables' edges and carries) against `<case> [redesign-textures]` (in
#   textures), the passes that write or read them summed (`blur_h` + `blur_v`; a table's
#   `.tile_sums` + `.carries` + its last pass): intermediates move to storage buffers
#   (`KernelLayout::buffers_intermediates` becomes the GPU layout's) where that sum is 3% or
#   more faster in every case at 4096²; slower in any: they stay textures. Within 3%:
#   textures (one path for every resource). The blurs and the tables may decide apart.
# - kernels.txt, the tables' `.carries` pass rows (`sat fixed`, `sat float`, `chain vssm`,
#   `chain msm_soft`, `chain cssm 8 terms`), `[redesign]` (`kernels/sat_carries_scan.wgsl`,
#   8 lanes a line) against `[gpu]` (a line an invocation): the scan ships where its
#   `.carries` row is 3% or more faster at 4096² and 8192² in every one of them (the table
#   totals mix the tile passes' redesign in); slower in any: the serial carries stay.
# - checks.txt, `[unchecked]` against `[shipped]` (both in the redesign layout): wgpu's runtime
#   checks cost a kernel where its unchecked row is 5% or more faster at 4096²; that kernel's
#   loops over private arrays are rewritten with constant indices (unrolled by hand, which
#   naga need not bound) and measured again. Unchecked modules never ship as a default.
set -u
B=${1:-target/release/shadowgraph}
OUT=${2:-gpu-out}
mkdir -p "$OUT"
export SHADOWGRAPH_MEMORY_BUDGET=${SHADOWGRAPH_MEMORY_BUDGET:-48GiB}
unset SHADOWGRAPH_KERNEL_DIR SHADOWGRAPH_KERNEL_LAYOUT SHADOWGRAPH_SHADER_CHECKS
T0=$(date +%s)
if [ -n "${SIZES:-}" ]; then
    DRY=1
    SCALE=${BOX_SCALE:-4}
    REPEAT=2
else
    DRY=
    SIZES=4096,8192
    SCALE=${BOX_SCALE:-1}
    REPEAT=10
fi
FIRST=${SIZES%%,*}
SECOND=${SIZES#*,}

# Runs a command (at most $2 seconds, times SCALE) with its output appended to $OUT/$1, then
# says how long it took in $OUT/steps.txt.
step() {
    local file=$1 limit=$(($2 * SCALE))
    shift 2
    local start
    start=$(date +%s%N)
    echo "## $*" >>"$OUT/$file"
    timeout "$limit" "$@" >>"$OUT/$file" 2>&1
    local status=$?
    echo "[t=$(($(date +%s) - T0)) s, $((($(date +%s%N) - start) / 1000000)) ms of $limit s, status $status] $*" |
        tee -a "$OUT/steps.txt"
}

command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,clocks.sm \
    --format=csv >>"$OUT/env.txt" 2>&1
step env.txt 10 "$B" info

# a. The evaluation's fronts on a GPU, first: three scenes at 1920×1080 with 2048² maps under
# the time protocol (interleaved rounds, the G-buffer as the clock check, n = 5). Each
# report's Markdown and CSV are appended to evaluate.txt between `#### <scene>/<file>` lines,
# so that one file comes back; the reports' folders stay on the machine.
EV=$(mktemp -d)
for scene in sphere_on_plane bunny colonnade; do
    if [ -n "$DRY" ]; then
        args=(--quick --techniques hard,vsm)
    else
        args=(--image 1920x1080 --sizes 2048 --repeat 5 --techniques hard,pcss,vsm,msm,vssm,msm_soft)
    fi
    step evaluate.txt 37 "$B" evaluate "scenes/$scene.toml" "${args[@]}" --out "$EV/$scene"
    for f in report.md report.csv; do
        [ -f "$EV/$scene/$f" ] && { echo "#### $scene/$f"; cat "$EV/$scene/$f"; } >>"$OUT/evaluate.txt"
    done
done
rm -rf "$EV"

# b. The kernel decisions: every case in both layouts, each size its own process (one warm-up,
# one clock, one set of copies a size; a step cut off loses only its size).
step kernels.txt 80 "$B" bench --sizes "$FIRST" --repeat "$REPEAT" --passes --layouts gpu,redesign
step kernels.txt 125 "$B" bench --sizes "$SECOND" --repeat "$REPEAT" --passes --layouts gpu,redesign
# Wgpu's runtime checks (naga bounding every index and loop) against none, in the redesign
# layout, whose kernels loop over private arrays; each case in both, adjacent in time.
# The intermediates in storage buffers against textures, in the redesign's kernels: the
# separable blurs, whose row output only their column pass reads, and the tables' edges and
# carries.
step buffers.txt 25 "$B" bench --sizes "$FIRST" --repeat "$REPEAT" --passes \
    --only 'blur rg32f,blur log,vsm_blur r32,msm_blur r32,sat fixed,sat float,chain vssm' \
    --layouts redesign,redesign-textures
SHADOWGRAPH_KERNEL_LAYOUT=redesign step checks.txt 15 "$B" bench --sizes "$FIRST" \
    --repeat "$REPEAT" --only 'linearize,evsm4,msm f16,chain vsm (depth,blur rg32f,vsm_blur r4,mips,sat fixed' \
    --kernel-dirs shipped,unchecked

# c. The redesign's maps on this device against the GPU layout's (checks.txt): every
# intermediate of five technique scenes dumped in both layouts and compared file by file. The
# encodings, blur rows, mip chain and fixed-point tables are the same bit for bit on lavapipe,
# whose subgroups have 8 lanes; such a file that differs here comes from this device (the
# tables' 32-lane path runs nowhere else): that redesign does not ship until the suite's
# `sat`, `csm_sat`, `mips_redesign`, `blur_rows` and `fused` tests pass on a GPU in the
# redesign layout. The fused blurs and the f32 tables may differ in their last bits (within
# their tests' tolerances): on lavapipe every map of `vsm_mips`, `msm_sat` (fixed-point) and
# `evsm4` is identical, and `vsm`'s fused blur and `vssm`'s f32 table, edges and carries
# differ (the carries' scan sums f32 in another order).
redesign_maps() {
    local d s l f same differ
    d=$(mktemp -d)
    for s in vsm vsm_mips vssm msm_sat evsm4; do
        for l in gpu redesign; do
            SHADOWGRAPH_KERNEL_LAYOUT=$l "$B" dump "scenes/techniques/$s.toml" --out "$d/$s.$l" \
                >/dev/null 2>&1 || echo "$s: dump in the $l layout failed"
        done
        same=0
        differ=
        for f in "$d/$s.gpu"/*.exr; do
            if cmp -s "$f" "$d/$s.redesign/${f##*/}"; then
                same=$((same + 1))
            else
                differ="$differ ${f##*/}"
            fi
        done
        echo "$s: $same maps identical; differ:${differ:- none}"
    done
    rm -rf "$d"
}
step checks.txt 15 bash -c "$(declare -f redesign_maps); B='$B'; redesign_maps"
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=clocks.sm --format=csv \
    >>"$OUT/env.txt" 2>&1
exit 0
