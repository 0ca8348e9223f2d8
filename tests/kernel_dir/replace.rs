//! Kernels replaced from a folder by name, refused ones as one-line errors, and the kernel layout.

use super::*;

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
    refused(
        &o,
        &[
            KERNEL_LAYOUT_ENV,
            "fast",
            "`gpu`, `cpu`, `redesign` or `redesign-textures`",
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
}
