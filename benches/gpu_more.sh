#!/bin/bash
# The device checks that follow benches/gpu_check.sh's (the evaluation's fronts and the kernel
# decisions), for a second call of at most 600 s: the soft table, the shading pass's floor and
# shapes, the kernel-folder variants of the blur rows, the tables and the mip chain, every
# kernel at 2048², the fused blurs' ablation, the `gpu` and `cpu` layouts, workgroup memory
# zeroed or not, a second binary (BASE), the timer against the wall clock, cascades. From the
# repository root, after `cargo build --release`:
#
#   benches/gpu_more.sh [BINARY] [OUT]     # defaults: target/release/shadowgraph, gpu-more
#
# The steps run in order, each under its own time box, appending to files of OUT (env, steps,
# soft, tables, shade, variants, kernels_2048), so a call stopped by its time box still returns
# what ran: soft table about 66 s, the shading over tables in buffers 50 s, four shading
# shapes about 80 s, the blur rows' variants 35 s, the tables' 30 s, the mip chain's 20 s,
# every kernel at 2048² 20 s, the fused ablation 10 s, the layouts 70 s, workgroup memory
# 30 s, the bunny frame and six cascaded frames 20 s (about 450 s; BASE about 60 s more). A second binary to compare against goes in as
# BASE=path/to/other/shadowgraph: its 2048² blur and table rows are then timed alternately with
# BINARY's (compare timings only within one call). Record the results in benches/RESULTS.md
# (device, date, commit, command, table).
#
# Reading the results (decided before the run, so that a lent GPU's time goes to the change):
# - shade.txt: a shape (wg16x4, tx2, tx4) ships where `hard` and `vssm` both fall below the
#   shipped kernel's in the same step at every light size. tx2/tx4 made llvmpipe 1.1-1.7x
#   slower, so they ship per device: TEXELS_X becomes an `override` of the layout (the
#   dispatch follows the value the pipeline was created with, kernels::Reflection), and
#   wg16x4 may ship everywhere if llvmpipe is no slower.
# - variants.txt, blur rows: the row pass (`blur_h`) of run1/run2 against shipped at each
#   radius and size, both rounds agreeing. A faster variant ships for GPUs through
#   exec::KernelLayout (the rows' run length an `override`; llvmpipe keeps 8), possibly by
#   radius; tests compare both layouts.
# - variants.txt, VSM's table: tile sums + tiles of sat_vsm_texel against shipped for `chain
#   vssm`. Faster: VSM's sub-block fill becomes `!GPU_LAYOUT` only (sat_tile.wgsl's existing
#   override), its per-texel branch the GPU's; `tests/sat/layouts.rs` already builds both layouts.
# - variants.txt, sat_sub2: tile sums + tiles against shipped for `sat fixed`, `chain vssm`,
#   `chain msm_soft` and CSSM, both rounds agreeing. Faster: the 2 x 2 sub-blocks ship for
#   GPUs (SUB, GRID and the tile kernels' workgroup size from exec::KernelLayout, the carries
#   kernel keeping 64; its f32 tables then differ from llvmpipe's in their last bits, within
#   the tolerances of tests/sat/) or everywhere if the suite's time allows.
# - variants.txt, sat_carries_serial: the `carries` pass against shipped's in `sat fixed`,
#   `chain vssm` and `chain msm_soft`, both rounds. The batched loads stay unless the serial
#   kernel is faster in both (then restore it from the variant, less its header).
# - variants.txt, mips: mip_quads faster at 2048² and 4096² in both rounds ships everywhere
#   (llvmpipe as fast or faster): copy it over kernels/shared/mip_chain.wgsl, less its header.
# - variants.txt, layouts: the fused tile blurs' `[cpu]` rows (strips, 8 invocations a tile)
#   against `[gpu]` (the tile, 256). The strips ship for GPUs only where faster for VSM, MSM
#   and EVSM4 alike: GPU_LAYOUT's branches in shared/encode_blur.wgsl go, LANES becomes the
#   constant CPU_LANES (then rename it).
# - variants.txt, zeroed: informational (exec::WorkgroupInit::AsLeft ships either way).
# - tables.txt: `vssm` and `msm_soft` (fixed-point tables) shaded over tables in storage
#   buffers (the first block, `redesign`) against textures (`redesign-textures`), at every
#   light size. Together with gpu_check.sh's buffers.txt: the renderer's tables move to
#   buffers where the shade pass and the table build are both 3% or more faster; a plug-in
#   output in a buffer (a host-visible change) only then.
set -u
B=${1:-target/release/shadowgraph}
OUT=${2:-gpu-more}
BASE=${BASE:-}
mkdir -p "$OUT"
export SHADOWGRAPH_MEMORY_BUDGET=${SHADOWGRAPH_MEMORY_BUDGET:-48GiB}
unset SHADOWGRAPH_KERNEL_DIR SHADOWGRAPH_KERNEL_LAYOUT SHADOWGRAPH_SHADER_CHECKS
T0=$(date +%s)

