// A value rounded as a 16-bit storage format would hold it (import-only module of
// shared/sat_tile_texel, whose depth-sourced tables sum the values a stored map would hold;
// tests/csm_sat/storage_round.rs checks both bit for bit against f64).

// `v` rounded to f16 and back (to nearest, ties to even): in f16's normal range the f32 significand rounded to 11 bits on its bits
// (a carry moves into the exponent), below it (|v| < 2⁻¹⁴) to f16's subnormal step 2⁻²⁴. Exact
// integer and power-of-two operations where `pack2x16float` and `unpack2x16float` cost llvmpipe
// a software conversion each. For |v| < 65504 (the basis and MSM's quantized moments lie
// within ±2).
fn round_f16(v: vec4<f32>) -> vec4<f32> {
    let b = bitcast<vec4<u32>>(v);
    let odd = (b >> vec4<u32>(13u)) & vec4<u32>(1u);
    let normal = bitcast<vec4<f32>>((b + vec4<u32>(0xFFFu) + odd) & vec4<u32>(0xFFFFE000u));
    let tiny = round(v * 16777216.0) * (1.0 / 16777216.0);
    return select(normal, tiny, abs(v) < vec4<f32>(6.103515625e-5));
}

// `v` rounded to 16-bit unorm and back, as `pack2x16unorm` / `unpack2x16unorm` define it: the
// code ⌊½ + 65535·v⌋ with the product in f32, so within 2⁻⁹ of a tie it may round either way.
fn round_unorm16(v: vec4<f32>) -> vec4<f32> {
    return floor(0.5 + 65535.0 * clamp(v, vec4<f32>(0.0), vec4<f32>(1.0))) / 65535.0;
}
