//! The soft techniques' tolerances: `vssm`'s, `msm_soft`'s and `cssm`'s chains, each
//! perturbed through its f64 reference (see the module above).

use super::*;

/// Soft VSM's tolerance at `s` over the table values `t` (see [`Chain`]).
pub fn vssm_tolerance(
    t: &Integral,
    err: &TableError,
    l: &LightGpu,
    s: &LightSample,
    v0: f64,
) -> Option<f64> {
    use cpu::vis_vssm as v;
    let b0 = v::blocker_of(&v::search(t, l, s), l, s);
    let width = cpu::blocker::filter_width(l, s, b0.depth);
    let el = grid_flips(t, l, s, width, err.mean(l, s, width));
    let search = |du| flat_cells(&v::search(t, l, &shifted(s, du)), 2, <[f64]>::to_vec);
    let errors = |m: &[f64]| cell_errors(m, 2, |_, area| err.cell(area));
    Chain {
        search: &search,
        e_search: errors(&search([0.0; 2])),
        cells: cpu::blocker::SEARCH_CELLS.pow(2) as usize,
        cell_errors: Some(&errors),
        blocker: &|m, dd| v::blocker_of(&unflat_cells(m, 2), l, &moved(s, dd)),
        finish: &|z| v::finish(t, l, s, Blocker { depth: z, ..b0 }),
        last: &|du| v::filtered(t, l, &shifted(s, du), b0)[..2].to_vec(),
        e_last: el[..2].to_vec(),
        visibility: &|m, dd| cpu::vis_vsm::vis_vsm_of(m, l, &moved(s, dd)),
        e_depth: depth_error(l, s),
        filter_box: &|z| filter_box(l, s, z),
        grid: true,
    }
    .tolerance(v0)
}

/// MSM's error in the moment domain: the table error carried through the dequantization
/// (its matrix's absolute column sums), plus 32·2⁻²⁴ relative (the kernel's solve is backward
/// stable in the moments: the GPU's answer is exact for moments that close, as in
/// `msm_tolerance`). Perturbed moments are then projected and biased, as the kernel does.
fn msm_moment_error(l: &LightGpu, m: &[f64], e: [f64; 4]) -> [f64; 4] {
    msm_dequantized_error(l, &cpu::vis_msm::dequantized(m, l), e)
}

/// [`msm_moment_error`] of moments already dequantized, `b`.
fn msm_dequantized_error(l: &LightGpu, b: &[f64], e: [f64; 4]) -> [f64; 4] {
    let carried: [f64; 4] = if l.msm_flags & MSM_QUANTIZED != 0 {
        let zero = cpu::msm::dequantize([0.0; 4]);
        let mut out = [0.0; 4];
        for (j, ej) in e.iter().enumerate() {
            let mut unit = [0.0; 4];
            unit[j] = 1.0;
            let col = cpu::msm::dequantize(unit);
            for c in 0..4 {
                out[c] += (col[c] - zero[c]).abs() * ej;
            }
        }
        out
    } else {
        e
    };
    std::array::from_fn(|c| carried[c] + 32.0 * ULP * b[c].abs())
}

/// The biased moments of dequantized moments `b` (a slice of four).
fn msm_bias(l: &LightGpu, b: &[f64]) -> cpu::vis_msm::Biased {
    cpu::vis_msm::bias_for([b[0], b[1], b[2], b[3]], l)
}

/// Soft MSM's tolerance at `s` (see [`Chain`]), perturbing the dequantized moments.
pub fn msm_soft_tolerance(
    t: &Integral,
    err: &TableError,
    l: &LightGpu,
    s: &LightSample,
    v0: f64,
) -> Option<f64> {
    use cpu::vis_msm_soft as v;
    let b0 = v::blocker_of(&v::search(t, l, s), l, s);
    let dequantized = |m: &[f64]| cpu::vis_msm::dequantized(m, l).to_vec();
    let search = |du| flat_cells(&v::search(t, l, &shifted(s, du)), 4, dequantized);
    let errors =
        |m: &[f64]| cell_errors(m, 4, |b, area| msm_dequantized_error(l, b, err.cell(area)));
    let d = s.depth - f64::from(l.bias);
    let cell_blockers = |m: &[f64], dd: f64| {
        let each = unflat_cells(m, 4)
            .into_iter()
            .filter(|(_, area)| *area > 0.0)
            .map(|(b, area)| (cpu::blocker::msm(&msm_bias(l, &b), d + dd), area))
            .collect::<Vec<_>>();
        cpu::blocker::combine(each, d + dd)
    };
    let width = cpu::blocker::filter_width(l, s, b0.depth);
    let last0 = v::filtered(t, l, s, b0);
    let el = msm_moment_error(l, &last0, grid_flips(t, l, s, width, err.mean(l, s, width)));
    Chain {
        search: &search,
        e_search: errors(&search([0.0; 2])),
        cells: cpu::blocker::SEARCH_CELLS.pow(2) as usize,
        cell_errors: Some(&errors),
        blocker: &cell_blockers,
        finish: &|z| v::finish(t, l, s, Blocker { depth: z, ..b0 }),
        last: &|du| cpu::vis_msm::dequantized(&v::filtered(t, l, &shifted(s, du), b0), l).to_vec(),
        e_last: el.to_vec(),
        visibility: &|b, dd| cpu::vis_msm::visibility(&msm_bias(l, b), d + dd, l),
        e_depth: depth_error(l, s),
        filter_box: &|z| filter_box(l, s, z),
        grid: true,
    }
    .tolerance(v0)
}

