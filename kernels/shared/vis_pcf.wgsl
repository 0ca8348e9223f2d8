// Percentage-closer filtering (Reeves et al. 1987): the weighted mean of comparison results
// over a (2r + 1)² window around the receiver's texel — never a filter of depths. With the
// receiver-plane bias each tap compares the receiver plane's depth at that texel's centre.
// #import shared/light
// #import shared/sampling

// #fetches vis_pcf: (2 * l.radius + 1) * (2 * l.radius + 1)
fn vis_pcf(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let c = texel_of(s.uv, l.map_size);
    let r = i32(l.radius);
    var lit = 0.0;
    var total = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            var w = 1.0;
            if l.kernel == 1u {
                w = f32(r + 1 - abs(dx)) * f32(r + 1 - abs(dy));
            }
            let t = c + vec2<i32>(dx, dy);
            let z = load_depth(map, t);
            let d = s.depth + light_receiver_offset(l, s, light_tap_offset(l, s, t));
            lit += w * select(0.0, 1.0, d <= z + l.bias);
            total += w;
        }
    }
    return lit / total;
}

// The hardware 2×2 comparison: bilinear weights of four comparisons against the raw depth map.
// #fetches vis_pcf_hardware: 1
fn vis_pcf_hardware(map: texture_depth_2d, cmp: sampler_comparison, l: Light, s: LightSample) -> f32 {
    let reference = light_linear_to_ndc(l, clamp(s.depth - l.bias, 0.0, 1.0));
    return textureSampleCompareLevel(map, cmp, s.uv, reference);
}
