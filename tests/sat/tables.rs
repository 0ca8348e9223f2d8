//! Fixed-point tables bit for bit against the integer reference, f32 tables within the
//! scan bound: the asked sizes, wrapping sums, 4096², a constant map, random small maps,
//! the device's largest dimension and the five-pass baseline.

use super::*;

/// The sizes asked for, plus lines of several blocks each way (the carry passes).
const SIZES: [(usize, usize); 8] = [
    (1, 1),
    (1, 57),
    (61, 1),
    (1000, 37),
    (256, 256),
    (1024, 1024),
    (3000, 5),
    (3, 2100),
];

#[test]
fn fixed_sat_is_bit_identical_to_the_integer_reference() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(70);
    for (i, (w, h)) in SIZES.into_iter().enumerate() {
        let channels = [1, 2, 4][i % 3];
        let map = Map::random(&mut rng, w, h, channels, 0.05, 1.0);
        // Every window of the map, the full map included, decodes exactly.
        let coding = SatCoding::fixed((w * h) as u64, [0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_fixed(
            &format!("fixed {w}x{h}"),
            &mut rng,
            &map,
            &coding,
            &table,
            None,
        );
    }
}

#[test]
fn fixed_sat_wraps_yet_keeps_small_windows_exact() {
    // Scale for 33×33 windows of values in [-2, 3]: codes up to ±2²¹, corner sums near 2⁴⁰
    // wrap many times over, and every window of up to 33×33 is still exact.
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(71);
    let map = Map::random(&mut rng, 1024, 1024, 2, -2.0, 3.0);
    let coding = SatCoding::fixed(33 * 33, [-2.0; 4], [3.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &coding);
    check_fixed(
        "fixed 1024² (33² windows)",
        &mut rng,
        &map,
        &coding,
        &table,
        Some(33),
    );
    let (w, h) = (map.w, map.h);
    let small: Vec<[usize; 4]> = (0..300)
        .map(|_| {
            let (x, y) = (rng.random_range(0..w - 33), rng.random_range(0..h - 33));
            let (a, b) = (rng.random_range(1..=33), rng.random_range(1..=33));
            [x, y, x + a, y + b]
        })
        .chain([[w - 33, h - 33, w, h]])
        .collect();
    let raw = reference::sat(&map.texels());
    let words = table.fixed();
    for [x0, y0, x1, y1] in small {
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let codes = reference::window_fixed(&words, w, x0, y0, x1, y1);
        let sums = reference::window(&raw, x0, y0, x1, y1);
        for c in 0..2 {
            let d = reference::decode_window(f64::from(codes[c]), area, &coding, c);
            let tol = area * (0.5 / f64::from(coding.scale[c]) + 2.5 * U) + 1e-9;
            assert!(
                (d - sums[c]).abs() <= tol,
                "window {x0},{y0}..{x1},{y1} c{c}: {d} vs {}",
                sums[c]
            );
        }
    }
}

#[test]
fn fixed_sat_of_a_4096_map_is_bit_identical() {
    // The stability case: 4096² (4 column blocks and 4 row blocks a line), corner sums near
    // 2⁴⁴ in units of the scale for 64×64-texel lookups, wrapped; still bit for bit.
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(75);
    let map = Map::random(&mut rng, 4096, 4096, 1, 0.0, 1.0);
    let coding = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &coding);
    check_fixed("fixed 4096²", &mut rng, &map, &coding, &table, Some(65));
}

#[test]
fn float_sat_is_within_the_scan_rounding_bound() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(72);
    for (i, (w, h)) in SIZES.into_iter().enumerate() {
        let channels = [4, 1, 2][i % 3];
        let map = Map::random(&mut rng, w, h, channels, 0.05, 1.0);
        let coding = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_float(&format!("float {w}x{h}"), &mut rng, &map, &coding, &table);
    }
}

