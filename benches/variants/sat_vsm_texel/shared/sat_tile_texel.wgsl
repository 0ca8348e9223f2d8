// BENCHMARK VARIANT (benches/variants/sat_vsm_texel, run through SHADOWGRAPH_KERNEL_DIR by
// benches/gpu_check.sh; not shipped): kernels/shared/sat_tile_texel.wgsl with VSM's texels
// computed one at a time, each from its own five depth loads (the neighbours from the texture
// cache), instead of a 4 × 4 sub-block's 36 depths held in a private array
// (`sat_block_fill`, which only ESM keeps here). On an H200 the shipped VSM table's tile sums
// took 0.110 ms at 2048² against MSM's 0.063 (four channels, quantized): the private arrays
// are the suspect. The same moments: the same tables bit for bit (tests/kernel_dir.rs).
// A tile pass's texel (import-only module of shared/sat_tile_sums and shared/sat_tile_scan,
// apart from shared/sat_tile because it reads the importing kernel's `src` binding, which the
// carries kernel, importing shared/sat_tile for `SatSource`, does not have). The importing
// kernel declares `src: texture_2d<f32>`:
// #completed-by-importer
// #import shared/sat_tile
// #import shared/csm_maps
// #import shared/msm_quantize
// #import shared/storage_round
// #import shared/linear_depth
// #import shared/vsm_moments
// #import shared/evsm_moments

// Non-finite depth texels this invocation's `sat_texel` replaced (depth sources; the first
// tile pass counts layer 0's).
var<private> sat_non_finite: u32;

// The moments of the sub-block a pass sweeps (SUB × SUB, row-major) for the sources that
// `sat_blocked` names, filled by `sat_block_fill` before its sweeps and read by `sat_texel`.
var<private> sat_block: array<vec2<f32>, 16>; // SUB · SUB

// Whether `s` (literal fields) is computed a sub-block at a time: VSM, whose texels share
// their neighbours' depth, and ESM, whose exp pass 3's two sweeps then share. One- and
// two-channel sources only (a four-channel block would hold 64 values an invocation).
fn sat_blocked(s: SatSource) -> bool {
    return s.from_depth && s.kind == SAT_ESM;
}

// The sub-block at `origin`'s moments. VSM's as `vsm` computes them (shared/vsm_moments):
// each texel's derivatives take its four neighbours' depths, clamped to the map; the linear
// depth of the sub-block and its one-texel border is read once, (SUB + 2)² loads, where each
// texel's own five would be 5·SUB² (80 against 36 at SUB = 4; on llvmpipe the table built with
// them per texel ran 1.1× slower than the stored map's, `benches/RESULTS.md`, 2026-11-27).
// ESM's exp(c (z − 1)), one exp a texel a pass instead of one a sweep. Texels past the map's
// edge (ragged tiles) get values that `sat_texel` discards. The sub-block's own non-finite
// depths are counted here (`sat_raw_own`): the sweeps load no depth.
fn sat_block_fill(origin: vec2<u32>, size: vec2<u32>, s: SatSource) {
    if s.kind == SAT_ESM {
        for (var k = 0u; k < SUB * SUB; k++) {
            let at = vec2<i32>(origin) + vec2<i32>(i32(k % SUB), i32(k / SUB));
            let z = linear_depth(sat_raw_own(at, origin, size), s.depth);
            sat_block[k] = vec2<f32>(exp(s.exp_pos * (z - 1.0)), 0.0);
        }
        return;
    }
    const BORDERED: u32 = SUB + 2u;
    var z: array<f32, 36>; // BORDERED²
    for (var k = 0u; k < BORDERED * BORDERED; k++) {
        let at = vec2<i32>(origin) + vec2<i32>(i32(k % BORDERED), i32(k / BORDERED)) - 1;
        z[k] = linear_depth(sat_raw_own(at, origin, size), s.depth);
    }
    for (var k = 0u; k < SUB * SUB; k++) {
        let c = (k / SUB + 1u) * BORDERED + k % SUB + 1u;
        sat_block[k] = vsm_moments(z[c], z[c - 1u], z[c + 1u], z[c - BORDERED], z[c + BORDERED]);
    }
}

