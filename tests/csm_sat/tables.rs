//! Every case's layered tables, texel by texel, against the f64 basis of the f64
//! linear depth; interleaving, dispatches, non-finite counts and the kernels' layouts.

use super::*;

fn check(g: &Gpu, seed: u64, case: &Case) {
    let what = format!(
        "{}×{} M = {} search {:?} moments {:?} {:?} {:?}",
        case.w, case.h, case.terms, case.search, case.moments, case.variant, case.storage
    );
    let mut rng = common::rng(seed);
    let (raw, lin) = depth(&mut rng, case.w, case.h, case.bad);
    // VSM's second moment passes 1 at depth steps near z = 1 (the derivative term); EVSM's
    // moments span ±exp(2c).
    let (lo, hi) = match case.moments {
        Some(Moments::Vsm) => (-1.0, 2.0),
        Some(Moments::Evsm { .. }) => {
            let e = (2.0 * case.exp[0].max(case.exp[1])).exp();
            (-e, e)
        }
        _ => (-1.0, 1.0),
    };
    let coding = match case.variant {
        SatVariant::Fixed => SatCoding::fixed(lookup_area(24.0, 24.0), [lo; 4], [hi; 4]),
        SatVariant::Float => SatCoding::float([lo; 4], [hi; 4]),
    }
    .expect("coding");
    // The shipped layout: fixed-point basis tables interleaved as many a texture as fit.
    let layers = if case.moments.is_some() {
        1
    } else {
        basis_sequence(case.terms, case.search).len() as u32
    };
    let interleave = basis_interleave(case.w as u32, layers, case.variant);
    let (tables, steps, stats) = run(g, case, &raw, coding, interleave);
    // The redesign layout (on a device with subgroups the tile passes by subgroup scans,
    // shared/sat_strip): the same dispatches and counts, fixed-point tables bit for bit, f32
    // tables checked below against the same reference and tolerance.
    let redesign = run_in(g, case, &raw, coding, interleave, KernelLayout::Redesign);
    assert_eq!(redesign.1, steps, "{what}: the redesign's dispatches");
    assert_eq!(redesign.2, stats, "{what}: the redesign's non-finite count");
    if case.variant == SatVariant::Fixed {
        for (m, (a, b)) in tables.iter().zip(&redesign.0).enumerate() {
            if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
                panic!(
                    "{what} table {m}: redesign word {i} is {:#x}, shipped {:#x}",
                    b[i], a[i]
                );
            }
        }
    }
    if interleave > 1 {
        // A texture a table, and two a texture (the last holding the rest: with nine tables
        // five textures, two pass-3 dispatches), hold the same words (each its own channels;
        // an interleaved table has its texture's, the widest table's, the rest 0).
        let texels = case.w * case.h;
        for other in [1, 2] {
            let (words, steps_other, _) = run(g, case, &raw, coding, other);
            for (m, (a, t)) in words.iter().zip(&tables).enumerate() {
                let (na, nt) = (a.len() / texels, t.len() / texels);
                let n = na.min(nt);
                let same = a.chunks(na).zip(t.chunks(nt)).all(|(x, y)| {
                    x[..n] == y[..n] && x[n..].iter().chain(&y[n..]).all(|&w| w == 0)
                });
                assert!(
                    same,
                    "{what} table {m}: {other} a texture against {interleave}, it differs"
                );
            }
            let textures = tables.len().div_ceil(other as usize);
            assert_eq!(
                steps_other,
                2 + textures.div_ceil(LAYERED_SAT_OUTPUTS as usize),
                "{what}: dispatches, {other} tables a texture"
            );
        }
    }
    let [c_pos, c_neg] = case.exp.map(f64::from);
    let want = match case.moments {
        Some(Moments::Msm) => vec![cpu::msm::msm(&lin, true)],
        Some(Moments::Vsm) => vec![cpu::vsm::vsm(&lin)],
        Some(Moments::Evsm { four }) => {
            let m = cpu::evsm::evsm(&lin, c_pos, c_neg);
            let n = if four { 4 } else { 2 };
            vec![Texels {
                channels: n,
                data: m.data.chunks(4).flat_map(|t| t[..n].to_vec()).collect(),
                ..m
            }]
        }
        Some(Moments::Esm) => vec![cpu::esm::esm_linear(&lin, c_pos)],
        None => basis(&lin, case.terms, case.search),
    };
    let moments = case.search == Some(CssmSearch::Moments);
    assert_eq!(tables.len(), want.len(), "{what}: tables");
    // The edges of every layer, the carries, four textures a dispatch.
    let per = LAYERED_SAT_OUTPUTS as usize;
    let textures = want.len().div_ceil(interleave as usize);
    assert_eq!(steps, 2 + textures.div_ceil(per), "{what}: dispatches");
    // Pass 1's layer 0 counts each non-finite texel once; nothing else counts.
    assert_eq!(stats, vec![case.bad as u32], "{what}: non-finite count");
    let texels = case.w * case.h;
    for (m, (words, v)) in tables.iter().zip(&want).enumerate() {
        let n = v.channels;
        // The format has the channels, or four for three (no three-channel format); the
        // fourth is 0 (the kernel's basis is 0 past the sequence). Interleaved tables have
        // their texture's format, the widest of its tables'.
        let stride = words.len() / texels;
        assert!(
            words.len() == texels * stride
                && stride >= n
                && (stride == n || interleave > 1 || n == 3),
            "{what} table {m}: {stride} channels for {n}"
        );
        assert!(
            words.chunks(stride).all(|t| t[n..].iter().all(|&w| w == 0)),
            "{what} table {m}: unused channel"
        );
        let decoded = decode_table(words, case.w, case.h, &coding, n);
        // MSM's quantized moments: MSM's table, or CSSM's moment map (its last table).
        let quantized = case.moments == Some(Moments::Msm) || (moments && m == want.len() - 1);
        let mut tol: Vec<f64> = v
            .data
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                // EVSM's channels: pos, pos², neg, neg².
                let channel = i % v.channels;
                if case.moments == Some(Moments::Vsm) {
                    vsm_tolerance(case.storage, x)
                } else if let Some(Moments::Evsm { .. }) = case.moments {
                    let c = if channel < 2 { c_pos } else { c_neg };
                    exp_tolerance(c, channel % 2 == 1, case.storage, x)
                } else if case.moments == Some(Moments::Esm) {
                    exp_tolerance(c_pos, false, case.storage, x)
                } else if quantized {
                    msm_tolerance(case.storage, x)
                } else {
                    basis_tolerance(case.terms, case.storage, x)
                }
            })
            .collect();
        if case.variant == SatVariant::Fixed {
            // Each code is rounded (½/scale; one scale for every channel of [−1, 1]) from the
            // f32 value less the offset (0 here); decoding rounds to f32 once more.
            assert!(coding.scale.iter().all(|&s| s == coding.scale[0]));
            let quantum = 0.5 / f64::from(coding.scale[0]);
            tol.iter_mut().for_each(|t| *t += quantum + U);
            common::assert_within(&format!("{what} table {m}"), &decoded, &v.data, &tol);
        } else {
            check_float(&format!("{what} table {m}"), words, v, &coding, &tol);
            let what = format!("{what} table {m}, redesign");
            check_float(&what, &redesign.0[m], v, &coding, &tol);
        }
    }
}

