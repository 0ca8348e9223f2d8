// Parameters and value coding of the summed-area-table kernels (import-only module).
//
// Values travel as vec4<u32> in both variants: u32 fixed point, added with two's-complement
// wraparound (WGSL's u32 `+` wraps), or the bits of an f32, added as floats. 0u is the identity
// of both (the bits of +0.0).

// Keep in sync with `SatParams` in src/sat.rs.
struct SatParams {
    offset: vec4<f32>,   // subtracted from every value before scaling (centres the range)
    scale: vec4<f32>,    // fixed: units per value unit (a power of two); float: 1
    limit: vec4<f32>,    // |(v − offset)·scale| is clamped to this (keeps window sums in range)
    channels: u32,       // channels of the representation that are used; the others are 0
    float_sums: u32,     // 1: f32 variant (values are f32 bits), 0: u32 fixed point
    axis: u32,           // sat_carry (five-pass baseline): 0 scans rows of block totals, 1 columns
    layers: u32,         // sat_carries: tables stacked in the edges (src/sat/layers.rs; 0 or 1: one)
}

// A representation texel in the variant's domain: (v − offset)·scale, clamped to ±limit,
// rounded to the nearest integer (ties to even) and wrapped into u32 for fixed point, or kept
// as f32 bits; channels past `channels` are 0 (a texture without alpha reads alpha as 1).
fn sat_encode(v: vec4<f32>, p: SatParams) -> vec4<u32> {
    return sat_encode_as(v, p, p.float_sums != 0u);
}

// `sat_encode` for the variant `float_sums` (a kernel of one variant passes a constant).
fn sat_encode_as(v: vec4<f32>, p: SatParams, float_sums: bool) -> vec4<u32> {
    let x = clamp((v - p.offset) * p.scale, -p.limit, p.limit);
    let used = vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(p.channels);
    var e = bitcast<vec4<u32>>(x);
    if !float_sums {
        e = bitcast<vec4<u32>>(vec4<i32>(round(x)));
    }
    return select(vec4<u32>(0u), e, used);
}
