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

// The receiver's factors of the series term by term, for a pass that sums every term (CSSM's
// filter): (sin, cos) of c_k x advanced from term k to k + 1 by a rotation of 2πx, and the
// weight's Gaussian exp(−α (k/M)²) by its ratio exp(−α (2k + 1)/M²), itself advanced by
// exp(−2α/M²). Two sines and one exponential in all, where csm_chunk_of computes two sines and
// an exponential per term; the rotation's rounding grows by a few ulps a term (M ≤ 16).
struct CsmTerms {
    k: u32,
    sc: vec2<f32>,    // (sin, cos) of c_k x
    step: vec2<f32>,  // (sin, cos) of 2πx
    gauss: f32,       // exp(−α (k/M)²)
    ratio: f32,       // exp(−α (2k + 1)/M²)
    q2: f32,          // exp(−2α/M²)
}

fn csm_terms_start(x: f32, l: Light) -> CsmTerms {
    var t: CsmTerms;
    t.k = 1u;
    t.sc = csm_sin_cos(1u, x);
    t.step = vec2<f32>(2.0 * t.sc.x * t.sc.y, t.sc.y * t.sc.y - t.sc.x * t.sc.x);
    let m = f32(l.csm_terms);
    let q = exp(-l.csm_attenuation / (m * m));
    t.gauss = q;
    t.q2 = q * q;
    t.ratio = q * t.q2;
    return t;
}

// csm_chunk_of with the factors `t` at the shifted receiver depth (csm_terms_start), advanced
// past the chunk's two terms: the chunks must come in order from 0.
fn csm_terms_chunk(v: vec4<f32>, t: ptr<function, CsmTerms>, l: Light) -> f32 {
    var sum = 0.0;
    for (var j = 0u; j < 2u; j++) {
        if (*t).k > l.csm_terms {
            break;
        }
        let w = 2.0 / (CSM_PI * f32(2u * (*t).k - 1u)) * (*t).gauss;
        let basis = select(v.xy, v.zw, j == 1u);
        sum += w * ((*t).sc.y * basis.x - (*t).sc.x * basis.y);
        csm_terms_advance(t);
    }
    return sum;
}

fn csm_terms_advance(t: ptr<function, CsmTerms>) {
    let sc = (*t).sc;
    let st = (*t).step;
    (*t).sc = vec2<f32>(sc.x * st.y + sc.y * st.x, sc.y * st.y - sc.x * st.x);
    (*t).gauss *= (*t).ratio;
    (*t).ratio *= (*t).q2;
    (*t).k += 1u;
}

// w_k = (2 / c_k) · exp(−α (k / M)²): the attenuated weight of term k.
fn csm_weight(k: u32, l: Light) -> f32 {
    let kf = f32(k) / f32(l.csm_terms);
    return 2.0 / (CSM_PI * f32(2u * k - 1u)) * exp(-l.csm_attenuation * kf * kf);
}

fn csm_resolve(sum: f32, l: Light) -> f32 {
    return clamp(l.csm_scale * sum + 0.5, 0.0, 1.0);
}
