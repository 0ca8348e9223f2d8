//! The benchmark variants in `benches/variants/` give the shipped results bit for bit.

use super::*;

/// Every sample of every level of `resource`'s mip chain as `shadowgraph dump` writes it for
/// `scene`, with `envs`, level by level.
fn dumped_chain(
    scene: &Path,
    resource: &str,
    out: &Path,
    envs: &[(&str, &OsStr)],
) -> Vec<Vec<u32>> {
    let args = [
        OsStr::new("dump"),
        scene.as_os_str(),
        OsStr::new("--out"),
        out.as_os_str(),
        OsStr::new("--only"),
        OsStr::new(resource),
    ];
    let o = shadowgraph(&args, envs);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut levels = Vec::new();
    for level in 0.. {
        let name = match level {
            0 => format!("{resource}.exr"),
            l => format!("{resource}.mip{l}.exr"),
        };
        let Ok(img) = exr::prelude::read_all_flat_layers_from_file(out.join(&name)) else {
            break;
        };
        let bits = img.layer_data[0]
            .channel_data
            .list
            .iter()
            .flat_map(|c| c.sample_data.values_as_f32().map(f32::to_bits))
            .collect();
        levels.push(bits);
    }
    levels
}

/// `resource` of the scene at `path` dumped with the shipped kernels and with each benchmark
/// variant of `variants` (`benches/variants/<name>`), in kernel layout `layout` (the device's
/// with `None`): the same levels, each at least a quarter non-zero (never a comparison of
/// zeros), bit for bit. Returns how many levels the chain has.
fn variants_match(
    path: &Path,
    resource: &str,
    dir: &Path,
    layout: Option<&str>,
    variants: &[&str],
) -> usize {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let name = path.file_stem().unwrap().to_string_lossy();
    let tag = format!("{name}_{}_{resource}", layout.unwrap_or("device"));
    let layout_env = layout.map(|l| (KERNEL_LAYOUT_ENV, OsStr::new(l)));
    let dump = |folder: Option<&Path>, out: &str| {
        let envs: Vec<(&str, &OsStr)> = layout_env
            .into_iter()
            .chain(folder.map(|f| (KERNEL_DIR_ENV, f.as_os_str())))
            .collect();
        dumped_chain(path, resource, &dir.join(format!("{out}_{tag}")), &envs)
    };
    let shipped = dump(None, "shipped");
    assert!(!shipped.is_empty(), "{tag}: nothing dumped");
    for (l, level) in shipped.iter().enumerate() {
        let nonzero = level.iter().filter(|&&v| v != 0).count();
        assert!(4 * nonzero >= level.len(), "{tag}: level {l} mostly zeros");
    }
    for variant in variants {
        let got = dump(Some(&root.join("benches/variants").join(variant)), variant);
        assert_eq!(got.len(), shipped.len(), "{variant} {tag}: levels");
        for (l, (a, b)) in shipped.iter().zip(&got).enumerate() {
            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
            assert_eq!(
                differ, 0,
                "{variant} {tag}: level {l}, {differ} samples differ"
            );
        }
    }
    shipped.len()
}