# Runs a command (at most $2 seconds) with its output appended to $OUT/$1, then says how long
# it took in $OUT/steps.txt.
# Says in $OUT/steps.txt if variant file $2 came out the same as $1, the file it was edited
# from (the edit no longer applies: its rows would time the file it came from).
edited() {
    cmp -s "$1" "$2" && echo "variant $2: its edit no longer applies to $1" | tee -a "$OUT/steps.txt"
    return 0
}

step() {
    local file=$1 limit=$2
    shift 2
    local start
    start=$(date +%s%N)
    echo "## $*" >>"$OUT/$file"
    timeout "$limit" "$@" >>"$OUT/$file" 2>&1
    local status=$?
    echo "[t=$(($(date +%s) - T0)) s, $((($(date +%s%N) - start) / 1000000)) ms, status $status] $*" |
        tee -a "$OUT/steps.txt"
}

command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,clocks.sm \
    --format=csv >>"$OUT/env.txt" 2>&1
step env.txt 30 "$B" info
# The soft techniques' shading against PCSS 16 + 32 at 1920×1080 with a 2048² map,
# each configuration's prefilter, and each frame's passes against its wall time.
# The SM clock sampled through it (on 2026-11-27 the soft table read its prefilter 2.4× the
# kernel bench's time for the same chain at a clock of 345-735 MHz, and 1.5× at 1980 MHz:
# the table's last block, the prefilter pass by pass, says which pass).
SAMPLER=
if command -v nvidia-smi >/dev/null; then
    echo "## clocks during the soft table" >>"$OUT/env.txt"
    nvidia-smi --query-gpu=timestamp,clocks.sm,utilization.gpu --format=csv,noheader -lms 200 \
        >>"$OUT/env.txt" 2>&1 &
    SAMPLER=$!
fi
step soft.txt 150 "$B" bench --lookup 3 --repeat 20 --image 1920x1080 --map 2048
[ -n "$SAMPLER" ] && kill "$SAMPLER" 2>/dev/null
# The shading over fixed-point tables in storage buffers (the redesign layout) against the
# same kernels over textures, one process each, back to back.
for layout in redesign redesign-textures; do
    SHADOWGRAPH_KERNEL_LAYOUT=$layout step tables.txt 25 "$B" bench --lookup 3 --repeat 20 \
        --image 1920x1080 --map 2048 --only vssm,msm_soft
done
# The shading pass's floor: `hard` with parts of kernels/shade.wgsl taken out
# (SHADOWGRAPH_KERNEL_DIR), from the constant store alone up to the shipped kernel. A variant
# that no longer uses a binding is bound without it (bindings follow the kernel's reflection).
V=$(mktemp -d)
S=kernels/shade.wgsl
MAIN='@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= frame.size) {
        return;
    }
    let xy = id.xy;'
mkdir -p "$V/shipped" "$V/empty" "$V/no_lookup" "$V/gbuffer_only" "$V/store_only" \
    "$V/wg16x4" "$V/tx2" "$V/tx4"
