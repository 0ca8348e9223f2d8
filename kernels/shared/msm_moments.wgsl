// Moment-shadow-map moments of one linear depth (import-only module of `msm` and `msm_blur`;
// Peters & Klein 2015): (z, z², z³, z⁴), or with `quantized` their optimized 16-bit
// quantization (shared/msm_quantize).

// #import shared/msm_quantize

fn msm_moments(z: f32, quantized: bool) -> vec4<f32> {
    let z2 = z * z;
    let b = vec4<f32>(z, z2, z2 * z, z2 * z2);
    if quantized {
        return msm_quantize(b);
    }
    return b;
}