/// The f32 table against the f64 table of the f64 basis: within the scan tree's rounding,
/// `float_sum_depth`·U·Σ|x| over each texel's rectangle, plus the basis error summed over it.
fn check_float(what: &str, words: &[u32], v: &Texels, coding: &SatCoding, basis_tol: &[f64]) {
    let exact = reference::sat(&reference::scaled_texels(v, coding));
    let abs = reference::sat(&Texels {
        data: v.data.iter().map(|x| x.abs()).collect(),
        ..v.clone()
    });
    let errors = reference::sat(&Texels {
        data: basis_tol.to_vec(),
        ..v.clone()
    });
    let depth = f64::from(float_sum_depth(v.width as u32, v.height as u32));
    let n = v.channels;
    let stride = words.len() / (v.width * v.height);
    let got: Vec<f32> = words
        .chunks(stride)
        .flat_map(|t| t[..n].iter().map(|&b| f32::from_bits(b)))
        .collect();
    let mut want = Vec::with_capacity(got.len());
    let mut tol = Vec::with_capacity(got.len());
    for i in 0..v.width * v.height {
        for c in 0..n {
            want.push(exact.data[i * 4 + c]);
            tol.push(depth * U * abs.data[i * n + c] + errors.data[i * n + c]);
        }
    }
    common::assert_within(what, &got, &want, &tol);
}

