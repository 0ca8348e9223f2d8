//! `SHADOWGRAPH_KERNEL_DIR`: a folder of `.wgsl` files replaces the embedded kernels of the same
//! names for one process (one build runs kernel variants). The replacement is what runs; a
//! stray file, a missing folder or broken WGSL is one line and status 1. And
//! `SHADOWGRAPH_KERNEL_LAYOUT`, which picks the kernels' layout (`exec::KernelLayout`): `info` prints it, a bad
//! value is one line.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use shadowgraph::low_level::exec::KERNEL_LAYOUT_ENV;
use shadowgraph::low_level::kernels::{self, KERNEL_DIR_ENV};

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-kdir-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Runs the CLI with `args`, neither switch set but those in `envs`.
fn shadowgraph(args: &[&OsStr], envs: &[(&str, &OsStr)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_shadowgraph"));
    cmd.args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .env_remove(KERNEL_DIR_ENV)
        .env_remove(KERNEL_LAYOUT_ENV)
        .envs(envs.iter().copied());
    cmd.output().expect("run shadowgraph")
}

/// `shadowgraph render sphere_on_plane.toml -o png` with `envs`.
fn render_with(png: &Path, envs: &[(&str, &OsStr)]) -> Output {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_on_plane.toml");
    let args = [
        OsStr::new("render"),
        scene.as_os_str(),
        OsStr::new("-o"),
        png.as_os_str(),
    ];
    shadowgraph(&args, envs)
}

/// [`render_with`] the kernels of `dir` (if any).
fn render(dir: Option<&Path>, png: &Path) -> Output {
    match dir {
        Some(dir) => render_with(png, &[(KERNEL_DIR_ENV, dir.as_os_str())]),
        None => render_with(png, &[]),
    }
}

/// Status 1 and one line on stderr after the note, containing every needle.
#[track_caller]
fn refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| !l.starts_with("note: ")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    for n in needles {
        assert!(errors[0].contains(n), "`{n}` missing from {err}");
    }
}