cp "$S" "$V/shipped/shade.wgsl"
# Nothing a pixel (the same 32 400 workgroups, each invocation testing its bounds and
# returning): the pass's own cost, its transitions and launch (a `no_srgb` variant, 0.015 ms
# of the 0.114 on 2026-11-27, is dropped for it).
{
    sed '/^@compute/,$d' "$S"
    printf '%s\n' "$MAIN"
    printf '}\n'
} >"$V/empty/shade.wgsl"
sed 's/let v = light_visibility(i, gp.xyz, n, dp.dpdx, dp.dpdy);/let v = 1.0;/' \
    "$S" >"$V/no_lookup/shade.wgsl"
{
    sed '/^@compute/,$d' "$S"
    printf '%s\n' "$MAIN"
    printf '    let gp = textureLoad(g_position, xy, 0);\n    let gn = textureLoad(g_normal, xy, 0);\n'
    printf '    out_visibility[xy.y * frame.size.x + xy.x] = gp.w;\n'
    printf '    textureStore(out_color, xy, vec4<f32>(gp.xyz + gn.xyz, 1.0));\n}\n'
} >"$V/gbuffer_only/shade.wgsl"
{
    sed '/^@compute/,$d' "$S"
    printf '%s\n' "$MAIN"
    printf '    textureStore(out_color, xy, vec4<f32>(0.5, 0.5, 0.5, 1.0));\n}\n'
} >"$V/store_only/shade.wgsl"
# Fewer workgroups (2026-11-27: an empty 8 × 8 kernel over 1080p 0.040 ms of `hard`'s
# 0.066, a constant store 0.058 in 8 × 8 and 0.025 in 16 × 16 workgroups, but the shipped
# kernel slower in 16 × 16, 0.112 against 0.094): 16 × 4 (64 invocations on rows twice as
# long), and 2 or 4 pixels an invocation along its row (`TEXELS_X`: the dispatch follows).
sed 's/^@compute @workgroup_size(WG_SIZE, WG_SIZE)$/@compute @workgroup_size(16, 4)/' "$S" \
    >"$V/wg16x4/shade.wgsl"
sed 's/^const TEXELS_X: u32 = 1u;$/const TEXELS_X: u32 = 2u;/' "$S" >"$V/tx2/shade.wgsl"
sed 's/^const TEXELS_X: u32 = 1u;$/const TEXELS_X: u32 = 4u;/' "$S" >"$V/tx4/shade.wgsl"
for v in no_lookup wg16x4 tx2 tx4; do
    edited "$S" "$V/$v/shade.wgsl"
done
# `vssm` beside `hard` where the whole pass is kept (the soft target's ratio with each shape).
# The floor's parts (empty, no_lookup, gbuffer_only, store_only) were timed on 2026-11-27
# (0.040, 0.055-0.059, 0.060-0.061, 0.057-0.058 ms): set SHADE_PARTS=1 to time them again.
SHAPES="shipped wg16x4 tx2 tx4"
[ -n "${SHADE_PARTS:-}" ] && SHAPES="$SHAPES empty no_lookup gbuffer_only store_only"
for v in $SHAPES; do
    only=hard
    case $v in shipped | wg16x4 | tx2 | tx4) only=hard,vssm ;; esac
    echo "## variant $v" >>"$OUT/shade.txt"
    SHADOWGRAPH_KERNEL_DIR="$V/$v" step shade.txt 40 "$B" bench --lookup 3 --repeat 20 \
        --image 1920x1080 --map 2048 --only "$only"
done
# The separable blur's row pass (H200: 3-5x its column pass over the same texels; both passes
# took 0.139 ms at 2048² one output an invocation on 2026-11-26, 0.164 with the runs of
# 8 since, which were chosen on llvmpipe): benches/variants/blur_rows_run1 (one output an
# invocation, neighbouring invocations on neighbouring texels) and blur_rows_run2 (runs of 2)
# against the shipped runs of 8, columns as shipped, the same blur bit for bit
# (tests/kernel_dir/), alternated twice. On llvmpipe the row pass is 2.1x (run1) and
# 1.4-1.6x (run2) slower than shipped (benches/RESULTS.md, 2026-11-27).
# One process a round (`bench --kernel-dirs`: one warm-up, one set of copies, each kernel in
# each folder adjacent in time), the folders' order reversed in the second.
R1=benches/variants/blur_rows_run1
R2=benches/variants/blur_rows_run2
for dirs in "shipped,$R1,$R2" "$R2,$R1,shipped"; do
    step variants.txt 60 "$B" bench --sizes 2048,4096 --repeat 20 \
        --only 'blur rg32f,evsm4+blur' --passes --kernel-dirs "$dirs"
