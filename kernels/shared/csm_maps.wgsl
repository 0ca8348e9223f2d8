// The light's four-channel CSM and CSM-Z basis maps (import-only module of `csm` and of the
// layered tables' `SatSource`, shared/sat_tile, which compute them on the fly), built from the
// Fourier basis of shared/csm_basis.
// #import shared/csm_basis

// Channel i of the CSM-Z sequence [z, z·sin c₁z, z·cos c₁z, …, z·cos c_M z] at depth z, M =
// `terms` (0 past channel 2M).
fn csm_z_channel(i: u32, terms: u32, z: f32) -> f32 {
    if i == 0u {
        return z;
    }
    if i > 2u * terms {
        return 0.0;
    }
    let sc = csm_sin_cos((i + 1u) / 2u, z);
    return z * select(sc.y, sc.x, (i & 1u) == 1u);
}

// Map m of the light's sequence at depth z: the ⌈M/2⌉ CSM basis maps (sin c_k z, cos c_k z,
// sin c_{k+1} z, cos c_{k+1} z), k = 2m + 1, a pair past M zeros; then (CSSM) the CSM-Z maps,
// four channels of the CSM-Z sequence each from channel 4·(m − ⌈M/2⌉) on.
fn csm_basis_map(m: u32, terms: u32, z: f32) -> vec4<f32> {
    let basis_maps = (terms + 1u) / 2u;
    if m < basis_maps {
        let k = 2u * m + 1u;
        let v = vec4<f32>(csm_sin_cos(k, z), csm_sin_cos(k + 1u, z));
        return select(v, vec4<f32>(v.xy, 0.0, 0.0), k + 1u > terms);
    }
    let first = 4u * (m - basis_maps);
    return vec4<f32>(
        csm_z_channel(first, terms, z),
        csm_z_channel(first + 1u, terms, z),
        csm_z_channel(first + 2u, terms, z),
        csm_z_channel(first + 3u, terms, z),
    );
}