/// CSSM's tolerance at `s` (see [`Chain`]). The series carry, per term, the error of the two
/// receiver factors (`e_trig`, the device's sin/cos error, plus c_M times the depth error)
/// against basis values of magnitude ≤ 1, and the error of the two means; E[z]'s mean error
/// enters ½-weighted; a 2M-term f32 sum adds 4M roundings. The sharpened result `v^p` is
/// `exp2(p·log2 v)`: log2 to 2⁻²¹ absolute (Vulkan, near 1; 3 ULP elsewhere is smaller here),
/// exp2 to (3 + 2|x|) ULP.
pub fn cssm_tolerance(
    maps: cpu::vis_cssm::Maps,
    err: (&TableError, &TableError),
    e_trig: f64,
    l: &LightGpu,
    s: &LightSample,
    v0: f64,
) -> Option<f64> {
    use cpu::vis_cssm as v;
    let kind = maps.kind;
    let search0 = v::search(maps, l, s);
    let b0 = v::blocker_of(kind, &search0, l, s);
    let terms = l.csm_terms;
    let e_d = depth_error(l, s);
    let e_factor = e_trig + std::f64::consts::PI * f64::from(2 * terms - 1) * e_d;
    let series_error = |e_basis: [f64; 4]| {
        let e = e_basis.iter().copied().fold(0.0, f64::max);
        (1..=terms)
            .map(|k| cpu::vis_csm::weight(k, l) * 2.0 * (e_factor + e))
            .sum::<f64>()
            + 8.0 * f64::from(terms) * ULP
    };
    let ws = cpu::blocker::search_width(l, s);
    // The moment search's means carry their tables' error as msm_soft's raw moments do; the
    // CSM-Z search's two series carry theirs per term, E[z]'s mean error ½-weighted.
    let e_search = match kind {
        CssmSearch::Moments => msm_moment_error(l, &search0, err.1.mean(l, s, ws)).to_vec(),
        CssmSearch::CsmZ => {
            let ez = err.1.mean(l, s, ws);
            vec![
                series_error(err.0.mean(l, s, ws)),
                series_error(ez) + 0.5 * ez[0],
            ]
        }
    };
    let width = cpu::blocker::filter_width(l, s, b0.depth);
    let sum = v::filtered(maps, l, s, b0);
    let e_sum = series_error(grid_flips(maps.basis, l, s, width, err.0.mean(l, s, width)));
    let pow = if b0.found() {
        let p = v::exponent(l, s, b0);
        let base = cpu::vis_csm::resolve(sum, l);
        let x = p * base.max(f64::MIN_POSITIVE).log2();
        v0 * (p * 2f64.powi(-21) * std::f64::consts::LN_2 + (3.0 + 2.0 * x.abs()) * 2.0 * ULP)
    } else {
        0.0
    };
    // The two-depth resolve's two series f_r, f_b carry the device's sin/cos error per term
    // (series_error without basis error, sinc's sin/t included: its argument is exact to
    // 2⁻²⁴ relative); v₂ = 1 − (f_r − sum)/c moves by at most 2e/c for each of f_r and f_b
    // (|f_r − sum| ≤ c where v₂ is inside [0, 1]), c ≥ MIN_CONTRAST; the blend weight's slope
    // is at most 1.5/(FULL − MIN) per unit of c, times |v₁^p − min(v₁, v₂)| ≤ 1.
    let two_depth = if b0.found() && l.cssm_two_depth != 0 {
        let e = 2.0 * series_error([0.0; 4]);
        4.0 * e / v::MIN_CONTRAST + 1.5 / (v::FULL_CONTRAST - v::MIN_CONTRAST) * 2.0 * e
    } else {
        0.0
    };
    // With the blockers' depth over the filter square (`cssm_two_depth == 2`) the final step
    // also reads the moments' table there: its four means carry their table's error as the
    // search's do, and the depth comes from them again under each perturbation.
    let refine = l.cssm_two_depth == 2;
    let last = |du: [f64; 2]| {
        let t = shifted(s, du);
        let mut inputs = vec![v::filtered(maps, l, &t, b0)];
        if refine {
            inputs.extend(maps.search.filter_square_mean(l.map_size, t.uv, width));
        }
        inputs
    };
    let mut e_last = vec![e_sum];
    if refine {
        let means = maps.search.filter_square_mean(l.map_size, s.uv, width);
        let e = grid_flips(maps.search, l, s, width, err.1.mean(l, s, width));
        e_last.extend(msm_moment_error(l, &means, e));
    }
    Chain {
        search: &|du| v::search(maps, l, &shifted(s, du)),
        e_search,
        cells: 1,
        cell_errors: None,
        blocker: &|m, dd| v::blocker_of(kind, m, l, &moved(s, dd)),
        finish: &|z| v::finish(maps, l, s, Blocker { depth: z, ..b0 }),
        last: &last,
        e_last,
        visibility: &|m, dd| {
            let t = moved(s, dd);
            let z_b = if refine {
                v::filter_blockers(&m[1..], l, &t, b0)
            } else {
                b0.depth
            };
            v::resolve(m[0], l, &t, b0, width, z_b)
        },
        e_depth: e_d,
        filter_box: &|z| filter_box(l, s, z),
        grid: maps.basis.is_filtered(),
    }
    .tolerance(v0)
    .map(|t| t + 2.0 * pow + two_depth)
}
