//! The kernels' layouts (`exec::KernelLayout`): the GPU's and a CPU driver's build the
//! same tables, the redesign's the same fixed-point tables and f32 tables within the
//! bound, and its modules only where the device allows.

use super::*;

/// The kernels' two layouts (`exec::KernelLayout`: pass 3's second sweep loading its texels
/// again, as on a GPU, or reading the first sweep's kept in private memory, as on a CPU
/// driver) build the same tables bit for bit, fixed point and f32, one, two and four channels,
/// ragged tiles and single lines (the references above run the device's layout; this ties the
/// other to it).
#[test]
fn both_layouts_build_the_same_tables() {
    let g = common::gpu();
    let mut recomputed = Executor::new();
    recomputed.kernels.set_layout(KernelLayout::Gpu);
    let mut kept = Executor::new();
    kept.kernels.set_layout(KernelLayout::Cpu);
    let mut rng = common::rng(76);
    for (i, (w, h)) in [(1, 57), (61, 1), (100, 70), (33, 200)]
        .into_iter()
        .enumerate()
    {
        let channels = [1, 2, 4][i % 3];
        let map = Map::random(&mut rng, w, h, channels, -0.5, 1.0);
        let codings = [
            SatCoding::fixed((w * h) as u64, [-0.5; 4], [1.0; 4]).unwrap(),
            SatCoding::float([-0.5; 4], [1.0; 4]).unwrap(),
        ];
        for coding in codings {
            let a = build(&g, &mut recomputed, &map, &coding).bytes;
            let b = build(&g, &mut kept, &map, &coding).bytes;
            let words = |x: &[u8]| bytemuck::cast_slice::<u8, u32>(x).to_vec();
            let (a, b) = (words(&a), words(&b));
            if let Some(k) = (0..a.len()).find(|&k| a[k] != b[k]) {
                panic!(
                    "{w}×{h}, {channels} channels, {:?}: word {k} is {:#x} in the GPU layout, \
                     {:#x} in the CPU layout",
                    coding.variant, a[k], b[k]
                );
            }
        }
    }
}

/// The redesign layout (`exec::KernelLayout::Redesign`: on a device with subgroups the tile
/// passes by subgroup scans, a lane a column, `kernels/shared/sat_strip.wgsl`, without them the
/// shipped passes; everywhere the carries scanned by 8 lanes a line,
/// `kernels/sat_carries_scan.wgsl`) builds fixed-point tables bit for bit as the GPU layout
/// does (wrapping sums in any order), and f32 tables within the same scan bound of the f64
/// table (its summation tree is no deeper than the shipped one's: `sat::float_sum_depth`):
/// one, two and four channels, ragged tiles, single lines, several tiles each way, and lines
/// of more than one segment of the carries' scan (64 tiles: 2090 wide, 2100 tall), ragged.
#[test]
fn redesign_layout_builds_the_same_tables() {
    let g = common::gpu();
    let mut shipped = Executor::new();
    shipped.kernels.set_layout(KernelLayout::Gpu);
    let mut redesign = Executor::new();
    redesign.kernels.set_layout(KernelLayout::Redesign);
    let mut rng = common::rng(78);
    let sizes = [
        (1, 57),
        (61, 1),
        (100, 70),
        (33, 200),
        (257, 95),
        (2090, 170),
        (45, 2100),
    ];
    for (i, (w, h)) in sizes.into_iter().enumerate() {
        let channels = [1, 2, 4][i % 3];
        let map = Map::random(&mut rng, w, h, channels, -0.5, 1.0);
        let fixed = SatCoding::fixed((w * h) as u64, [-0.5; 4], [1.0; 4]).unwrap();
        let a = build(&g, &mut shipped, &map, &fixed).bytes;
        let table = build(&g, &mut redesign, &map, &fixed);
        if let Some(k) = (0..a.len()).find(|&k| a[k] != table.bytes[k]) {
            panic!("{w}×{h}, {channels} channels: byte {k} differs from the GPU layout's");
        }
        let what = format!("redesign fixed {w}x{h}");
        check_fixed(&what, &mut rng, &map, &fixed, &table, None);
        let float = SatCoding::float([-0.5; 4], [1.0; 4]).unwrap();
        let table = build(&g, &mut redesign, &map, &float);
        let what = format!("redesign float {w}x{h}");
        check_float(&what, &mut rng, &map, &float, &table);
    }
}

/// The redesign's modules replace the shipped ones only in the redesign layout and only on a
/// device with the feature they need: elsewhere every kernel compiles as shipped.
#[test]
fn redesigned_sat_modules_need_the_redesign_layout_and_subgroups() {
    let all = wgpu::Features::SUBGROUP;
    assert!(
        KernelLayout::Redesign
            .module_sources(wgpu::Features::empty())
            .is_empty()
    );
    assert!(KernelLayout::Gpu.module_sources(all).is_empty());
    assert!(KernelLayout::Cpu.module_sources(all).is_empty());
    assert_eq!(
        KernelLayout::Redesign.module_sources(all),
        [
            ("shared/sat_tile_sums", "shared/sat_tile_sums_subgroup"),
            ("shared/sat_tile_scan", "shared/sat_tile_scan_subgroup"),
        ]
    );
}
