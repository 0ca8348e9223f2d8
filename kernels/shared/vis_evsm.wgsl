// Exponential variance shadow maps: Chebyshev bound on the warped moments; EVSM4 takes the
// smaller of the positive and negative bounds (which removes EVSM2's contact leaks).
// The variance floor is given in depth units² and carried through the warp's derivative at the
// occluders' mean, where the variance lives: d exp(c (2z − 1)) / dz = 2c·exp(…), so
// floor_warped = min_variance · (2c·E[warped])². (Taken at the receiver instead, the floor grows
// with the receiver's own warped depth and, for c = 40, lets ~40% of the light into the umbra.)
// #import shared/light
// #import shared/sampling

fn chebyshev_upper(mean: f32, mean_sq: f32, receiver: f32, floor: f32) -> f32 {
    if receiver <= mean {
        return 1.0;
    }
    let variance = max(mean_sq - mean * mean, floor);
    let t = receiver - mean;
    return variance / (variance + t * t);
}

// #fetches vis_evsm: sample_map
fn vis_evsm(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    return vis_evsm_of(sample_map(map, l, s), l, s);
}

// The bounds from filtered moments `m` however they were filtered.
fn vis_evsm_of(m: vec4<f32>, l: Light, s: LightSample) -> f32 {
    let w = 2.0 * (s.depth - l.bias) - 1.0;
    let pos = exp(l.exp_pos * w);
    let slope_pos = 2.0 * l.exp_pos * m.x;
    var p = chebyshev_upper(m.x, m.y, pos, l.min_variance * slope_pos * slope_pos);
    if l.moments == 4u {
        let neg = -exp(-l.exp_neg * w);
        let slope_neg = 2.0 * l.exp_neg * m.z;
        p = min(p, chebyshev_upper(m.z, m.w, neg, l.min_variance * slope_neg * slope_neg));
    }
    return linstep(l.bleed, 1.0, p);
}