#[test]
fn constant_depth_0_999_map() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(73);
    let (w, h) = (512, 384);
    let map = Map {
        w,
        h,
        channels: 1,
        values: vec![0.999; w * h],
    };
    let fixed = SatCoding::fixed((w * h) as u64, [0.0; 4], [1.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &fixed);
    check_fixed("fixed constant", &mut rng, &map, &fixed, &table, None);
    // Every window holds exactly area × the code of 0.999.
    let code = reference::encode_fixed(0.999, &fixed, 0) as i32;
    let words = table.fixed();
    for [x0, y0, x1, y1] in windows(&mut rng, w, h, 100) {
        let area = ((x1 - x0) * (y1 - y0)) as i64;
        let got = reference::window_fixed(&words, w, x0, y0, x1, y1)[0];
        assert_eq!(
            i64::from(got),
            area * i64::from(code),
            "{x0},{y0}..{x1},{y1}"
        );
    }
    let float = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
    let table = build(&g, &mut exec, &map, &float);
    check_float("float constant", &mut rng, &map, &float, &table);
}

/// Random small maps: lines of one to three blocks in either direction, 1, 2 or 4 channels,
/// random value ranges, both variants.
#[test]
fn property_sat_matches_the_references_on_random_small_maps() {
    let g = common::gpu();
    let exec = RefCell::new(Executor::new());
    let mut runner = TestRunner::new(Config {
        cases: 24,
        max_shrink_iters: 16,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (
        1usize..=2600,
        1usize..=12,
        any::<bool>(),
        prop::sample::select(vec![1usize, 2, 4]),
        -4.0f32..4.0,
        0.01f32..8.0,
        any::<bool>(),
        any::<u64>(),
    );
    runner
        .run(
            &strategy,
            |(long, short, transpose, channels, lo, span, fixed, seed)| {
                let (w, h) = if transpose {
                    (short, long)
                } else {
                    (long, short)
                };
                let mut rng = common::rng(seed);
                let map = Map::random(&mut rng, w, h, channels, lo, lo + span);
                let what = format!("{w}x{h}x{channels} [{lo}, {}] fixed {fixed}", lo + span);
                let mut exec = exec.borrow_mut();
                if fixed {
                    let coding = SatCoding::fixed((w * h) as u64, [lo; 4], [lo + span; 4]).unwrap();
                    let table = build(&g, &mut exec, &map, &coding);
                    check_fixed(&what, &mut rng, &map, &coding, &table, None);
                } else {
                    let coding = SatCoding::float([lo; 4], [lo + span; 4]).unwrap();
                    let table = build(&g, &mut exec, &map, &coding);
                    check_float(&what, &mut rng, &map, &coding, &table);
                }
                Ok(())
            },
        )
        .unwrap();
}

/// The device's largest 2-D texture along each axis (16384 on lavapipe), as a strip of 16
/// lines (16 row blocks of 1024 texels a line; 16 column blocks a column): fixed tables bit
/// for bit, f32 tables within the scan bound. A full 16384² rgba32 table is 4 GiB, past what
/// a 24 GiB test machine holds with its intermediates and readback, so the strips stand in.
#[test]
fn largest_texture_dimension_each_way() {
    let g = common::gpu();
    let max = g.device.limits().max_texture_dimension_2d as usize;
    let mut exec = Executor::new();
    let mut rng = common::rng(76);
    for (w, h) in [(max, 16), (16, max)] {
        let map = Map::random(&mut rng, w, h, 2, 0.0, 1.0);
        let coding = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_fixed(
            &format!("fixed {w}x{h}"),
            &mut rng,
            &map,
            &coding,
            &table,
            Some(17),
        );
        let coding = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut exec, &map, &coding);
        check_float(&format!("float {w}x{h}"), &mut rng, &map, &coding, &table);
    }
}

/// The five-pass baseline `shadowgraph bench` times against still builds the same table.
#[test]
fn five_pass_baseline_is_bit_identical_too() {
    let g = common::gpu();
    let mut exec = Executor::new();
    let mut rng = common::rng(77);
    let map = Map::random(&mut rng, 1500, 70, 2, 0.05, 1.0);
    let coding = SatCoding::fixed(lookup_area(16.0, 16.0), [0.0; 4], [1.0; 4]).unwrap();
    let table = build_with(&g, &mut exec, &map, &coding, add_sat_five_pass);
    check_fixed(
        "five-pass 1500x70",
        &mut rng,
        &map,
        &coding,
        &table,
        Some(17),
    );
}
