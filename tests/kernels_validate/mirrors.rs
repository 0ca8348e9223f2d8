//! Rust mirrors of WGSL structs and constants match naga's layouts and the WGSL's values.

use super::*;

#[test]
fn rust_mirrors_match_naga_layouts() {
    let shade = kernels::resolve("shade", Some(&shading_block(&[light(Technique::Hard)]))).unwrap();
    let (m, _) = kernels::reflect("shade", &shade).unwrap();
    assert_eq!(
        struct_size(&m, "Light"),
        Some(size_of::<LightGpu>() as u32),
        "LightGpu vs struct Light"
    );
    assert_eq!(
        struct_size(&m, "Frame"),
        Some(size_of::<shadowgraph::low_level::wgsl_mirrors::FrameGpu>() as u32),
        "FrameGpu vs struct Frame"
    );
    use shadowgraph::low_level::filter::BlurParams;
    use shadowgraph::low_level::technique::CsmSatParams;
    use shadowgraph::low_level::wgsl_mirrors::{
        CsmParams, ExpParams, MsmParams, SecondDepthParams, VsmParams,
    };
    for (kernel, rust) in [
        ("second_depth", size_of::<SecondDepthParams>()),
        ("csm", size_of::<CsmParams>()),
        ("csm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("csm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("csm_sat_tiles", size_of::<CsmSatParams>()),
        ("csm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("msm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("msm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("msm_sat_tiles", size_of::<CsmSatParams>()),
        ("msm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("vsm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("vsm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("vsm_sat_tiles", size_of::<CsmSatParams>()),
        ("vsm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("evsm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("evsm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("evsm_sat_tiles", size_of::<CsmSatParams>()),
        ("evsm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("esm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("esm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("esm_sat_tiles", size_of::<CsmSatParams>()),
        ("esm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("vsm", size_of::<VsmParams>()),
        ("evsm", size_of::<ExpParams>()),
        ("esm", size_of::<ExpParams>()),
        ("msm", size_of::<MsmParams>()),
        // The encodings fused into the blur: the encoding's parameters, then the blur's.
        ("vsm_blur", size_of::<VsmParams>() + size_of::<BlurParams>()),
        (
            "vsm_blur_row",
            size_of::<VsmParams>() + size_of::<BlurParams>(),
        ),
        (
            "evsm_blur",
            size_of::<ExpParams>() + size_of::<BlurParams>(),
        ),
        ("msm_blur", size_of::<MsmParams>() + size_of::<BlurParams>()),
        (
            "msm_blur_row",
            size_of::<MsmParams>() + size_of::<BlurParams>(),
        ),
        (
            "evsm_blur_row",
            size_of::<ExpParams>() + size_of::<BlurParams>(),
        ),
    ] {
        let wgsl = kernels::resolve(kernel, None).unwrap();
        let (m, _) = kernels::reflect(kernel, &wgsl).unwrap();
        assert_eq!(
            struct_size(&m, "Params").or(struct_size(&m, "CsmSatParams")),
            Some(rust as u32),
            "Rust params vs {kernel}'s Params"
        );
        assert_eq!(
            struct_size(&m, "DepthParams"),
            Some(size_of::<LinearizeParams>() as u32),
            "LinearizeParams vs {kernel}'s DepthParams"
        );
    }
}

/// A `const NAME: u32` of a kernel, from naga's IR (following a constant defined as another).
fn wgsl_const(module: &naga::Module, name: &str) -> Option<u32> {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))?;
    let mut init = c.init;
    loop {
        match module.global_expressions[init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => return Some(v),
            naga::Expression::Constant(h) => init = module.constants[h].init,
            _ => return None,
        }
    }
}

/// The blur passes' geometry that `filter::add_filter` dispatches by is the kernels' own: a
/// column invocation of `blur` writes `BLUR_COL_PER` rows, one of `blur_log` `PER`.
#[test]
fn blur_dispatch_constants_match_the_wgsl() {
    use shadowgraph::low_level::filter::{BLUR_COL_PER, BLUR_GROUP, BLUR_PER_INVOCATION};
    for (kernel, col_per) in [
        ("blur", BLUR_COL_PER),
        ("blur_log", BLUR_PER_INVOCATION),
        ("blur_log_wide", BLUR_PER_INVOCATION),
    ] {
        let wgsl = kernels::resolve(kernel, None).expect("resolve");
        let (module, r) = kernels::reflect(kernel, &wgsl).expect("reflect");
        assert_eq!(
            wgsl_const(&module, "PER"),
            Some(BLUR_PER_INVOCATION),
            "{kernel}: PER"
        );
        assert_eq!(
            wgsl_const(&module, "COL_PER"),
            Some(col_per),
            "{kernel}: COL_PER"
        );
        assert_eq!(
            r.workgroup_size,
            Some([BLUR_GROUP, 1, 1]),
            "{kernel}: workgroup"
        );
    }
}

/// The peel pass discards by the margin the f64 reference of the second depth
/// (`truth::peel`) peels by: `PEEL_EPSILON` in `shadow_peel.wgsl` is `wgsl_mirrors`'s.
#[test]
fn peel_epsilon_matches_the_wgsl() {
    let wgsl = kernels::resolve("shadow_peel", None).expect("resolve");
    let (module, _) = kernels::reflect("shadow_peel", &wgsl).expect("reflect");
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some("PEEL_EPSILON"))
        .expect("PEEL_EPSILON in shadow_peel.wgsl");
    let value = match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::F32(v)) => v,
        ref e => panic!("PEEL_EPSILON is {e:?}, not an f32 literal"),
    };
    assert_eq!(value, shadowgraph::low_level::wgsl_mirrors::PEEL_EPSILON);
}

/// `blur_log`'s span, past which only `blur_log_wide` is exact, is the planner's
/// `LOG_BLUR_SPAN` (`BlurMode::log_sum_exp` picks the kernel by it), and `blur_log` has no
/// per-output path (`WIDE` false) where `blur_log_wide` has one.
#[test]
fn log_blur_span_matches_the_wgsl() {
    for (kernel, wide) in [("blur_log", false), ("blur_log_wide", true)] {
        let wgsl = kernels::resolve(kernel, None).expect("resolve");
        let (module, _) = kernels::reflect(kernel, &wgsl).expect("reflect");
        let literal = |name: &str| {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("{name} in {kernel}"));
            module.global_expressions[c.init].clone()
        };
        assert!(
            matches!(literal("SPAN"), naga::Expression::Literal(naga::Literal::F32(v))
                if v == shadowgraph::low_level::filter::LOG_BLUR_SPAN),
            "{kernel}: SPAN"
        );
        assert!(
            matches!(literal("WIDE"), naga::Expression::Literal(naga::Literal::Bool(w)) if w == wide),
            "{kernel}: WIDE"
        );
    }
    use shadowgraph::low_level::filter::BlurMode;
    assert_eq!(BlurMode::log_sum_exp(80.0), BlurMode::LogSumExp);
    assert_eq!(BlurMode::log_sum_exp(80.5), BlurMode::LogSumExpWide);
}

#[test]
fn encode_blur_dispatch_constants_match_the_wgsl() {
    use shadowgraph::low_level::filter::{
        ENCODE_BLUR_TILE_RADIUS, encode_blur_cpu_rows, encode_blur_row, encode_blur_row_kernel,
        encode_blur_tile,
    };
    use shadowgraph::low_level::kernels::KernelId;
    // The row kernels where their rows are full, else the tile kernels' shorter rows.
    for (kernel, width, row) in [
        (KernelId::VsmBlur, 1023, KernelId::VsmBlur),
        (KernelId::VsmBlur, 1024, KernelId::VsmBlurRow),
        (KernelId::EvsmBlur, 511, KernelId::EvsmBlur),
        (KernelId::MsmBlur, 512, KernelId::MsmBlurRow),
        (KernelId::EvsmBlur, 4096, KernelId::EvsmBlurRow),
        (KernelId::Blur, 4096, KernelId::Blur),
    ] {
        assert_eq!(
            encode_blur_row_kernel(kernel, width),
            row,
            "{kernel:?} at {width}"
        );
    }
    for kernel in [
        KernelId::VsmBlur,
        KernelId::VsmBlurRow,
        KernelId::EvsmBlur,
        KernelId::EvsmBlurRow,
        KernelId::MsmBlur,
        KernelId::MsmBlurRow,
    ] {
        let name = kernel.name();
        let wgsl = kernels::resolve(name, None).expect("resolve");
        let (module, r) = kernels::reflect(name, &wgsl).expect("reflect");
        let tile = encode_blur_tile(kernel);
        for (constant, rust) in [
            ("TILE", tile),
            ("CPU_TILE_ROWS", encode_blur_cpu_rows(kernel)),
            ("ROW", encode_blur_row(kernel)),
            ("TILE_RADIUS", ENCODE_BLUR_TILE_RADIUS),
        ] {
            assert_eq!(
                wgsl_const(&module, constant),
                Some(rust),
                "{name}: {constant}"
            );
        }
        // One invocation per output of a row; a tile's encoded texels in at most six blocks of
        // WG_SIZE (`encode_tile`). Its blur: with two channels in runs of RUN = 4
        // (four named sums), one run an invocation along x (TILE / RUN a row of the encoded
        // tile) and along y; with four, one output an invocation, the horizontal sums in at
        // most four blocks of WG_SIZE (`blur_tile_single`'s h0 … h3).
        let wg = r.workgroup_size.expect("workgroup size")[0];
        assert_eq!(wg, 256, "{name}: workgroup");
        // A CPU driver's layout: CPU_LANES invocations walk the tile in strips (and run the
        // row path's WG_SIZE invocations' work in turn).
        let lanes = wgsl_const(&module, "CPU_LANES").expect("CPU_LANES");
        assert_eq!(
            r.cpu_workgroup_size,
            Some([lanes, 1, 1]),
            "{name}: CPU workgroup"
        );
        assert!(lanes < wg && wg % lanes == 0, "{name}: CPU_LANES");
        // The row: ROW_RUN outputs an invocation, every invocation busy (2 with two channels,
        // `blur_row_pairs`; 1 with four).
        let row = encode_blur_row(kernel);
        let row_run = wgsl_const(&module, "ROW_RUN").expect("ROW_RUN");
        assert_eq!(row, row_run * wg, "{name}: ROW = ROW_RUN · WG_SIZE");
        let enc = tile + 2 * ENCODE_BLUR_TILE_RADIUS;
        assert!(enc * enc <= 6 * wg, "{name}: encoded tile");
        let run = wgsl_const(&module, "RUN").expect("RUN");
        let channels = wgsl_const(&module, "CHANNELS").expect("CHANNELS");
        match channels {
            2 => {
                // `vsm_blur_row`'s runs of 4 (`blur_row_quads`), `vsm_blur`'s of 2
                // (`blur_row_pairs`).
                let want = if kernel == KernelId::VsmBlurRow { 4 } else { 2 };
                assert_eq!(row_run, want, "{name}: ROW_RUN");
                assert_eq!(run, 4, "{name}: RUN (the sums s0 … s3)");
                assert_eq!(tile % run, 0, "{name}: runs per line");
                assert!(tile / run * enc <= wg, "{name}: runs along x");
                assert!(tile / run * tile <= wg, "{name}: runs along y");
            }
            _ => {
                // The row kernels' runs of 2 (`blur_row_pairs`), else one output an invocation.
                let row_kernel = matches!(kernel, KernelId::EvsmBlurRow | KernelId::MsmBlurRow);
                assert_eq!(row_run, if row_kernel { 2 } else { 1 }, "{name}: ROW_RUN");
                assert_eq!(run, 1, "{name}: RUN (one output an invocation)");
                assert!(tile * enc <= 4 * wg, "{name}: horizontal sums");
            }
        }
        // Workgroup memory: the encoded tile with its halo and the fallback's encoded row
        // (each encoding reads its depths straight from the texture), no more.
        let sh = wgsl_const(&module, "SH_TEXELS").expect("SH_TEXELS");
        let max_radius = wgsl_const(&module, "MAX_RADIUS").expect("MAX_RADIUS");
        let widest_row = [
            KernelId::VsmBlurRow,
            KernelId::EvsmBlurRow,
            KernelId::MsmBlurRow,
        ]
        .into_iter()
        .chain([kernel])
        .filter(|k| encode_blur_tile(*k) == tile)
        .map(encode_blur_row)
        .max()
        .unwrap();
        assert_eq!(
            sh,
            (enc * enc).max(widest_row + 2 * max_radius),
            "{name}: SH_TEXELS (the encoded tile or the widest encoded row sharing the module)"
        );
        assert!(
            sh * 4 * channels <= 16384,
            "{name}: 16 KiB of workgroup memory"
        );
    }
}