/// `benches/variants/mip_quads` (the mip chain without level s + 1 in workgroup memory, a
/// benchmark variant `benches/gpu_check.sh` times beside the shipped kernel) builds the shipped
/// chain bit for bit: VSM at 512² (two halving dispatches) and 300² (odd levels: the general
/// path, and tiles cut by the level's edge), ESM's log-sum-exp chain at 200². A variant whose
/// level s + 2 reads its quad's texels in another order fails it.
#[test]
fn the_mip_chain_benchmark_variant_builds_the_same_chain() {
    let dir = temp_dir("mips");
    for (scene, from, to, resource) in [
        (
            "vsm_mips.toml",
            "shadow_map = 512",
            "shadow_map = 512",
            "light0.vsm.mips",
        ),
        (
            "vsm_mips.toml",
            "shadow_map = 512",
            "shadow_map = 300",
            "light0.vsm.mips",
        ),
        (
            "esm_mips_aniso.toml",
            "shadow_map = 1024",
            "shadow_map = 200",
            "light0.esm.mips",
        ),
    ] {
        let name = format!("{}_{}", to.replace([' ', '='], ""), scene);
        let path = edited_scene(&dir, scene, &[(from, to)], &name);
        let levels = variants_match(&path, resource, &dir, None, &["mip_quads"]);
        assert!(levels >= 8, "{scene} {to}: {levels} levels");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `benches/variants/blur_rows_run1` and `blur_rows_run2` (the separable blur's row pass one
/// output an invocation, and in runs of 2, benchmark variants `benches/gpu_check.sh` times
/// beside the shipped runs of 8) blur as the shipped kernel does, bit for bit: CSM's four
/// basis maps (`blur` along x, then y) at radius 3 on 512² and at radius 20 on 300² (rows
/// cut by the map's edge, a window wider than a run). A variant that weights the two taps of
/// a pair apart (w·l + w·r) fails it (255 129 samples of CSM 3's vertical pass at 512²).
#[test]
fn the_blur_row_benchmark_variants_blur_the_same() {
    let dir = temp_dir("blur_rows");
    for (size, radius) in [("512", "3"), ("300", "20")] {
        let edits = [
            ("shadow_map = 512", &*format!("shadow_map = {size}")),
            ("filter_radius = 3", &*format!("filter_radius = {radius}")),
        ];
        let path = edited_scene(
            &dir,
            "csm.toml",
            &edits,
            &format!("csm_{size}_r{radius}.toml"),
        );
        for resource in ["light0.csm0.blur_h", "light0.csm3.blur_v"] {
            let variants = ["blur_rows_run1", "blur_rows_run2"];
            assert_eq!(variants_match(&path, resource, &dir, None, &variants), 1);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `benches/variants/sat_vsm_texel` (VSM's table texels each from its own five depth loads
/// instead of a sub-block's depths in private arrays, a benchmark variant
/// `benches/gpu_check.sh` times beside the shipped kernels) builds the shipped tables bit for
/// bit: the fixed-point (`vsm_sat.toml`) and f32 (`vssm.toml`) tables at 512² and at 300²
/// (ragged tiles: clamped neighbours at the map's edge), in both kernel layouts (pass 3's
/// second sweep loaded again, or kept). A variant that takes a neighbour one texel off fails
/// it.
#[test]
fn the_vsm_table_benchmark_variant_builds_the_same_tables() {
    let dir = temp_dir("sat_vsm");
    for (scene, size) in [
        ("vsm_sat.toml", 512),
        ("vsm_sat.toml", 300),
        ("vssm.toml", 300),
    ] {
        let edits = [("shadow_map = 512", &*format!("shadow_map = {size}"))];
        let path = edited_scene(&dir, scene, &edits, &format!("{size}_{scene}"));
        for layout in ["gpu", "cpu"] {
            let levels = variants_match(
                &path,
                "light0.vsm.sat",
                &dir,
                Some(layout),
                &["sat_vsm_texel"],
            );
            assert_eq!(levels, 1);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `benches/variants/sat_sub2` (the tables' tile passes with 2 × 2 sub-blocks, 256 invocations a
/// tile, and its own carries kernel) builds every fixed-point table bit for bit as the shipped
/// 4 × 4 sub-blocks do (integer sums in any order): VSM's, MSM's, ESM's, EVSM's and CSM's
/// tables computed from the depth, CSSM's interleaved ones (its moment table), at the scenes'
/// 512² in both kernel layouts and at 300² (ragged tiles) in the CPU layout, ESM's carries
/// too. A variant whose line sums skip the last line fails it at 459 712 samples.
#[test]
fn the_small_sub_block_table_variant_builds_the_same_tables() {
    let dir = temp_dir("sat_sub2");
    let cases: [(&str, &[&str]); 6] = [
        ("vsm_sat.toml", &["light0.vsm.sat"]),
        ("msm_sat.toml", &["light0.msm.sat"]),
        (
            "esm_sat.toml",
            &["light0.esm.sat", "light0.esm.sat.row_carry"],
        ),
        (
            "evsm4_sat.toml",
            &["light0.evsm.sat", "light0.evsm.sat.col_part"],
        ),
        (
            "csm_sat.toml",
            &[
                "light0.csm0.sat",
                "light0.csm3.sat",
                "light0.csm.sat.row_carry",
            ],
        ),
        ("cssm.toml", &["light0.csm1.sat", "light0.csm_moments.sat"]),
    ];
    for (scene, resources) in cases {
        for size in [512, 300] {
            let edits = [("shadow_map = 512", &*format!("shadow_map = {size}"))];
            let path = edited_scene(&dir, scene, &edits, &format!("{size}_{scene}"));
            // The GPU layout on the two larger cases only: the suite's time.
            let layouts: &[&str] = if size == 300 {
                &["cpu"]
            } else {
                &["gpu", "cpu"]
            };
            for &layout in layouts {
                for resource in resources {
                    let levels = variants_match(&path, resource, &dir, Some(layout), &["sat_sub2"]);
                    assert_eq!(levels, 1);
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `benches/variants/sat_carries_serial` (the carries kernel loading each edge texel as its
/// serial sum reaches it, as before its loads ran eight ahead) gives the same carries and
/// tables bit for bit, f32 sums included (the sums keep their order): VSM's f32 table and ESM's
/// fixed-point one at 300² (10 tiles a line: a batch of eight and two after it) and 520²
/// (17: two batches and one). Carries added in another order (the row's tiles above taken
/// from the tile beside) fail it.
#[test]
fn the_serial_carries_variant_builds_the_same_tables() {
    let dir = temp_dir("carries");
    for (scene, resources) in [
        (
            "vsm_sat_float.toml",
            [
                "light0.vsm.sat",
                "light0.vsm.sat.row_carry",
                "light0.vsm.sat.col_carry",
            ],
        ),
        (
            "esm_sat.toml",
            [
                "light0.esm.sat",
                "light0.esm.sat.row_carry",
                "light0.esm.sat.col_carry",
            ],
        ),
    ] {
        for size in [300, 520] {
            let edits = [("shadow_map = 512", &*format!("shadow_map = {size}"))];
            let path = edited_scene(&dir, scene, &edits, &format!("{size}_{scene}"));
            for resource in resources {
                let levels = variants_match(&path, resource, &dir, None, &["sat_carries_serial"]);
                assert_eq!(levels, 1);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Each benchmark variant in `benches/variants/<name>/` is a whole-file copy of a shipped kernel
/// with a few lines changed (`SHADOWGRAPH_KERNEL_DIR` and `bench --kernel-dirs` replace whole
/// files), so a later change to the shipped file would leave the variant timing the old code
/// while its bit-for-bit test still passed. This pins, for every variant file, how many of the
/// shipped file's lines it lacks and how many of its own the shipped file lacks (as multisets):
/// an edit to either side moves a count and fails here, naming the file to bring up to date.
/// Every file below `benches/variants` must be listed.
#[test]
fn benchmark_variants_track_the_shipped_kernels() {
    use std::collections::HashMap;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // (variant file below benches/variants/<name>/, its lines missing, its own lines added)
    let expected: HashMap<&str, (usize, usize)> = HashMap::from([
        ("blur_rows_run1/blur.wgsl", (3, 21)),
        ("blur_rows_run2/blur.wgsl", (2, 7)),
        ("mip_quads/shared/mip_chain.wgsl", (23, 21)),
        ("sat_carries_serial/sat_carries.wgsl", (106, 7)),
        ("sat_sub2/sat_carries.wgsl", (9, 16)),
        ("sat_sub2/shared/sat_tile.wgsl", (5, 16)),
        ("sat_sub2/shared/sat_tile_scan.wgsl", (8, 15)),
        ("sat_sub2/shared/sat_tile_sums.wgsl", (11, 23)),
        ("sat_vsm_texel/shared/sat_tile_texel.wgsl", (1, 18)),
    ]);
    let counts = |text: &str| {
        let mut m: HashMap<String, usize> = HashMap::new();
        for line in text.lines() {
            *m.entry(line.to_string()).or_default() += 1;
        }
        m
    };
    let only_in = |a: &HashMap<String, usize>, b: &HashMap<String, usize>| -> usize {
        a.iter()
            .map(|(line, n)| n.saturating_sub(b.get(line).copied().unwrap_or(0)))
            .sum()
    };
    let variants = root.join("benches/variants");
    let mut seen = Vec::new();
    let mut stack = vec![variants.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            let rel = path.strip_prefix(&variants).unwrap();
            let key = rel.to_string_lossy().replace('\\', "/");
            let Some(&(missing, added)) = expected.get(key.as_str()) else {
                panic!("benches/variants/{key}: not listed here");
            };
            // benches/variants/<name>/<path> varies kernels/<path>.
            let shipped_path = root
                .join("kernels")
                .join(rel.components().skip(1).collect::<PathBuf>());
            let shipped = counts(&std::fs::read_to_string(&shipped_path).unwrap());
            let variant = counts(&std::fs::read_to_string(&path).unwrap());
            assert_eq!(
                (only_in(&shipped, &variant), only_in(&variant, &shipped)),
                (missing, added),
                "benches/variants/{key} against {}: the shipped file or the variant changed; \
                 bring the variant up to date (and its bit-for-bit test), then these counts",
                shipped_path.display()
            );
            seen.push(key);
        }
    }
    assert_eq!(
        seen.len(),
        expected.len(),
        "listed but missing: {expected:?} against {seen:?}"
    );
}
