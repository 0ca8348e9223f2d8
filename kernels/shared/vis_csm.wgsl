// Convolution shadow maps (Annen et al. 2007): the step H(z − d) as its Fourier series
//   f(d, z) ≈ ½ + Σ_k w_k [cos(c_k d) sin(c_k z) − sin(c_k d) cos(c_k z)],
//   c_k = π (2k − 1),  w_k = (2 / c_k) · exp(−α (k / M)²)   (α: ringing attenuation),
// linear in the basis images, so their filtered values give the filtered test. d is shifted by
// an offset so a receiver at its own depth is not read as ½, and the response is scaled about
// ½ and clamped to [0, 1], which cuts the remaining ringing (seed 000).
// The shading block sums `csm_chunk` over the light's maps (two terms each), then calls
// `csm_resolve`.
// #import shared/light
// #import shared/sampling
// #import shared/csm_basis

// Terms 2·chunk + 1 and 2·chunk + 2 (those ≤ M) of the series at this receiver.
// #fetches csm_chunk: sample_map
fn csm_chunk(map: texture_2d<f32>, chunk: u32, l: Light, s: LightSample) -> f32 {
    return csm_chunk_of(sample_map(map, l, s), chunk, l, s);
}

// The same from the chunk's filtered basis values `v` however they were filtered.
fn csm_chunk_of(v: vec4<f32>, chunk: u32, l: Light, s: LightSample) -> f32 {
    let d = s.depth - l.bias - l.csm_offset;
    var sum = 0.0;
    for (var j = 0u; j < 2u; j++) {
        let k = 2u * chunk + 1u + j;
        if k > l.csm_terms {
            break;
        }
        let w = csm_weight(k, l);
        let basis = select(v.xy, v.zw, j == 1u);
        let sc = csm_sin_cos(k, d);
        sum += w * (sc.y * basis.x - sc.x * basis.y);
    }
    return sum;
}

// w_k = (2 / c_k) · exp(−α (k / M)²): the attenuated weight of term k.
fn csm_weight(k: u32, l: Light) -> f32 {
    let kf = f32(k) / f32(l.csm_terms);
    return 2.0 / (CSM_PI * f32(2u * k - 1u)) * exp(-l.csm_attenuation * kf * kf);
}

fn csm_resolve(sum: f32, l: Light) -> f32 {
    return clamp(l.csm_scale * sum + 0.5, 0.0, 1.0);
}
