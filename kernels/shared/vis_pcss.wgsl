// Percentage-closer soft shadows (Fernando 2005), the brute-force peer of the prefiltered soft
// shadows: 1) blocker search over the region the light cone cuts from the map, 2) penumbra
// width w = size · (Z_r − Z_b) / Z_b, 3) PCF over that width. Taps lie on a Vogel disc. With
// the receiver-plane bias each tap (search and filter) compares the receiver plane's depth at
// its texel's centre.
// #import shared/light
// #import shared/sampling

// Radii are in units of a face's UV (the map's, but for a point light's atlas, whose UV is
// face UV · face_uv). On a point light and in cascades (`capped_filter`) the filter radius is
// capped at max_search as the search is, so that no tap leaves the guard band of the face
// (src/model/point.rs) or of the cascade (src/render/cascade.rs).
// Radius (UV) of the blocker search: the cone from the receiver to the light's width, at the
// near plane where it is widest, capped by max_search.
fn pcss_search_radius(l: Light, s: LightSample) -> f32 {
    let world = 0.5 * l.size * (s.view_z - l.near) / s.view_z;
    return min(world / light_map_width(l, l.near), l.max_search);
}

// #fetches vis_pcss: l.blocker_samples + l.filter_samples
fn vis_pcss(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    let search = pcss_search_radius(l, s);
    var sum = 0.0;
    var count = 0u;
    for (var i = 0u; i < l.blocker_samples; i++) {
        let t = texel_of(s.uv + search * l.face_uv * vogel_disc(i, l.blocker_samples), l.map_size);
        let z = load_depth(map, t);
        if z + l.bias < s.depth + light_receiver_offset(l, s, light_tap_offset(l, s, t)) {
            sum += z;
            count += 1u;
        }
    }
    if count == 0u {
        return 1.0;
    }
    let z_blocker = light_linear_to_z(l, sum / f32(count));
    let penumbra_world = l.size * (s.view_z - z_blocker) / z_blocker;
    var radius = max(0.5 * penumbra_world / light_map_width(l, s.view_z), 0.5 / (l.map_size.x * l.face_uv.x));
    if l.capped_filter != 0u {
        radius = min(radius, l.max_search);
    }
    var lit = 0.0;
    for (var i = 0u; i < l.filter_samples; i++) {
        let t = texel_of(s.uv + radius * l.face_uv * vogel_disc(i, l.filter_samples), l.map_size);
        let d = s.depth + light_receiver_offset(l, s, light_tap_offset(l, s, t));
        lit += select(0.0, 1.0, d <= load_depth(map, t) + l.bias);
    }
    return lit / f32(l.filter_samples);
}
