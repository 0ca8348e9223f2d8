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

// Non-finite depth texels this invocation's `sat_texel` replaced (depth sources; the first
// tile pass counts layer 0's).
var<private> sat_non_finite: u32;

// The encoded texel `q` of `src` (`size` its size) read as `s` says, 0 outside the map (the
// load is clamped to the map and its value discarded, so no invocation branches).
// `src` is the importing kernel's binding, read here and not passed down: the executor's
// packed variant (src/exec/packed.rs) re-declares it `texture_2d<u32>` and unpacks this load
// when the representation is f16 pairs in r32uint words, which a `texture_2d<f32>` parameter
// would not let it do.
fn sat_texel(
    q: vec2<u32>,
    size: vec2<u32>,
    p: SatParams,
    fs: bool,
    s: SatSource,
) -> vec4<u32> {
    let inside = all(q < size);
    var v = textureLoad(src, min(q, size - 1u), 0);
    if s.from_depth {
        let raw = v.r;
        if inside && !depth_is_finite(raw) {
            sat_non_finite += 1u;
        }
        let z = linear_depth(raw, s.depth);
        if s.msm {
            // MSM's moments as shared/msm_moments computes them, quantized (a table's always
            // are).
            let z2 = z * z;
            v = msm_quantize(vec4<f32>(z, z2, z2 * z, z2 * z2));
        } else {
            v = csm_basis_map(s.layer, s.terms, s.moments, z);
        }
        // The storage's rounding, selected rather than branched on: llvmpipe runs a branch's
        // body for every lane, and both roundings are a few integer operations.
        v = select(v, round_f16(v), s.f16);
        v = select(v, round_unorm16(v), s.unorm16);
    }
    return select(vec4<u32>(0u), sat_encode_as(v, p, fs), inside);
}
