// The light's four-channel CSM and CSM-Z basis maps (import-only module of `csm` and of the
// layered tables' `SatSource`, shared/sat_tile, which compute them on the fly), built from the
// Fourier basis of shared/csm_basis.
// #import shared/csm_basis
// #import shared/msm_quantize

// Map m of the light's sequence at depth z, M = `terms`: the ⌈M/2⌉ CSM basis maps (sin c_k z,
// cos c_k z, sin c_{k+1} z, cos c_{k+1} z), k = 2m + 1, a pair past M zeros; then (CSSM) the
// CSM-Z maps, map j = m − ⌈M/2⌉ holding channels 4j … 4j + 3 of the CSM-Z sequence
// [z, z·sin c₁z, z·cos c₁z, …, z·cos c_M z] (channel i ≥ 1: z·sin of term ⌈i/2⌉ for odd i,
// z·cos for even i; past channel 2M zeros): z·cos of term 2j (z itself for j = 0), z·sin and
// z·cos of term 2j + 1, z·sin of term 2j + 2.
// Branch-free, three (sin, cos) pairs whichever the map: a software rasterizer runs both
// sides of a branch on the map index, and a GPU's workgroups of one layer agree on it anyway.
fn csm_basis_map(m: u32, terms: u32, moments: bool, z: f32) -> vec4<f32> {
    let basis_maps = (terms + 1u) / 2u;
    let csm = m < basis_maps;
    let j = m - min(m, basis_maps);
    // The map's first term: 2m + 1 (CSM) or 2j (CSM-Z; term 0 of map 0 is z, not evaluated).
    let k = select(2u * j, 2u * m + 1u, csm);
    let a = csm_sin_cos(max(k, 1u), z);
    let b = csm_sin_cos(k + 1u, z);
    let c = csm_sin_cos(k + 2u, z);
    let basis = vec4<f32>(a, b);
    let z_seq = z * vec4<f32>(select(a.y, 1.0, j == 0u), b, c.x);
    // What each channel holds: CSM its term (≤ M kept), CSM-Z its channel (≤ 2M kept).
    let term = vec4<u32>(k, k, k + 1u, k + 1u);
    let channel = 4u * j + vec4<u32>(0u, 1u, 2u, 3u);
    let keep = select(channel <= vec4<u32>(2u * terms), term <= vec4<u32>(terms), csm);
    let z2 = z * z;
    let power = msm_quantize(vec4<f32>(z, z2, z2 * z, z2 * z2));
    let rest = select(select(vec4<f32>(0.0), z_seq, keep), power, moments);
    return select(rest, select(vec4<f32>(0.0), basis, keep), csm);
}
