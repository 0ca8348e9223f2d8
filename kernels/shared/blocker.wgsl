// The blocker search of the soft techniques (cssm, vssm, msm_soft) as filtered lookups
// (import-only module): each technique reads the mean of its representation over the search
// square from its summed-area table, turns it into the share of texels in front of the
// receiver and their average depth z_avg, and reads the table again over the PCSS penumbra
// width. No loop over texels: the cost is the same for any light size.
//
// Widths are in shadow-map texels, squares centred on the receiver:
//   search  w_s = size·(Z − near)/Z at the near plane (the cone from the receiver to the light's
//           width, where it is widest, as PCSS's search: vis_pcss.wgsl), / light_map_width(near);
//   filter  w   = size·(Z − Z_b)/Z_b at the receiver (PCSS's penumbra, Fernando 2005), with
//           Z_b = light_linear_to_z(z_avg), / light_map_width(Z);
// both · the face's texels (map_size · face_uv), at least 1 texel and at most l.max_width (2·max_search·map_size, the square
// the fixed-point table is coded for). A NaN width (outside the map, where the result is
// discarded) reads as 1 texel.
// #import shared/light
// #import shared/vis_csm
// #import shared/vis_msm

// A search square whose estimated share of blockers is below this reads as lit, without a
// lookup at the filter width (PCSS: no blocker tap). The estimates are smooth, so a
// threshold keeps ringing (CSM-Z) and Chebyshev's tail (VSM) from turning into blockers.
const BLOCKER_MIN_SHARE: f32 = 0.01;

fn blocker_width(texels: f32, l: Light) -> f32 {
    return min(select(1.0, texels, texels > 1.0), l.max_width);
}

fn blocker_search_width(l: Light, s: LightSample) -> f32 {
    let world = l.size * (s.view_z - l.near) / s.view_z;
    return blocker_width(world / light_map_width(l, l.near) * (l.map_size.x * l.face_uv.x), l);
}

fn blocker_filter_width(l: Light, s: LightSample, z_avg: f32) -> f32 {
    let z_b = light_linear_to_z(l, z_avg);
    let penumbra = l.size * (s.view_z - z_b) / z_b;
    return blocker_width(penumbra / light_map_width(l, s.view_z) * (l.map_size.x * l.face_uv.x), l);
}

// A soft technique's two table lookups: the search (`sat_search_*`, the square snapped
// outward to texel edges, 4 loads a table) estimates the blockers (soft_blockers); the filter
// lookup at the penumbra width (`sat_filter_*`, the square's edges rounded to the nearest
// texel edges, 4 loads a table), made only where the search found some
// (share ≥ BLOCKER_MIN_SHARE), sits in a loop of `soft_filter_trips` (0 or 1) trips; elsewhere
// the receiver is lit after the search. A loop, not a branch: llvmpipe (lavapipe) runs a
// loop-free branch body (a table lookup's loads) for its whole SIMD group whatever its lanes
// decide, but skips a loop no lane enters (measured: 64 loads under a branch never taken cost
// what they cost taken, 11.0 against 10.9 ms; a loop-bearing body under a branch or loop never
// entered, 3 against 12 ms); a GPU runs either as a branch.
struct SoftLookup {
    width: f32,          // texels: the square the filter lookup reads
    blocker: vec2<f32>,  // (z_avg, share) from the search
    blockers: bool,      // whether the search found any (the filter lookup is made)
}

// After the search's estimate b = (z_avg, share): the penumbra width of z_avg.
fn soft_blockers(b: vec2<f32>, l: Light, s: LightSample) -> SoftLookup {
    var look: SoftLookup;
    look.width = blocker_filter_width(l, s, b.x);
    look.blocker = b;
    look.blockers = b.y >= BLOCKER_MIN_SHARE;
    return look;
}

// The trips of the filter lookup's loop: 1 where the search found blockers, else 0.
fn soft_filter_trips(look: SoftLookup) -> u32 {
    return select(0u, 1u, look.blockers);
}

// The blocker estimates of a search square's cells combined: the share is the cells' shares
// weighted by their areas, z_avg the cells' z_avg weighted by their blockers (area · share).
struct BlockerSum {
    z: f32,      // Σ area · share · z_avg
    share: f32,  // Σ area · share
    area: f32,   // Σ area
}

// An empty cell (area 0: its moments are the table's offset, any estimate of them) adds
// nothing, selected rather than multiplied so that no value of its estimate can reach the sum.
fn blocker_add(acc: BlockerSum, b: vec2<f32>, area: f32) -> BlockerSum {
    let blockers = area * max(b.y, 0.0);
    let add = select(vec3<f32>(0.0), vec3<f32>(blockers * b.x, blockers, area), area > 0.0);
    return BlockerSum(acc.z + add.x, acc.share + add.y, acc.area + add.z);
}

// (z_avg, share) of the cells summed in `acc`, receiver depth d.
fn blocker_total(acc: BlockerSum, d: f32) -> vec2<f32> {
    let share = acc.share / max(acc.area, 1.0);
    return blocker_result(acc.z / max(acc.share, 1e-30), share, d);
}

