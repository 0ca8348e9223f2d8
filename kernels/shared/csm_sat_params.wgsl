// Parameters of the layered summed-area tables computed from the depth — CSM's basis, CSSM's
// search maps, the moments of MSM, VSM, EVSM and ESM (`msm_sat_*`, …) — (import-only module of
// `csm_sat_tile_sums`, `csm_sat_tiles` and their f32 variants; src/sat/layers.rs): the tile
// passes read the depth buffer and compute their layer's basis map on the fly (`SatSource`,
// shared/sat_tile), so the basis maps are never stored. Layer L (workgroup z = L − first_map)
// is map L of the light's sequence; its edges and carries are band L of the stacked
// intermediates (⌈height / TILE⌉ rows of col_part / col_carry, ⌈width / TILE⌉ columns of
// row_part / row_carry a band).
// #import shared/sat_tile

// Keep in sync with `CsmSatParams` in src/technique/csm_sat.rs.
struct CsmSatParams {
    sat: SatParams,       // the tables' coding (channels 4; sat.layers: every layer of the stack)
    depth: DepthParams,   // the depth buffer's linearization
    first_map: u32,       // the layer workgroup z = 0 computes
    maps: u32,            // layers of this dispatch (workgroups along z)
    terms: u32,           // M
    f16: u32,             // 1: round each basis value to f16, as an rgba16float map would hold it
    moments: u32,         // 1: the layer after CSM's is MSM's moments (CSSM's moment search)
    unorm16: u32,         // 1: round each value to 16-bit unorm, as an rgba16unorm map would hold it
    exp_pos: f32,         // EVSM's c⁺, ESM's c (the moment layers)
    exp_neg: f32,         // EVSM's c⁻
    interleave: u32,      // n: tables a texture, interleaved along x (src/sat/layers.rs)
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// Where pass 3 stores texel q of layer `z` of its dispatch: (x, y) of output texture dst<w>,
// w the result's z. With n = p.interleave tables a texture, texel (x, y) of table k is texel
// (x·m + k mod n, y) of texture ⌊k / n⌋, which holds m = n tables (the last the rest); a
// dispatch starts at a multiple of 4n tables, so its texture ⌊z / n⌋ is dst<⌊z / n⌋>.
fn csm_sat_texel(p: CsmSatParams, z: u32, q: vec2<u32>) -> vec3<u32> {
    let n = max(p.interleave, 1u);
    let k = p.first_map + z;
    let m = min(n, p.sat.layers - k / n * n);
    return vec3<u32>(q.x * m + k % n, q.y, z / n);
}

// Pass 3's tile (x, y) and layer of its dispatch (z) for workgroup `wg`: as dispatched, or with
// n > 1 tables a texture the layers side by side along x (`Dispatch::Interleaved`: workgroup
// x = X·maps + k on layer k of tile X), so that the interleaved texels of one tile are written
// within a short time (a layer a workgroup z wrote each cache line n times, each after the
// others had left it: pass 3 1.7× slower on llvmpipe).
fn csm_sat_pass3_at(p: CsmSatParams, wg: vec3<u32>) -> vec3<u32> {
    if p.interleave > 1u {
        return vec3<u32>(wg.x / p.maps, wg.y, wg.x % p.maps);
    }
    return wg;
}

// Tiles of a `size` map along x and y: the width of a band of row_part, the height of one of
// col_part.
fn csm_sat_tiles_of(size: vec2<u32>) -> vec2<u32> {
    return (size + vec2<u32>(TILE - 1u)) / TILE;
}

// Layer `layer`'s source, for a map of `tiles` tiles: map `layer` of the CSM sequence.
fn csm_sat_source(p: CsmSatParams, layer: u32, tiles: vec2<u32>) -> SatSource {
    return SatSource(true, SAT_CSM, p.f16 != 0u, layer, p.terms, p.moments != 0u, false, 0.0, 0.0,
        p.depth, layer * tiles);
}

// The source of one layer of moments (`msm_sat`, `vsm_sat`, `evsm_sat`, `esm_sat` kernels), by
// `kind` (a literal in each kernel): MSM's quantized moments, VSM's (each texel's derivatives
// from its neighbours' depth, as `vsm`), EVSM's (c⁺ = p.exp_pos, c⁻ = p.exp_neg) or ESM's
// exp(c (z − 1)) (c = p.exp_pos), as their encoding kernels compute them, rounded as the
// map's storage would (`p.f16`, `p.unorm16`).
fn moment_sat_source(p: CsmSatParams, kind: u32) -> SatSource {
    return SatSource(true, kind, p.f16 != 0u, 0u, 0u, false, p.unorm16 != 0u, p.exp_pos, p.exp_neg,
        p.depth, vec2<u32>(0u));
}