#[test]
fn layered_csm_tables_match_the_f64_basis() {
    let g = common::gpu();
    let cases = [
        // CSSM M = 8 (4 + 5 tables, three pass-3 dispatches), 4 × 3 tiles, the last ragged.
        Case {
            w: 200,
            h: 130,
            terms: 8,
            search: Some(CssmSearch::CsmZ),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 11,
        },
        // Odd M: the last CSM table two channels, the last CSM-Z one three; f32 sums.
        Case {
            w: 70,
            h: 150,
            terms: 3,
            search: Some(CssmSearch::CsmZ),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F32,
            bad: 6,
        },
        // CSM alone, M = 16 (8 tables, two dispatches), one exact tile, f16 storage.
        Case {
            w: 64,
            h: 64,
            terms: 16,
            search: None,
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F16,
            bad: 5,
        },
        // CSSM M = 8 with the moment search (4 + 1 tables, two pass-3 dispatches).
        Case {
            w: 200,
            h: 130,
            terms: 8,
            search: Some(CssmSearch::Moments),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 7,
        },
        // The moment search at odd M, f32 sums, f16 storage.
        Case {
            w: 90,
            h: 70,
            terms: 5,
            search: Some(CssmSearch::Moments),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 6,
        },
        // MSM's quantized moments alone (msm_soft, msm with `filter = "sat"`): one layer, no
        // terms; unorm16 and f16 rounding, both variants.
        Case {
            w: 150,
            h: 100,
            terms: 0,
            search: None,
            moments: Some(Moments::Msm),
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::Unorm16,
            bad: 7,
        },
        Case {
            w: 64,
            h: 97,
            terms: 0,
            search: None,
            moments: Some(Moments::Msm),
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 5,
        },
        Case {
            w: 33,
            h: 70,
            terms: 0,
            search: None,
            moments: Some(Moments::Msm),
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 6,
        },
        // Lines of more than one segment of the redesign's carries (64 tiles,
        // `kernels/sat_carries_scan.wgsl`), layered: CSM at M = 4 (two tables), 66 tiles
        // across, ragged, fixed point; CSM and CSM-Z at M = 2 (two tables), 66 tiles down, f32.
        Case {
            w: 2090,
            h: 40,
            terms: 4,
            search: None,
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 5,
        },
        Case {
            w: 40,
            h: 2090,
            terms: 2,
            search: Some(CssmSearch::CsmZ),
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F32,
            bad: 5,
        },
        // CSM at M = 1: one two-channel table, so two-channel edges and carries.
        Case {
            w: 40,
            h: 33,
            terms: 1,
            search: None,
            moments: None,
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 5,
        },
        // VSM's moments alone (vssm, vsm with `filter = "sat"`): one two-channel layer, the
        // derivatives from the neighbours' depth at ragged tile and map edges; both variants,
        // f32 and f16.
        Case {
            w: 150,
            h: 77,
            terms: 0,
            search: None,
            moments: Some(Moments::Vsm),
            exp: [0.0; 2],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 7,
        },
        Case {
            w: 64,
            h: 97,
            terms: 0,
            search: None,
            moments: Some(Moments::Vsm),
            exp: [0.0; 2],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 6,
        },
        // EVSM's moments (evsm4 and evsm2 with `filter = "sat"`) and ESM's exp(c (z − 1))
        // (esm with `filter = "sat"`): one layer of four, two and one channel.
        Case {
            w: 130,
            h: 70,
            terms: 0,
            search: None,
            moments: Some(Moments::Evsm { four: true }),
            exp: [5.0, 4.0],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 6,
        },
        Case {
            w: 70,
            h: 45,
            terms: 0,
            search: None,
            moments: Some(Moments::Evsm { four: false }),
            exp: [5.5, 0.0],
            variant: SatVariant::Float,
            storage: Storage::F16,
            bad: 5,
        },
        Case {
            w: 100,
            h: 67,
            terms: 0,
            search: None,
            moments: Some(Moments::Esm),
            exp: [20.0, 0.0],
            variant: SatVariant::Fixed,
            storage: Storage::F32,
            bad: 6,
        },
    ];
    for (k, case) in cases.iter().enumerate() {
        check(&g, 0xC55 + k as u64, case);
    }
}
