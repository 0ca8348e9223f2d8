// Hard shadow test (Williams 1978): lit when d ≤ z_map + bias at the nearest texel, d moved
// along the receiver plane to the texel's centre when the receiver-plane bias is on.
// #import shared/light
// #import shared/sampling

// #fetches vis_hard: 1
fn vis_hard(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let t = texel_of(s.uv, l.map_size);
    let z = load_depth(map, t);
    let d = s.depth + light_receiver_offset(l, s, light_tap_offset(l, s, t));
    return select(0.0, 1.0, d <= z + l.bias);
}