// (z_avg, share) from a blocker depth estimate `z` and share: z clamped to [0, d] (blockers
// are in front of the receiver d).
fn blocker_result(z: f32, share: f32, d: f32) -> vec2<f32> {
    return vec2<f32>(clamp(z, 0.0, max(d, 0.0)), share);
}

// VSM moments m = (μ, E[z²]) over the search square, receiver depth d (Yang et al. 2010):
// Chebyshev's one-tailed bound p on the share of texels at or behind d, and with those texels
// taken at d, μ = p·d + (1 − p)·z_avg, so z_avg = (μ − p·d)/(1 − p). σ² is floored at `floor`.
fn blocker_vsm(m: vec4<f32>, d: f32, floor: f32) -> vec2<f32> {
    let variance = max(m.y - m.x * m.x, floor);
    let t = d - m.x;
    let p = select(1.0, variance / (variance + t * t), t > 0.0);
    let share = 1.0 - p;
    return blocker_result((m.x - p * d) / max(share, BLOCKER_MIN_SHARE), share, d);
}

// Biased MSM moments over the search square, receiver depth d: the three-point distribution
// through d that Hamburger MSM reconstructs (support d, z₂ ≤ z₃; msm_roots) carries the
// blockers at the support points in front of d; z_avg is their weighted mean, the share their
// weight. Weights from the Vandermonde system, w_i = E[Π_{j≠i} (z − z_j)] / Π_{j≠i} (z_i − z_j):
// d ≤ z₂: none; z₂ < d ≤ z₃: z₂ alone, share w₂ (= MSM's shadow intensity); d > z₃: both,
// share 1 − w₁ (= MSM's intensity) with w₃ = 1 − w₁ − w₂. Each support point is clamped to
// [0, d] before averaging: as d crosses the value where z₃ passes through ±∞ (the roots
// reorder), a point far outside [0, 1] carries a vanishing weight whose product with its depth
// need not vanish; clamped, it does, and z_avg stays continuous. Degenerate moments: a single
// point at μ, or (rank-deficient) the two-moment estimate.
fn blocker_msm(mm: MsmMoments, d: f32) -> vec2<f32> {
    let b = mm.b;
    let roots = msm_roots(mm, d);
    if roots.z == 1.0 {
        return vec2<f32>(b.x, select(0.0, 1.0, d > b.x));
    }
    if roots.z == 2.0 {
        return blocker_vsm(b, d, 0.0);
    }
    let z2 = roots.x;
    let z3 = roots.y;
    if d <= z2 {
        return vec2<f32>(max(d, 0.0), 0.0);
    }
    let w2 = msm_expect(mm, d, z3) / ((z3 - z2) * (d - z2));
    if d <= z3 {
        return blocker_result(z2, w2, d);
    }
    let w1 = msm_expect(mm, z2, z3) / ((d - z2) * (d - z3));
    let share = 1.0 - w1;
    let z = w2 * clamp(z2, 0.0, d) + (share - w2) * clamp(z3, 0.0, d);
    return blocker_result(z / max(share, BLOCKER_MIN_SHARE), share, d);
}

// The CSM-Z basis (Annen et al. 2008): with f̄(d, z) = 1 − f(d, z) the complementary test
// (1 where z < d) in CSM's Fourier expansion,
//   f̄(d, z)·z ≈ ½ z − Σ_k w_k [cos(c_k d)·z sin(c_k z) − sin(c_k d)·z cos(c_k z)],
// linear in the images z, z·sin(c_k z), z·cos(c_k z), which `csm_z` writes in the order
// [z, z·sin c₁z, z·cos c₁z, z·sin c₂z, …], four to a map. This is map `chunk`'s share of
// E[f̄·z] from its filtered values v, at the shifted receiver depth CSM uses.
fn csm_z_chunk_of(v: vec4<f32>, chunk: u32, l: Light, s: LightSample) -> f32 {
    let d = s.depth - l.bias - l.csm_offset;
    var sum = 0.0;
    for (var c = 0u; c < 4u; c++) {
        let i = 4u * chunk + c;
        let k = (i + 1u) / 2u;
        let sc = csm_sin_cos(max(k, 1u), d);
        // Odd i: z·sin c_k z, weighted −w_k cos(c_k d); even i > 0: z·cos, weighted w_k sin.
        var weight = select(csm_weight(max(k, 1u), l) * sc.x, -csm_weight(max(k, 1u), l) * sc.y,
            (i & 1u) == 1u);
        weight = select(weight, 0.5, i == 0u);
        sum += select(0.0, weight * v[c], i <= 2u * l.csm_terms);
    }
    return sum;
}

// CSSM's blocker estimate from the search square's sums: `below` = Σ csm_chunk_of over the
// basis maps = E[f] − ½ (unscaled), `zsum` = Σ csm_z_chunk_of over the CSM-Z maps = E[f̄·z].
// Share E[f̄] = ½ − below, z_avg = E[f̄·z] / E[f̄] (seed 000: the denominator is 1 − the
// filtered CSM test).
fn blocker_csm_z(below: f32, zsum: f32, d: f32) -> vec2<f32> {
    let share = 0.5 - below;
    return blocker_result(zsum / max(share, BLOCKER_MIN_SHARE), share, d);
}