// The raw depth of `src` (the depth buffer) at p clamped to the map of `size`, p within one
// texel of the sub-block at `origin`, a non-finite depth counted here (`sat_non_finite`) when p is a texel of the
// sub-block inside the map, so that the blocked sources' sweeps load nothing more.
fn sat_raw_own(p: vec2<i32>, origin: vec2<u32>, size: vec2<u32>) -> f32 {
    let q = clamp(p, vec2<i32>(0), vec2<i32>(size) - 1);
    let raw = textureLoad(src, q, 0).r;
    let o = vec2<i32>(origin);
    let own = all(p == q) && all(p >= o) && all(p < o + i32(SUB));
    if own && !depth_is_finite(raw) {
        sat_non_finite += 1u;
    }
    return raw;
}

// The encoded texel `q` of `src` (`size` its size) read as `s` says, 0 outside the map (the
// load is clamped to the map and its value discarded, so no invocation branches). `own` is
// q's index in its sub-block (`sat_block`'s, row-major), which the callers' sweeps know as
// their loop counters: a constant once a driver unrolls them, where recovering it from q
// (q % SUB) leaves a private array indexed at run time.
// `src` is the importing kernel's binding, read here and not passed down: the executor's
// packed variant (src/exec/packed.rs) re-declares it `texture_2d<u32>` and unpacks this load
// when the representation is f16 pairs in r32uint words, which a `texture_2d<f32>` parameter
// would not let it do.
fn sat_texel(
    q: vec2<u32>,
    own: u32,
    size: vec2<u32>,
    p: SatParams,
    fs: bool,
    s: SatSource,
) -> vec4<u32> {
    let inside = all(q < size);
    var v: vec4<f32>;
    if s.from_depth {
        // Unused by the blocked sources below, whose `sat_block_fill` loaded and counted it.
        var raw = 0.0;
        if !sat_blocked(s) {
            raw = textureLoad(src, min(q, size - 1u), 0).r;
            if inside && !depth_is_finite(raw) {
                sat_non_finite += 1u;
            }
        }
        let z = linear_depth(raw, s.depth);
        if s.kind == SAT_MSM {
            // MSM's moments as shared/msm_moments computes them, quantized (a table's always
            // are).
            let z2 = z * z;
            v = msm_quantize(vec4<f32>(z, z2, z2 * z, z2 * z2));
        } else if s.kind == SAT_VSM {
            // The four neighbours' linear depths, clamped to the map (as `sat_block_fill`).
            let c = vec2<i32>(min(q, size - 1u));
            let hi = vec2<i32>(size) - 1;
            let left = textureLoad(src, clamp(c - vec2<i32>(1, 0), vec2<i32>(0), hi), 0).r;
            let right = textureLoad(src, clamp(c + vec2<i32>(1, 0), vec2<i32>(0), hi), 0).r;
            let up = textureLoad(src, clamp(c - vec2<i32>(0, 1), vec2<i32>(0), hi), 0).r;
            let down = textureLoad(src, clamp(c + vec2<i32>(0, 1), vec2<i32>(0), hi), 0).r;
            v = vec4<f32>(vsm_moments(z, linear_depth(left, s.depth), linear_depth(right, s.depth),
                linear_depth(up, s.depth), linear_depth(down, s.depth)), 0.0, 0.0);
        } else if sat_blocked(s) {
            // VSM's moments or ESM's exp(c (z − 1)) (`esm`'s moment for a summed-area table)
            // of the invocation's sub-block, computed once a pass (`sat_block_fill`;
            // sub-blocks start at multiples of SUB).
            v = vec4<f32>(sat_block[own], 0.0, 0.0);
        } else if s.kind == SAT_EVSM {
            v = evsm_moments(z, s.exp_pos, s.exp_neg);
        } else {
            v = csm_basis_map(s.layer, s.terms, s.moments, z);
        }
        // The storage's rounding, selected rather than branched on: llvmpipe runs a branch's
        // body for every lane, and both roundings are a few integer operations.
        v = select(v, round_f16(v), s.f16);
        v = select(v, round_unorm16(v), s.unorm16);
    } else {
        v = textureLoad(src, min(q, size - 1u), 0);
    }
    return select(vec4<u32>(0u), sat_encode_as(v, p, fs), inside);
}
