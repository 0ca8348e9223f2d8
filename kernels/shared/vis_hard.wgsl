// Hard shadow test (Williams 1978): lit when d ≤ z_map + bias at the nearest texel.
// #import shared/light
// #import shared/sampling

// #fetches vis_hard: 1
fn vis_hard(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let z = load_depth(map, texel_of(s.uv, l.map_size));
    return select(0.0, 1.0, s.depth <= z + l.bias);
}