/// The shading kernel with its sRGB encoding replaced by black: every pixel's colour is then 0
/// exactly, where the embedded kernel's render of the same scene has lit pixels.
#[test]
fn a_replaced_kernel_is_the_one_that_runs() {
    let dir = temp_dir("shade");
    let shade = kernels::source("shade").expect("embedded shade");
    let head = "fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {\n";
    assert!(shade.contains(head), "shade.wgsl's sRGB function moved");
    let black = shade.replace(head, &format!("{head}    return vec3<f32>(0.0);\n"));
    std::fs::write(dir.join("shade.wgsl"), black).unwrap();

    let lit = |o: &Output, png: &Path| {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let img = image::open(png).expect("png").to_rgba8();
        img.pixels().filter(|p| p.0[..3] != [0, 0, 0]).count()
    };
    let png = dir.join("embedded.png");
    let embedded = lit(&render(None, &png), &png);
    assert!(
        embedded > 1000,
        "the embedded render is black: {embedded} lit pixels"
    );

    let png = dir.join("replaced.png");
    let o = render(Some(&dir), &png);
    assert_eq!(lit(&o, &png), 0, "the replaced kernel did not run");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("kernels replaced: shade"),
        "no note naming the replaced kernel: {err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The shading kernel with each invocation shading 2 or 7 pixels along its row (`TEXELS_X`,
/// the dispatch narrowed to match; 7 leaves the last workgroup of every row ragged on the 480-
/// pixel-wide image) renders the embedded kernel's image pixel for pixel (a variant whose
/// invocations skip the wrong columns, `wg.x + k` for `wg.x · TEXELS_X + k`, differs).
#[test]
fn shading_several_pixels_an_invocation_renders_the_same() {
    let shade = kernels::source("shade").expect("embedded shade");
    let one = "const TEXELS_X: u32 = 1u;\n";
    assert!(shade.contains(one), "shade.wgsl's TEXELS_X moved");
    let dir = temp_dir("texels");
    let png = dir.join("embedded.png");
    let o = render(None, &png);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = image::open(&png).expect("png").to_rgba8();
    for n in [2, 7] {
        let variant = dir.join(format!("x{n}"));
        std::fs::create_dir_all(&variant).unwrap();
        let src = shade.replace(one, &format!("const TEXELS_X: u32 = {n}u;\n"));
        std::fs::write(variant.join("shade.wgsl"), src).unwrap();
        let png = dir.join(format!("x{n}.png"));
        let o = render(Some(&variant), &png);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let got = image::open(&png).expect("png").to_rgba8();
        assert_eq!(got.dimensions(), want.dimensions());
        let differ = got
            .pixels()
            .zip(want.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "TEXELS_X = {n}: {differ} pixels differ");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A graph kernel whose node is dispatched by texels covers `TEXELS_X` texels an invocation,
/// the dispatch following: `linearize` made to cover 3 (its redesign path, the 1024² map's
/// last workgroup of a row ragged) renders the embedded kernel's image pixel for pixel. One
/// whose node has a geometry of its own (the mip chain's dispatches) replaced by one declaring
/// `TEXELS_X` would cover the wrong texels: refused by name, in one line.
#[test]
fn texels_x_in_a_graph_kernel_widens_a_texel_dispatch_and_is_refused_elsewhere() {
    let dir = temp_dir("texels-graph");
    let linearize = kernels::source("linearize").expect("embedded linearize");
    let layout = "override TEXELS_X: u32 = select(1u, 4u, REDESIGN);";
    assert!(
        linearize.contains(layout),
        "linearize.wgsl's TEXELS_X moved"
    );
    let three = linearize
        .replace(layout, "const TEXELS_X: u32 = 3u;")
        .replace("    if REDESIGN {\n", "    if true {\n");
    std::fs::write(dir.join("linearize.wgsl"), three).unwrap();
    let png = dir.join("embedded.png");
    let o = render(None, &png);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = image::open(&png).expect("png").to_rgba8();
    let png = dir.join("x3.png");
    let o = render(Some(&dir), &png);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let got = image::open(&png).expect("png").to_rgba8();
    let differ = got
        .pixels()
        .zip(want.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differ, 0, "linearize, TEXELS_X = 3: {differ} pixels differ");
    std::fs::remove_file(dir.join("linearize.wgsl")).unwrap();
    let mips = kernels::source("mips").expect("embedded mips");
    std::fs::write(
        dir.join("mips.wgsl"),
        format!("const TEXELS_X: u32 = 2u;\n{mips}"),
    )
    .unwrap();
    let scene = edited_scene(&dir, "vsm_mips.toml", &[], "vsm_mips.toml");
    let png = dir.join("out.png");
    let args = [
        OsStr::new("render"),
        scene.as_os_str(),
        OsStr::new("-o"),
        png.as_os_str(),
    ];
    let o = shadowgraph(&args, &[(KERNEL_DIR_ENV, dir.as_os_str())]);
    refused(&o, &["mips", "TEXELS_X", "dispatched by texels"]);
    let _ = std::fs::remove_dir_all(&dir);
}

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

/// `scenes/techniques/<scene>` with each `(from, to)` of `edits` replaced (each `from` must be
/// there), written into `dir` as `name`.
fn edited_scene(dir: &Path, scene: &str, edits: &[(&str, &str)], name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut text = std::fs::read_to_string(root.join("scenes/techniques").join(scene)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{scene}: `{from}` moved");
        text = text.replace(from, to);
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
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

/// `bench --kernel-dirs shipped,<folder>,…` times each kernel compiled from each folder in one
/// process, rows `<kernel> [shipped]`, `<kernel> [<folder's name>]` and `<kernel> [zeroed]` (the
/// embedded kernels with their workgroup memory zeroed first). A folder's kernel that
/// does not validate is named; one that reads a binding no node binds is refused by the
/// executor (so the folder's kernel is what the executor compiles, not the embedded file), as
/// is a kernel dispatched a line an invocation with another workgroup size than its node's
/// lines a workgroup; a folder that replaces nothing or cannot be read, a name given twice,
/// `--layouts` beside it and `SHADOWGRAPH_KERNEL_DIR` set under it are each
/// one line and status 1.
#[test]
fn bench_times_kernel_folders_side_by_side() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let variant = root.join("benches/variants/blur_rows_run1");
    let dirs = format!("shipped,{},zeroed", variant.display());
    let bench = |dirs: &str, envs: &[(&str, &OsStr)]| {
        let args = [
            "bench",
            "--sizes",
            "64",
            "--repeat",
            "1",
            "--only",
            "blur rg32f r4",
            "--kernel-dirs",
            dirs,
        ];
        let args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
        shadowgraph(&args, envs)
    };
    let o = bench(&dirs, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Table rows only: a busy machine may add a WARNING line that names a row too.
    for row in [
        "blur rg32f r4 [shipped]",
        "blur rg32f r4 [blur_rows_run1]",
        "blur rg32f r4 [zeroed]",
    ] {
        let rows = out
            .lines()
            .filter(|l| l.trim_start().starts_with("64 ") && l.contains(row))
            .count();
        assert_eq!(rows, 1, "`{row}` in {out}");
    }
    assert!(
        out.contains("kernel folders shipped, blur_rows_run1, zeroed"),
        "{out}"
    );

    let dir = temp_dir("bench_dirs");
    let blur = std::fs::read_to_string(root.join("kernels/blur.wgsl")).unwrap();
    let broken = dir.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    std::fs::write(
        broken.join("blur.wgsl"),
        format!("{blur}\nfn f() -> u32 {{\n    return 1.5;\n}}\n"),
    )
    .unwrap();
    refused(
        &bench(&format!("shipped,{}", broken.display()), &[]),
        &["--kernel-dirs", "broken", "kernel `blur`"],
    );
    // The tables' carries, dispatched a line an invocation (`Dispatch::Lines`, 64 lines a
    // workgroup): a variant with another workgroup size is refused by the executor.
    let wide = dir.join("wide");
    std::fs::create_dir_all(&wide).unwrap();
    let carries = std::fs::read_to_string(root.join("kernels/sat_carries.wgsl")).unwrap();
    let from = "@compute @workgroup_size(WG_SIZE)";
    assert!(carries.contains(from), "sat_carries.wgsl: `{from}` moved");
    assert!(blur.contains(from), "blur.wgsl: `{from}` moved");
    std::fs::write(
        wide.join("sat_carries.wgsl"),
        carries.replace(from, "@compute @workgroup_size(32)"),
    )
    .unwrap();
    let wide_dirs = std::ffi::OsString::from(format!("shipped,{}", wide.display()));
    let args: Vec<&OsStr> = [
        "bench",
        "--sizes",
        "64",
        "--repeat",
        "1",
        "--only",
        "sat fixed",
        "--kernel-dirs",
    ]
    .iter()
    .map(OsStr::new)
    .chain([wide_dirs.as_os_str()])
    .collect();
    refused(
        &shadowgraph(&args, &[]),
        &[
            "kernel `sat_carries`",
            "64 lines a workgroup",
            "32 invocations",
        ],
    );
    // A variant that validates and keeps the geometry but reads a binding no node binds: only
    // the executor's pipeline meets it, so the refusal says the folder's kernel is what runs.
    let extra = dir.join("extra");
    std::fs::create_dir_all(&extra).unwrap();
    let entry = "fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {\n";
    assert!(blur.contains(entry), "blur.wgsl: its `main` moved");
    let with_extra = blur
        .replace(entry, &format!("{entry}    _ = sg_extra[li];\n"))
        .replace(
            from,
            &format!("@group(0) @binding(9) var<storage, read> sg_extra: array<u32>;\n\n{from}"),
        );
    std::fs::write(extra.join("blur.wgsl"), with_extra).unwrap();
    refused(
        &bench(&format!("shipped,{}", extra.display()), &[]),
        &["binds nothing to `sg_extra`"],
    );
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    refused(
        &bench(&format!("shipped,{}", empty.display()), &[]),
        &["--kernel-dirs", "empty", "replaces no kernel"],
    );
    let missing = dir.join("missing");
    refused(
        &bench(&format!("shipped,{}", missing.display()), &[]),
        &["--kernel-dirs: ", "missing"],
    );
    refused(
        &bench("shipped,shipped", &[]),
        &["--kernel-dirs", "`shipped` twice"],
    );
    refused(
        &bench(&dirs, &[(KERNEL_DIR_ENV, variant.as_os_str())]),
        &["--kernel-dirs", KERNEL_DIR_ENV],
    );
    let args: Vec<&OsStr> = [
        "bench",
        "--sizes",
        "64",
        "--layouts",
        "gpu",
        "--kernel-dirs",
        "shipped",
    ]
    .iter()
    .map(OsStr::new)
    .collect();
    refused(&shadowgraph(&args, &[]), &["cannot be used with"]);
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

/// Files are named by their path below the folder (`shared/` for modules); anything else is
/// refused by name.
#[test]
fn replacements_are_read_by_name() {
    let dir = temp_dir("names");
    std::fs::create_dir_all(dir.join("shared")).unwrap();
    std::fs::write(dir.join("linearize.wgsl"), "// a").unwrap();
    std::fs::write(dir.join("shared/light.wgsl"), "// b").unwrap();
    std::fs::write(dir.join("notes.txt"), "not a kernel").unwrap();
    let read = kernels::read_replacements(&dir).expect("read");
    let mut names: Vec<&str> = read.keys().map(String::as_str).collect();
    names.sort_unstable();
    assert_eq!(names, ["linearize", "shared/light"]);
    assert_eq!(read["shared/light"], "// b");

    std::fs::write(dir.join("shared/nonesuch.wgsl"), "").unwrap();
    let e = kernels::read_replacements(&dir).expect_err("a stray kernel");
    assert!(
        e.contains("nonesuch.wgsl") && e.contains("names no kernel"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_replacements_are_one_line_errors() {
    let dir = temp_dir("bad");
    let png = dir.join("out.png");
    std::fs::write(dir.join("nonesuch.wgsl"), "").unwrap();
    refused(
        &render(Some(&dir), &png),
        &["nonesuch.wgsl", "names no kernel"],
    );
    std::fs::remove_file(dir.join("nonesuch.wgsl")).unwrap();

    refused(
        &render(Some(&dir.join("missing")), &png),
        &[KERNEL_DIR_ENV, "missing"],
    );

    // A parse error on the third line, and a type error (naga places it at the function).
    std::fs::write(dir.join("linearize.wgsl"), "// a\n\nfn f( {}\n").unwrap();
    refused(
        &render(Some(&dir), &png),
        &["kernel `linearize`", "(line 3 of", KERNEL_DIR_ENV],
    );
    std::fs::write(
        dir.join("linearize.wgsl"),
        "fn f() -> u32 {\n    return 1.5;\n}\n",
    )
    .unwrap();
    refused(
        &render(Some(&dir), &png),
        &["kernel `linearize`", "cannot convert", KERNEL_DIR_ENV],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `shadowgraph info` with `SHADOWGRAPH_KERNEL_LAYOUT` set to `layout` (unset: `None`).
fn info(layout: Option<&str>) -> Output {
    let envs: Vec<(&str, &OsStr)> = layout
        .map(|l| (KERNEL_LAYOUT_ENV, OsStr::new(l)))
        .into_iter()
        .collect();
    shadowgraph(&[OsStr::new("info")], &envs)
}

/// The layout line of `info`: lavapipe is a CPU driver, so `cpu` unless forced.
#[test]
fn kernel_layout_is_the_devices_unless_forced() {
    let line = |o: &Output| -> String {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let out = String::from_utf8_lossy(&o.stdout).into_owned();
        let line = out.lines().find(|l| l.starts_with("kernel layout"));
        line.unwrap_or_else(|| panic!("no layout line: {out}"))
            .to_string()
    };
    assert!(
        line(&info(None)).ends_with(" cpu"),
        "lavapipe is a CPU driver"
    );
    assert!(line(&info(Some("gpu"))).ends_with(" gpu"));
    assert!(line(&info(Some("cpu"))).ends_with(" cpu"));

    let dir = temp_dir("layout");
    let o = render_with(
        &dir.join("out.png"),
        &[(KERNEL_LAYOUT_ENV, OsStr::new("fast"))],
    );
    refused(&o, &[KERNEL_LAYOUT_ENV, "fast", "`gpu` or `cpu`"]);
    let _ = std::fs::remove_dir_all(&dir);
}