done
# VSM's table texels each from five depth loads (benches/variants/sat_vsm_texel) against the
# shipped 4 x 4 sub-block of depths in private arrays (H200, 2026-11-27: VSM's tile
# sums 0.110 ms at 2048² against MSM's 0.063; llvmpipe 1.3x slower with the variant), the same
# tables bit for bit, alternated twice.
# And the tables' tile passes with 2 x 2 sub-blocks, 256 invocations a tile
# (benches/variants/sat_sub2: lanes 2 texels apart instead of 4, four times the invocations;
# fixed-point tables bit for bit the same; llvmpipe 1.15-1.5x slower).
# And the carries kernel loading one edge texel at a time as its serial sum reaches it
# (benches/variants/sat_carries_serial, shipped until f1ee092; the H200's
# carries took 0.034 ms at 2048² and 0.082 at 4096², 0.5-0.6 us a tile of a line: a load's
# latency each), against the shipped loads eight ahead of the sums; the same carries bit for bit.
TV=benches/variants/sat_vsm_texel
TS=benches/variants/sat_sub2
TC=benches/variants/sat_carries_serial
for dirs in "shipped,$TV,$TS,$TC" "$TC,$TS,$TV,shipped"; do
    step variants.txt 60 "$B" bench --sizes 2048,4096 --repeat 20 \
        --only 'sat fixed,chain vssm,chain msm_soft,chain cssm 8 terms (depth → 5' --passes \
        --kernel-dirs "$dirs"
done
# The mip chain without level s + 1 in workgroup memory (benches/variants/mip_quads: 5.4 of
# the shipped kernel's 21.3 KiB, which admits 10 workgroups of 64 an SM; the same chain bit for
# bit, tests/kernel_dir/), alternated with the shipped kernel twice.
for dirs in shipped,benches/variants/mip_quads benches/variants/mip_quads,shipped; do
    step variants.txt 40 "$B" bench --sizes 2048,4096 --repeat 20 --only mips \
        --kernel-dirs "$dirs"
done
# Every kernel at 2048² by dispatch (the soft tables' build, target ≤ 0.2 ms at 2048²,
# `chain vssm`, `chain msm_soft`); 4096² and 8192² are gpu_check.sh's.
step kernels_2048.txt 60 "$B" bench --sizes 2048 --repeat 20 --passes
# Where the fused tile blurs' time goes (they ran at 0.26-0.30x their copy on the H200, 3x
# their bytes' time): the shipped kernels beside variants of kernels/shared/encode_blur.wgsl
# whose tiles store their encoded centres unblurred (`no_blur`: load, encode, store) and
# store without loading or encoding (`no_encode`: the stores alone, of workgroup memory's
# stale contents). Timings only:
# the variants' outputs are not the filter's.
E=kernels/shared/encode_blur.wgsl
UNBLURRED='            for (var k = i32(li); k < t.outs.x * t.outs.y; k += i32(WG_SIZE)) {
                let yx = div_mod(k, t.outs.x);
                store(t, vec2<i32>(yx.y, yx.x), sh_get((yx.x + t.r.y) * t.enc.x + yx.y + t.r.x));
            }'
mkdir -p "$V/fused_no_blur/shared" "$V/fused_no_encode/shared"
awk -v body="$UNBLURRED" '/^                blur_tile_(runs|single)\(t, li\);$/ { print body; next } { print }' \
    "$E" >"$V/fused_no_blur/shared/encode_blur.wgsl"
