// The optimized 16-bit moment quantization of Peters & Klein (2015), section 4.3, and its
// inverse (import-only module). The moment vector multiplies the matrices from the left (as a
// row vector); the constructors list their columns.

fn msm_quantize(b: vec4<f32>) -> vec4<f32> {
    let m = mat4x4<f32>(
        vec4<f32>(-2.07224649, 32.23703778, -68.571074599, 39.3703274134),
        vec4<f32>(13.7948857237, -59.4683975703, 82.0359750338, -35.364903257),
        vec4<f32>(0.105877704, -1.9077466311, 9.3496555107, -6.6543490743),
        vec4<f32>(9.7924062118, -33.7652110555, 47.9456096605, -23.9728048165),
    );
    return b * m + vec4<f32>(0.035955884801, 0.0, 0.0, 0.0);
}

fn msm_dequantize(q: vec4<f32>) -> vec4<f32> {
    let m = mat4x4<f32>(
        vec4<f32>(0.2227744146, 0.0771972861, 0.7926986636, 0.0319417555),
        vec4<f32>(0.1549679261, 0.1394629426, 0.7963415838, -0.1722823173),
        vec4<f32>(0.1451988946, 0.2120202157, 0.7258694464, -0.2758014811),
        vec4<f32>(0.163127443, 0.2591432266, 0.6539092497, -0.3376131734),
    );
    return (q - vec4<f32>(0.035955884801, 0.0, 0.0, 0.0)) * m;
}