sed 's/^        encode_tile(t, li);$/        workgroupBarrier();/' "$V/fused_no_blur/shared/encode_blur.wgsl" \
    >"$V/fused_no_encode/shared/encode_blur.wgsl"
edited "$E" "$V/fused_no_blur/shared/encode_blur.wgsl"
edited "$V/fused_no_blur/shared/encode_blur.wgsl" "$V/fused_no_encode/shared/encode_blur.wgsl"
step variants.txt 40 "$B" bench --sizes 2048 --repeat 20 \
    --only 'vsm_blur r4,msm_blur r4,evsm_blur 4 r4' \
    --kernel-dirs "shipped,$V/fused_no_blur,$V/fused_no_encode"
# The soft table build at 2048² (target ≤ 0.2 ms) in the kernels' two layouts (exec::KernelLayout)
# in one process, every case in both side by side (`bench --layouts`), one round (two rounds
# agreed within 1% on 2026-11-27): `gpu` (the default on a GPU) loads and encodes pass 3's texels
# again, `cpu` keeps the first sweep's (2026-11-27: `chain vssm` 0.313 against 0.336
# ms). The fused tile blurs too: `gpu` blurs a tile in workgroup memory with 256 invocations,
# `cpu` walks it in strips with 8 (2-3x faster on llvmpipe, 2026-11-28). The strips
# ship for GPUs only if faster there in this step at 2048² (then GPU_LAYOUT's branches in
# shared/encode_blur.wgsl go, and LANES becomes a constant).
for order in gpu,cpu; do
    step variants.txt 60 "$B" bench --sizes 2048 --repeat 20 \
        --only 'sat,chain vssm,chain msm_soft,chain esm,chain cssm,vsm_blur r4,msm_blur r4,evsm_blur 4 r4' \
        --passes --layouts "$order"
done
# The kernels' workgroup memory left as the device leaves it (shipped: exec::WorkgroupInit::AsLeft,
# safe because tests/workgroup_memory.rs finds every kernel writing it before reading it)
# against wgpu's default of zeroing it first (`zeroed`: each workgroup stores its whole declared
# workgroup memory and waits at a barrier), alternated twice. Runs on 2026-11-27 found
# declared workgroup memory costing the H200 1.1-2x even where no branch used it; this says how
# much of that was the zeroing. Informational: AsLeft ships (less work); llvmpipe showed no
# difference beyond its spread.
for dirs in shipped,zeroed zeroed,shipped; do
    step variants.txt 40 "$B" bench --sizes 2048 --repeat 20 \
        --only 'vsm_blur r4,msm_blur r4,mips,sat fixed,chain vssm,chain msm_soft' --passes \
        --kernel-dirs "$dirs"
done
if [ -n "$BASE" ]; then
    for round in 1 2; do
        for b in "$BASE" "$B"; do
            step variants.txt 40 "$b" bench --sizes 2048 --repeat 20 \
                --only 'blur,sat fixed,chain vssm,chain msm_soft' --passes
        done
    done
fi
# The timer against the wall clock on a bundled scene.
step env.txt 30 "$B" render scenes/bunny.toml --timings --repeat 20 -o "$V/bunny.png"
# Cascades on a GPU (never timed there; llvmpipe runs every cascade's case, 3.3-4.7x one map's
# wall time): city_street at 1920x1080, its four 512² cascades against one 512² map
# (`cascades = 1`), with hard, PCSS 16 + 32 and vssm; each frame's passes against its wall time.
for t in hard pcss vssm; do
    for c in 4 1; do
        sed -e "s/^technique = \"pcf\"$/technique = \"$t\"/" -e '/^radius = 1$/d' \
            -e "s/^cascades = 4$/cascades = $c/" -e 's/^width = 480$/width = 1920/' \
            -e 's/^height = 360$/height = 1080/' scenes/city_street.toml >"$V/city_${t}_$c.toml"
        step env.txt 20 "$B" render "$V/city_${t}_$c.toml" --timings --repeat 20 -o "$V/city.png"
    done
done
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=clocks.sm --format=csv \
    >>"$OUT/env.txt" 2>&1
rm -rf "$V"
exit 0
