//! Scene files: every bad input is refused with an error that names the file, the key and the
//! line; every bundled scene loads, and its lights cast shadows the camera can see. No GPU needed.

use std::path::{Path, PathBuf};

use glam::{Vec3, Vec4Swizzles};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{Error, LightKind, PcfKernel, Technique};

/// A minimal valid scene; each error case changes one thing in it.
///
/// Line numbers the cases below rely on (checked by `base_scene_is_valid`):
/// 4 `width`, 8 `position` (camera), 13 `kind`, 14 `position` (light), 17 `near`, 18 `far`,
/// 21 `technique`, 25 `size` (plane), 28 `shape` (box), 30 `translate`.
const BASE: &str = r#"ambient = [0.1, 0.1, 0.1]

[output]
width = 64
height = 48

[camera]
position = [0.0, 3.0, 6.0]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 45.0

[[light]]
kind = "directional"
position = [-3.0, 6.0, 2.0]
target = [0.0, 0.0, 0.0]
extent = 4.0
near = 1.0
far = 20.0

[light.shadow]
technique = "hard"

[[object]]
shape = "plane"
size = [8.0, 8.0]

[[object]]
shape = "box"
size = [1.0, 1.0, 1.0]
translate = [0.0, 0.5, 0.0]
"#;

const INLINE: &str = "inline.toml";

/// `BASE` with each `(from, to)` applied; each `from` must occur exactly once.
#[track_caller]
fn scene_with(edits: &[(&str, &str)]) -> String {
    let mut text = BASE.to_string();
    for (from, to) in edits {
        assert_eq!(
            text.matches(from).count(),
            1,
            "`{from}` must occur once in the scene text"
        );
        text = text.replacen(from, to, 1);
    }
    text
}

/// 1-based line of the one occurrence of `needle` in `text`.
#[track_caller]
fn line_of(text: &str, needle: &str) -> usize {
    assert_eq!(
        text.matches(needle).count(),
        1,
        "`{needle}` must occur once"
    );
    let at = text.find(needle).unwrap();
    text[..at].matches('\n').count() + 1
}

fn parse(text: &str) -> shadowgraph::Result<Scene> {
    Scene::parse(Path::new(INLINE), text)
}

/// Parses `text` expecting `Error::Scene` at `path:line:`; its Display must contain each of
/// `needles`. Returns the Display.
#[track_caller]
fn expect_at(path: &Path, text: &str, line: usize, needles: &[&str]) -> String {
    let err = match Scene::parse(path, text) {
        Ok(_) => panic!("expected an error at line {line}, but the scene parsed:\n{text}"),
        Err(e) => e,
    };
    let shown = err.to_string();
    match &err {
        Error::Scene {
            path: p,
            location,
            message,
        } => {
            assert_eq!(p, path, "error names the wrong file: {shown}");
            let mut parts = location.split(':');
            assert_eq!(
                parts.next(),
                Some(""),
                "location `{location}` must start with ':'"
            );
            assert_eq!(
                parts.next().and_then(|l| l.parse::<usize>().ok()),
                Some(line),
                "wrong line in `{shown}`"
            );
            let col = parts.next().and_then(|c| c.parse::<usize>().ok());
            assert!(matches!(col, Some(c) if c >= 1), "no column in `{shown}`");
            assert!(
                parts.next().is_none(),
                "location `{location}` is not `:line:col`"
            );
            assert!(!message.trim().is_empty(), "empty message: {shown}");
        }
        other => panic!("expected Error::Scene, got {other:?}"),
    }
    let prefix = format!("{}:{line}:", path.display());
    assert!(
        shown.starts_with(&prefix),
        "`{shown}` does not start with `{prefix}`"
    );
    for needle in needles {
        assert!(
            shown.contains(needle),
            "`{shown}` does not mention `{needle}`"
        );
    }
    shown
}

/// `expect_at` for inline text, with the line found from `at` (a unique substring of `text`).
#[track_caller]
fn expect(text: &str, at: &str, needles: &[&str]) -> String {
    expect_at(Path::new(INLINE), text, line_of(text, at), needles)
}

/// Column (1-based) of the one occurrence of `needle` within its line.
fn col_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap();
    at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1
}

fn location(err: &Error) -> &str {
    match err {
        Error::Scene { location, .. } => location,
        other => panic!("expected Error::Scene, got {other:?}"),
    }
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

fn bundled_scenes() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("scenes/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

// ---------------------------------------------------------------------------------------------
// The base text itself.

#[test]
fn base_scene_is_valid() {
    let s = parse(BASE).expect("base scene parses");
    assert_eq!((s.width, s.height), (64, 48));
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].shadow.technique, Technique::Hard);
    assert_eq!(s.objects.len(), 2);
    for (needle, line) in [
        ("width", 4),
        ("position = [0.0, 3.0", 8),
        ("kind", 13),
        ("position = [-3.0", 14),
        ("near", 17),
        ("far", 18),
        ("technique", 21),
        ("size = [8.0", 25),
        ("shape = \"box\"", 28),
        ("translate", 30),
    ] {
        assert_eq!(line_of(BASE, needle), line, "`{needle}`");
    }
}

// ---------------------------------------------------------------------------------------------
// Syntax and structure (reported by the TOML reader).

#[test]
fn malformed_toml_names_the_line() {
    let text = scene_with(&[("width = 64", "width = = 64")]);
    let shown = expect(&text, "width = = 64", &[]);
    assert!(shown.starts_with("inline.toml:4:"), "{shown}");

    let text = scene_with(&[("kind = \"directional\"", "kind = \"directional")]);
    expect(&text, "kind = \"directional", &[]);

    let text = scene_with(&[("[[object]]\nshape = \"box\"", "[[object]\nshape = \"box\"")]);
    expect(&text, "[[object]\n", &[]);
}

#[test]
fn unknown_key_is_named() {
    let text = scene_with(&[("technique = \"hard\"", "techniqe = \"hard\"")]);
    let shown = expect(&text, "techniqe", &["techniqe"]);
    assert!(shown.starts_with("inline.toml:21:"), "{shown}");

    let text = scene_with(&[("extent = 4.0", "extent = 4.0\nfar_plane = 9.0")]);
    expect(&text, "far_plane", &["far_plane"]);

    let text = scene_with(&[(
        "translate = [0.0, 0.5, 0.0]",
        "translation = [0.0, 0.5, 0.0]",
    )]);
    expect(&text, "translation", &["translation"]);
}

#[test]
fn ambient_after_a_table_is_an_unknown_key_of_that_table() {
    // Top-level keys must come before the first table: here `ambient` lands in `[camera]`.
    let text = scene_with(&[
        ("ambient = [0.1, 0.1, 0.1]\n", ""),
        (
            "fov_y_degrees = 45.0",
            "fov_y_degrees = 45.0\nambient = [0.1, 0.1, 0.1]",
        ),
    ]);
    expect(&text, "ambient", &["ambient"]);
}

#[test]
fn missing_required_key_is_named() {
    let text = scene_with(&[("position = [0.0, 3.0, 6.0]\n", "")]);
    expect(&text, "[camera]", &["position"]);

    let text = scene_with(&[("width = 64\n", "")]);
    expect(&text, "[output]", &["width"]);

    let text = scene_with(&[("technique = \"hard\"\n", "bias = 0.001\n")]);
    expect(&text, "[light.shadow]", &["technique"]);
}

#[test]
fn wrong_value_type_names_the_line() {
    let text = scene_with(&[("width = 64", "width = \"64\"")]);
    expect(&text, "width", &[]);

    let text = scene_with(&[(
        "target = [0.0, 0.0, 0.0]\nextent",
        "target = [0.0, 0.0]\nextent",
    )]);
    expect(&text, "target = [0.0, 0.0]", &[]);
}

#[test]
fn integers_are_accepted_where_numbers_are_expected() {
    let text = scene_with(&[
        ("position = [0.0, 3.0, 6.0]", "position = [0, 3, 6]"),
        ("fov_y_degrees = 45.0", "fov_y_degrees = 45"),
        ("extent = 4.0", "extent = 4"),
        ("size = [8.0, 8.0]", "size = 8"),
        ("translate = [0.0, 0.5, 0.0]", "translate = [0, 0.5, 0]"),
    ]);
    let s = parse(&text).expect("integers accepted");
    assert_eq!(s.camera.position, Vec3::new(0.0, 3.0, 6.0));
    assert_eq!(s.camera.fov_y_degrees, 45.0);
    assert_eq!(s.lights[0].kind, LightKind::Directional { extent: 4.0 });
}

// ---------------------------------------------------------------------------------------------
// Unknown names.

#[test]
fn unknown_technique() {
    let text = scene_with(&[("technique = \"hard\"", "technique = \"foo\"")]);
    let shown = expect(
        &text,
        "technique",
        &["light[0].shadow.technique", "\"foo\"", "pcss"],
    );
    assert!(shown.starts_with("inline.toml:21:"), "{shown}");
    // The span is the value's.
    let err = parse(&text).unwrap_err();
    assert_eq!(location(&err), format!(":21:{}", col_of(&text, "\"foo\"")));
}

#[test]
fn unknown_light_kind() {
    let text = scene_with(&[("kind = \"directional\"", "kind = \"area\"")]);
    let shown = expect(
        &text,
        "kind",
        &["light[0].kind", "\"area\"", "spot", "point"],
    );
    assert!(shown.starts_with("inline.toml:13:"), "{shown}");
}

/// The base scene's light as a point light (no extent, no target needed) with `shadow` lines.
fn point_scene(shadow: &str, map: u32) -> String {
    scene_with(&[
        ("kind = \"directional\"", "kind = \"point\""),
        ("target = [0.0, 0.0, 0.0]\nextent = 4.0\n", ""),
        (
            "far = 20.0\n",
            &format!("far = 20.0\nshadow_map = {map}\nsize = 0.2\n"),
        ),
        ("technique = \"hard\"\n", shadow),
    ])
}

#[test]
fn point_light_loads_without_target_or_extent() {
    let text = point_scene("technique = \"pcf\"\nradius = 2\n", 256);
    let scene = parse(&text).expect("a point light needs no target");
    let light = &scene.lights[0];
    assert_eq!(light.kind, shadowgraph::LightKind::Point);
    // PCF radius 2 reads 3 texels around the receiver: a guard band of 4.
    let layout = light.point_layout().expect("layout");
    assert_eq!((layout.face, layout.guard), (256, 4));
    assert_eq!(light.map_dims(), (768, 512));
}

#[test]
fn point_light_refuses_what_six_faces_cannot_bound() {
    // A technique whose rays no guard band bounds.
    let text = point_scene("technique = \"smrt\"\n", 512);
    expect(
        &text,
        "technique = \"smrt\"",
        &["light[0].shadow", "point lights", "smrt"],
    );
    // A second-depth technique (one peeled map, not six faces).
    let text = point_scene("technique = \"midpoint\"\n", 512);
    expect(
        &text,
        "technique = \"midpoint\"",
        &["point lights", "midpoint"],
    );
    // Anisotropic mips.
    let text = point_scene(
        "technique = \"vsm\"\nfilter = \"mips\"\nfilter_width = 4\nmax_anisotropy = 4\n",
        512,
    );
    expect(
        &text,
        "technique = \"vsm\"",
        &["anisotropic", "max_anisotropy"],
    );
    // A blur too wide for the face: guard band 34 needs a face of 136 texels.
    let text = point_scene(
        "technique = \"vsm\"\nfilter = \"blur\"\nfilter_radius = 32\nfilter_sigma = 10\n",
        128,
    );
    expect(
        &text,
        "technique = \"vsm\"",
        &["guard band of 34", "at least 136"],
    );
    // The receiver-plane bias is derived per face: accepted.
    let text = point_scene("technique = \"pcf\"\nbias_mode = \"receiver_plane\"\n", 512);
    let scene = parse(&text).expect("receiver-plane bias on a point light");
    assert!(scene.lights[0].shadow.receiver_plane > 0.0);
    // Cascades.
    let text = point_scene("technique = \"hard\"\ncascades = 2\n", 512);
    expect(
        &text,
        "cascades = 2",
        &["light[0].shadow.cascades", "directional"],
    );
}

#[test]
fn spot_light_still_needs_a_target() {
    let text = scene_with(&[
        ("kind = \"directional\"", "kind = \"spot\""),
        (
            "target = [0.0, 0.0, 0.0]\nextent = 4.0\n",
            "fov_degrees = 60.0\n",
        ),
    ]);
    expect(
        &text,
        "kind = \"spot\"",
        &["light[0].target", "required", "spot"],
    );
}

#[test]
fn unknown_shape() {
    let text = scene_with(&[("shape = \"box\"", "shape = \"torus\"")]);
    let shown = expect(
        &text,
        "torus",
        &["object[1].shape", "\"torus\"", "cylinder"],
    );
    assert!(shown.starts_with("inline.toml:28:"), "{shown}");
}

#[test]
fn unknown_pcf_kernel() {
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"pcf\"\nkernel = \"gauss\"",
    )]);
    expect(&text, "gauss", &["light[0].shadow.kernel", "\"gauss\""]);
}

#[test]
fn second_light_is_indexed() {
    let text = format!(
        "{BASE}\n[[light]]\nkind = \"spot\"\nposition = [0.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\n\
         fov_degrees = 60.0\n\n[light.shadow]\ntechnique = \"pcf\"\nkernel = \"hardware\"\nradius = 2\n"
    );
    expect(&text, "radius", &["light[1].shadow.radius", "hardware"]);
}

// ---------------------------------------------------------------------------------------------
// Mesh files.

#[test]
fn missing_mesh_file_names_the_path_key_and_line() {
    let text =
        format!("{BASE}\n[[object]]\nshape = \"mesh\"\npath = \"meshes/no_such_mesh.obj\"\n");
    let scene_path = scenes_dir().join("inline.toml");
    let line = line_of(&text, "path =");
    let shown = expect_at(
        &scene_path,
        &text,
        line,
        &["object[2].path", "no_such_mesh.obj", "not found"],
    );
    assert_eq!(line, 34);
    // The path in the message is resolved against the scene file's folder.
    assert!(
        shown.contains(&scenes_dir().join("meshes").display().to_string()),
        "{shown}"
    );
}

#[test]
fn mesh_without_path() {
    let text = format!("{BASE}\n[[object]]\nshape = \"mesh\"\nscale = 2.0\n");
    expect(&text, "shape = \"mesh\"", &["object[2].path", "missing"]);
}

#[test]
fn unreadable_scene_file_is_an_io_error() {
    let path = scenes_dir().join("no_such_scene.toml");
    match Scene::load(&path) {
        Err(e @ Error::Io { .. }) => {
            assert!(e.to_string().contains("no_such_scene.toml"), "{e}");
        }
        Err(other) => panic!("expected Error::Io, got {other:?}"),
        Ok(_) => panic!("loaded a missing file"),
    }
}

// ---------------------------------------------------------------------------------------------
// Values out of range.

#[test]
fn zero_size_output() {
    let text = scene_with(&[("width = 64", "width = 0")]);
    let shown = expect(&text, "width", &["output.width", "0"]);
    assert!(shown.starts_with("inline.toml:4:"), "{shown}");

    let text = scene_with(&[("height = 48", "height = -3")]);
    expect(&text, "height", &["output.height", "-3"]);

    let text = scene_with(&[("height = 48", "height = 100000000")]);
    expect(&text, "height", &["output.height"]);
}

#[test]
fn nan_in_a_transform() {
    let text = scene_with(&[("translate = [0.0, 0.5, 0.0]", "translate = [nan, 0, 0]")]);
    let shown = expect(
        &text,
        "translate",
        &["object[1].translate", "finite", "NaN"],
    );
    assert!(shown.starts_with("inline.toml:30:"), "{shown}");

    let text = scene_with(&[(
        "translate = [0.0, 0.5, 0.0]",
        "translate = [0.0, 0.5, 0.0]\nrotate_degrees = [0, -nan, 0]",
    )]);
    expect(
        &text,
        "rotate_degrees",
        &["object[1].rotate_degrees", "finite"],
    );

    let text = scene_with(&[(
        "translate = [0.0, 0.5, 0.0]",
        "translate = [0.0, 0.5, 0.0]\nscale = [1.0, nan, 1.0]",
    )]);
    expect(&text, "scale", &["object[1].scale"]);

    let text = scene_with(&[("size = [1.0, 1.0, 1.0]", "size = nan")]);
    expect(&text, "size = nan", &["object[1].size"]);
}

#[test]
fn infinite_light_position() {
    let text = scene_with(&[("position = [-3.0, 6.0, 2.0]", "position = [-3.0, inf, 2.0]")]);
    let shown = expect(&text, "inf", &["light[0].position", "finite", "inf"]);
    assert!(shown.starts_with("inline.toml:14:"), "{shown}");

    let text = scene_with(&[("position = [0.0, 3.0, 6.0]", "position = [0.0, 3.0, -inf]")]);
    expect(&text, "-inf", &["camera.position", "finite"]);

    let text = scene_with(&[("extent = 4.0", "extent = +inf")]);
    expect(&text, "extent", &["light[0].extent"]);
}

#[test]
fn far_not_beyond_near() {
    let text = scene_with(&[("far = 20.0", "far = 1.0")]);
    let shown = expect(&text, "far", &["light[0].far", "light[0].near"]);
    assert!(shown.starts_with("inline.toml:18:"), "{shown}");

    let text = scene_with(&[("far = 20.0", "far = 0.5")]);
    expect(&text, "far", &["light[0].far", "light[0].near"]);

    // Only `near` written, beyond the default far (50): the error points at `near`.
    let text = scene_with(&[("far = 20.0\n", ""), ("near = 1.0", "near = 60.0")]);
    expect(&text, "near", &["light[0].far", "light[0].near"]);

    let text = scene_with(&[("near = 1.0", "near = 0.0")]);
    expect(&text, "near", &["light[0].near"]);
}

#[test]
fn pcss_needs_a_light_size() {
    let text = scene_with(&[("technique = \"hard\"", "technique = \"pcss\"")]);
    // No `size` key: the error points at the light (its `kind`).
    let shown = expect(&text, "kind", &["light[0].size", "pcss"]);
    assert!(shown.starts_with("inline.toml:13:"), "{shown}");

    let text = scene_with(&[
        ("technique = \"hard\"", "technique = \"pcss\""),
        ("far = 20.0", "far = 20.0\nsize = 0.0"),
    ]);
    expect(&text, "size = 0.0", &["light[0].size", "pcss"]);

    let text = scene_with(&[
        ("technique = \"hard\"", "technique = \"pcss\""),
        ("far = 20.0", "far = 20.0\nsize = -1.0"),
    ]);
    expect(&text, "size = -1.0", &["light[0].size"]);

    let text = scene_with(&[
        ("technique = \"hard\"", "technique = \"pcss\""),
        ("far = 20.0", "far = 20.0\nsize = 0.5"),
    ]);
    let s = parse(&text).expect("pcss with size parses");
    assert_eq!(s.lights[0].size, 0.5);
    assert!(matches!(
        s.lights[0].shadow.technique,
        Technique::Pcss { .. }
    ));
}

#[test]
fn parameter_that_does_not_apply_to_the_technique() {
    let text = scene_with(&[("technique = \"hard\"", "technique = \"hard\"\nradius = 2")]);
    let shown = expect(&text, "radius", &["light[0].shadow.radius", "\"hard\""]);
    assert!(shown.starts_with("inline.toml:22:"), "{shown}");

    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"pcf\"\nblocker_samples = 8",
    )]);
    expect(
        &text,
        "blocker_samples",
        &["light[0].shadow.blocker_samples", "\"pcf\""],
    );

    let text = scene_with(&[
        (
            "technique = \"hard\"",
            "technique = \"pcss\"\nkernel = \"tent\"",
        ),
        ("far = 20.0", "far = 20.0\nsize = 0.5"),
    ]);
    expect(&text, "kernel", &["light[0].shadow.kernel", "\"pcss\""]);

    // And the ones that do apply parse.
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"pcf\"\nradius = 3\nkernel = \"tent\"",
    )]);
    let s = parse(&text).expect("pcf parameters parse");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::Pcf {
            radius: 3,
            kernel: PcfKernel::Tent
        }
    );
}

#[test]
fn light_kind_specific_keys() {
    // Spot without its cone angle: points at `kind`.
    let text = scene_with(&[
        ("kind = \"directional\"", "kind = \"spot\""),
        ("extent = 4.0\n", ""),
    ]);
    expect(&text, "kind", &["light[0].fov_degrees", "missing"]);

    // Spot with a directional-only key.
    let text = scene_with(&[(
        "kind = \"directional\"",
        "kind = \"spot\"\nfov_degrees = 50.0",
    )]);
    expect(&text, "extent", &["light[0].extent", "directional"]);

    // Directional without its extent.
    let text = scene_with(&[("extent = 4.0\n", "")]);
    expect(&text, "kind", &["light[0].extent", "missing"]);

    let text = scene_with(&[("extent = 4.0", "extent = 4.0\nfov_degrees = 30.0")]);
    expect(&text, "fov_degrees", &["light[0].fov_degrees", "spot"]);
}

#[test]
fn degenerate_directions() {
    let text = scene_with(&[(
        "target = [0.0, 0.0, 0.0]\nextent",
        "target = [-3.0, 6.0, 2.0]\nextent",
    )]);
    expect(&text, "target = [-3.0", &["light[0].target"]);

    let text = scene_with(&[(
        "target = [0.0, 0.0, 0.0]\nfov",
        "target = [0.0, 3.0, 6.0]\nfov",
    )]);
    expect(&text, "target = [0.0, 3.0", &["camera.target"]);

    // Looking straight down with the default up vector: no `up` key, so point at the target.
    let text = scene_with(&[("position = [0.0, 3.0, 6.0]", "position = [0.0, 6.0, 0.0]")]);
    expect(
        &text,
        "target = [0.0, 0.0, 0.0]\nfov",
        &["camera.up", "parallel"],
    );

    let text = scene_with(&[(
        "fov_y_degrees = 45.0",
        "fov_y_degrees = 45.0\nup = [0.0, 0.0, 0.0]",
    )]);
    expect(&text, "up =", &["camera.up"]);
}

#[test]
fn other_ranges() {
    let text = scene_with(&[("fov_y_degrees = 45.0", "fov_y_degrees = 180.0")]);
    expect(&text, "fov_y_degrees", &["camera.fov_y_degrees", "180"]);

    let text = scene_with(&[("extent = 4.0", "extent = 4.0\nshadow_map = 0")]);
    expect(&text, "shadow_map", &["light[0].shadow_map"]);

    let text = scene_with(&[("technique = \"hard\"", "technique = \"pcf\"\nradius = 99")]);
    expect(&text, "radius", &["light[0].shadow.radius", "99"]);

    let text = scene_with(&[("size = [8.0, 8.0]", "size = [8.0, 0.0]")]);
    expect(&text, "size = [8.0, 0.0]", &["object[0].size"]);

    let text = scene_with(&[("size = [8.0, 8.0]", "size = [8.0, 8.0, 8.0]")]);
    expect(&text, "size = [8.0, 8.0, 8.0]", &["object[0].size"]);

    let text = scene_with(&[("size = [1.0, 1.0, 1.0]", "size = [1.0, 1.0]")]);
    expect(&text, "size = [1.0, 1.0]", &["object[1].size"]);

    let text = format!("{BASE}\n[[object]]\nshape = \"sphere\"\nradius = -1.0\n");
    expect(&text, "radius", &["object[2].radius"]);

    let text = format!("{BASE}\n[[object]]\nshape = \"cylinder\"\nradius = 1.0\n");
    expect(
        &text,
        "shape = \"cylinder\"",
        &["object[2].height", "missing"],
    );

    let text = scene_with(&[("technique = \"hard\"", "technique = \"hard\"\nbias = 2.0")]);
    expect(&text, "bias", &["light[0].shadow.bias"]);
}

// ---------------------------------------------------------------------------------------------
// Empty scenes.

#[test]
fn scene_without_lights() {
    let start = BASE.find("[[light]]").unwrap();
    let end = BASE.find("[[object]]").unwrap();
    let text = format!("{}{}", &BASE[..start], &BASE[end..]);
    let err = parse(&text).unwrap_err();
    let shown = err.to_string();
    assert!(matches!(err, Error::Scene { .. }), "{err:?}");
    // Nothing to point at: no location, but the file and the missing table are named.
    assert_eq!(location(&err), "");
    assert!(shown.starts_with("inline.toml: "), "{shown}");
    assert!(shown.contains("[[light]]"), "{shown}");
}

#[test]
fn scene_without_objects() {
    let end = BASE.find("[[object]]").unwrap();
    let err = parse(&BASE[..end]).unwrap_err();
    let shown = err.to_string();
    assert!(shown.starts_with("inline.toml"), "{shown}");
    assert!(shown.contains("[[object]]"), "{shown}");
}

#[test]
fn location_is_counted_in_the_text_given() {
    // Leading blank lines and comments shift the line; CRLF line ends count once.
    let text = format!(
        "# comment\n\n{}",
        scene_with(&[("width = 64", "width = 0")])
    );
    expect(&text, "width", &["output.width"]);
    assert_eq!(line_of(&text, "width"), 6);

    let crlf = scene_with(&[("technique = \"hard\"", "technique = \"foo\"")]).replace('\n', "\r\n");
    expect(&crlf, "technique", &["light[0].shadow.technique"]);
}

// ---------------------------------------------------------------------------------------------
// Built-in shapes.

#[test]
fn built_in_shapes_wind_counter_clockwise_around_their_normals() {
    let text = format!(
        "{BASE}\n[[object]]\nshape = \"sphere\"\nradius = 0.5\ntranslate = [2.0, 1.0, 0.0]\n\
         \n[[object]]\nshape = \"cylinder\"\nradius = 0.3\nheight = 2.0\nrotate_degrees = [10.0, 20.0, 30.0]\n\
         \n[[object]]\nshape = \"box\"\nsize = [1.0, 2.0, 3.0]\nscale = [2.0, 1.0, 0.5]\nrotate_degrees = [0.0, 45.0, 0.0]\n"
    );
    let s = parse(&text).unwrap();
    let names = ["plane", "box", "sphere", "cylinder", "scaled box"];
    assert_eq!(s.objects.len(), names.len());
    for (o, name) in s.objects.iter().zip(names) {
        let m = &o.mesh;
        assert_eq!(m.indices.len() % 3, 0);
        let mut checked = 0;
        for (t, tri) in m.indices.chunks_exact(3).enumerate() {
            let [a, b, c] = [0, 1, 2].map(|k| tri[k] as usize);
            let face = (m.positions[b] - m.positions[a]).cross(m.positions[c] - m.positions[a]);
            if face.length() < 1e-9 {
                continue; // the sphere's poles
            }
            let n = m.normals[a] + m.normals[b] + m.normals[c];
            assert!(
                face.dot(n) > 0.0,
                "{name}: triangle {t} winds clockwise around its normals (face {face}, normal {n})"
            );
            checked += 1;
        }
        assert!(checked > 0, "{name}");
        for n in &m.normals {
            assert!(
                (n.length() - 1.0).abs() < 1e-4,
                "{name}: normal {n} is not unit"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Bundled scenes.

#[test]
fn every_bundled_scene_loads() {
    let files = bundled_scenes();
    assert!(
        files.len() >= 6,
        "expected the bundled scenes, found {files:?}"
    );
    for file in &files {
        let s = Scene::load(file).unwrap_or_else(|e| panic!("{e}"));
        let name = file.display();
        let first = std::fs::read_to_string(file).unwrap();
        assert!(
            first.starts_with("# "),
            "{name} must start with a comment saying what it shows"
        );
        assert!(!s.lights.is_empty(), "{name}: no lights");
        assert!(!s.objects.is_empty(), "{name}: no objects");
        assert!(
            s.width <= 640 && s.height <= 480,
            "{name}: keep outputs small"
        );
        for l in &s.lights {
            assert!(
                l.shadow_map <= 1024,
                "{name}: shadow map {} too large",
                l.shadow_map
            );
        }
        for (i, o) in s.objects.iter().enumerate() {
            let m = &o.mesh;
            assert!(!m.indices.is_empty(), "{name}: object {i} has no triangles");
            assert_eq!(m.positions.len(), m.normals.len());
            assert!(m.indices.iter().all(|&k| (k as usize) < m.positions.len()));
            assert!(
                m.positions.iter().all(|p| p.is_finite()),
                "{name}: object {i}"
            );
            assert!(
                m.normals.iter().all(|n| n.is_finite()),
                "{name}: object {i}"
            );
        }
        let vertices = s.vertices();
        assert!(
            vertices
                .iter()
                .all(|v| v.position.iter().chain(&v.normal).all(|x| x.is_finite()))
        );
    }
}

#[test]
fn bundled_bunny_is_a_real_mesh_on_the_ground() {
    let s = Scene::load(scenes_dir().join("bunny.toml")).unwrap();
    assert!(matches!(
        s.lights[0].shadow.technique,
        Technique::Pcf {
            radius: 2,
            kernel: PcfKernel::Tent
        }
    ));
    let bunny = s
        .objects
        .iter()
        .max_by_key(|o| o.mesh.indices.len())
        .unwrap();
    let triangles = bunny.mesh.indices.len() / 3;
    assert!(triangles > 1000, "bunny has only {triangles} triangles");
    let (lo, hi) = bunny.mesh.positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    assert!(lo.y.abs() < 0.01, "bunny's feet at y = {}", lo.y);
    assert!(
        (hi.y - lo.y - 2.0).abs() < 0.05,
        "bunny is {} tall",
        hi.y - lo.y
    );
}

#[test]
fn bundled_scenes_use_the_techniques_they_demonstrate() {
    let load = |n: &str| Scene::load(scenes_dir().join(n)).unwrap();
    let techniques = |s: &Scene| -> Vec<&'static str> {
        s.lights.iter().map(|l| l.shadow.technique.name()).collect()
    };
    let s = load("sphere_on_plane.toml");
    assert_eq!(techniques(&s), ["pcss"]);
    assert!(matches!(s.lights[0].kind, LightKind::Spot { .. }));
    assert_eq!(s.lights[0].size, 0.5);

    let s = load("grazing.toml");
    assert_eq!(techniques(&s), ["hard"]);
    let elevation = (-s.lights[0].direction().y).asin().to_degrees();
    assert!(
        (elevation - 8.0).abs() < 0.5,
        "grazing light is {elevation}° up"
    );

    let s = load("pole.toml");
    assert_eq!(techniques(&s), ["pcss"]);
    assert!(matches!(s.lights[0].kind, LightKind::Directional { .. }));
    assert_eq!(s.lights[0].size, 1.0);

    let s = load("stacked.toml");
    assert_eq!(techniques(&s), ["pcf"]);
    assert!(matches!(s.lights[0].kind, LightKind::Spot { .. }));

    let s = load("two_lights.toml");
    assert_eq!(techniques(&s), ["hard", "pcf"]);
    assert!(matches!(
        s.lights[1].shadow.technique,
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        }
    ));
}

/// Every object above the ground is inside every light's frustum, its shadow on y = 0 lies
/// within the light's depth range, and both the object and its shadow are in the camera's view.
#[test]
fn bundled_scenes_cast_shadows_the_camera_sees() {
    for file in bundled_scenes() {
        let name = file.display().to_string();
        if name.ends_with("city_street.toml") {
            // A street-level view of city.toml's objects (checked there): most buildings lie
            // behind the camera or beside the street, by design.
            continue;
        }
        let s = Scene::load(&file).unwrap();
        let camera = s.camera.view_proj(s.width as f32 / s.height as f32);
        let on_screen = |p: Vec3| {
            let c = camera * p.extend(1.0);
            let ndc = c.xyz() / c.w;
            c.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0
        };
        let casters: Vec<_> = s
            .objects
            .iter()
            .filter(|o| o.mesh.positions.iter().any(|p| p.y > 0.01))
            .collect();
        assert!(!casters.is_empty(), "{name}: nothing above the ground");
        for (li, light) in s.lights.iter().enumerate() {
            let vp = light.projection() * light.view();
            let in_light = |p: Vec3| {
                if light.kind == LightKind::Point {
                    // Six faces see every direction: only the depth range bounds them.
                    let z = (p - light.position).abs().max_element();
                    return (light.near..=light.far).contains(&z);
                }
                let c = vp * p.extend(1.0);
                let ndc = c.xyz() / c.w;
                c.w > 0.0
                    && ndc.x.abs() <= 1.0
                    && ndc.y.abs() <= 1.0
                    && (0.0..=1.0).contains(&ndc.z)
            };
            for (oi, o) in casters.iter().enumerate() {
                // Where each vertex's shadow falls on y = 0 (vertices on the ground are their own).
                let mut ground = Vec::with_capacity(o.mesh.positions.len());
                for &p in &o.mesh.positions {
                    assert!(
                        in_light(p),
                        "{name}: caster {oi} vertex {p} outside light {li}"
                    );
                    if p.y <= 1e-4 {
                        ground.push(p);
                        continue;
                    }
                    let ray = match light.kind {
                        LightKind::Directional { .. } => light.direction(),
                        LightKind::Spot { .. } | LightKind::Point => {
                            (p - light.position).normalize()
                        }
                    };
                    assert!(ray.y < 0.0, "{name}: light {li} does not shine down on {p}");
                    let g = p - ray * (p.y / ray.y);
                    assert!(
                        in_light(g),
                        "{name}: shadow of {p} at {g} outside light {li}'s range"
                    );
                    ground.push(g);
                }
                let centre = o.mesh.positions.iter().sum::<Vec3>() / o.mesh.positions.len() as f32;
                assert!(on_screen(centre), "{name}: caster {oi} off screen");
                let shadow = ground.iter().sum::<Vec3>() / ground.len() as f32;
                let seen = ground.iter().filter(|&&g| on_screen(g)).count();
                assert!(
                    on_screen(shadow) && 2 * seen >= ground.len(),
                    "{name}: light {li}'s shadow of caster {oi} (around {shadow}) is off screen \
                     ({seen} of {} points seen)",
                    ground.len()
                );
            }
        }
    }
}

#[test]
fn sat_filter_keys() {
    use shadowgraph::{Filter, SatVariant};
    // `sat_sums` needs the sat filter; `filter_width` needs mips or sat.
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"blur\"\nsat_sums = \"float\"",
    )]);
    expect(&text, "sat_sums", &["light[0].shadow.sat_sums", "sat"]);
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"sat\"\nsat_sums = \"double\"",
    )]);
    expect(&text, "sat_sums", &["light[0].shadow.sat_sums", "double"]);
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"sat\"\nfilter_width = 2000.0",
    )]);
    expect(&text, "filter_width", &["light[0].shadow.filter_width"]);

    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"msm\"\nfilter = \"sat\"\nfilter_width = 7.5\nsat_sums = \"float\"",
    )]);
    let s = parse(&text).expect("sat parameters parse");
    assert_eq!(
        s.lights[0].shadow.technique.filter(),
        Some(Filter::Sat {
            width: 7.5,
            variant: SatVariant::Float
        })
    );
}

/// Exponents past what a summed-area table keeps accurate are clamped to
/// `sat_exponent_limit`, with a warning when the scene set them; defaults clamp silently.
#[test]
fn sat_filter_clamps_exponents() {
    use shadowgraph::Filter;
    use shadowgraph::low_level::technique::sat_exponent_limit;
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"evsm4\"\nfilter = \"sat\"\nfilter_width = 4.0",
    )]);
    let s = parse(&text).expect("parses");
    let filter = Filter::Sat {
        width: 4.0,
        variant: shadowgraph::SatVariant::Fixed,
    };
    // (4 + 1)² = 25 texels: ½ ln(2²² / 25) = 6.0.
    let limit = sat_exponent_limit(&filter, false).expect("a limit");
    assert!(
        (limit - 0.5 * (4194304.0f32 / 25.0).ln()).abs() < 1e-5,
        "{limit}"
    );
    let Technique::Evsm {
        exp_pos, exp_neg, ..
    } = s.lights[0].shadow.technique
    else {
        panic!("evsm4")
    };
    assert_eq!((exp_pos, exp_neg), (limit, 5.0f32.min(limit)));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);

    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"esm\"\nfilter = \"sat\"\nfilter_width = 4.0\nexponent = 60.0",
    )]);
    let s = parse(&text).expect("parses");
    let esm_limit = sat_exponent_limit(&filter, true).expect("a limit");
    assert!((esm_limit - 4.0 * limit).abs() < 1e-4);
    let Technique::Esm { exponent, .. } = s.lights[0].shadow.technique else {
        panic!("esm")
    };
    assert_eq!(exponent, esm_limit);
    assert!(
        s.warnings.iter().any(|w| w.contains("exponent")),
        "{:?}",
        s.warnings
    );
}

/// `max_anisotropy` belongs to the mips filter, 0–16.
#[test]
fn max_anisotropy_key() {
    use shadowgraph::Filter;
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"blur\"\nmax_anisotropy = 4",
    )]);
    expect(
        &text,
        "max_anisotropy",
        &["light[0].shadow.max_anisotropy", "mips"],
    );
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"vsm\"\nfilter = \"mips\"\nmax_anisotropy = 17",
    )]);
    expect(&text, "max_anisotropy", &["light[0].shadow.max_anisotropy"]);
    let text = scene_with(&[(
        "technique = \"hard\"",
        "technique = \"esm\"\nfilter = \"mips\"\nfilter_width = 2.0\nmax_anisotropy = 16",
    )]);
    let s = parse(&text).expect("parses");
    assert_eq!(
        s.lights[0].shadow.technique.filter(),
        Some(Filter::Mips {
            width: 2.0,
            max_anisotropy: 16
        })
    );
}

#[test]
fn soft_techniques_keys_defaults_and_errors() {
    use shadowgraph::{SatVariant, Soft, Storage};
    let soft = |keys: &str, size: &str| {
        scene_with(&[
            ("technique = \"hard\"", keys),
            ("far = 20.0", &format!("far = 20.0\n{size}")),
        ])
    };
    // Each needs an area light, named at the light's `kind` when no `size` is given.
    for t in ["cssm", "vssm", "msm_soft"] {
        let text = scene_with(&[("technique = \"hard\"", &format!("technique = \"{t}\""))]);
        let shown = expect(&text, "kind", &["light[0].size", t]);
        assert!(shown.starts_with("inline.toml:13:"), "{shown}");
        let text = soft(&format!("technique = \"{t}\""), "size = 0.0");
        expect(&text, "size = 0.0", &["light[0].size", t]);
    }
    // Defaults: f32 representation, fixed-point sums, search cap 0.1; CSSM as CSM plus the
    // sharpening; VSSM as VSM; soft MSM as MSM.
    let defaults = Soft {
        storage: Storage::F32,
        sums: SatVariant::Fixed,
        max_search: 0.1,
    };
    let s = parse(&soft("technique = \"cssm\"", "size = 0.5")).expect("cssm parses");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::Cssm {
            soft: defaults,
            terms: 8,
            attenuation: 1.0,
            offset: 0.0625,
            scale: 2.0,
            sharpen: shadowgraph::low_level::model::DEFAULT_SHARPEN,
            sharpen_falloff: shadowgraph::low_level::model::DEFAULT_SHARPEN_FALLOFF,
            search: shadowgraph::CssmSearch::Moments,
            resolve: shadowgraph::CssmResolve::TwoDepth,
        }
    );
    let s = parse(&soft("technique = \"vssm\"", "size = 0.5")).expect("vssm parses");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::Vssm {
            soft: defaults,
            bleed: 0.2,
            min_variance: 1e-5,
        }
    );
    let keys = "technique = \"msm_soft\"\nformat = \"unorm16\"\nsat_sums = \"float\"\n\
                max_search = 0.05\nreconstruction = \"hausdorff\"";
    let s = parse(&soft(keys, "size = 0.5")).expect("msm_soft parses");
    assert_eq!(
        s.lights[0].shadow.technique,
        Technique::MsmSoft {
            soft: Soft {
                storage: Storage::Unorm16,
                sums: SatVariant::Float,
                max_search: 0.05,
            },
            hausdorff: true,
            moment_bias: shadowgraph::low_level::model::default_soft_moment_bias(Storage::Unorm16),
            bleed: 0.0,
        }
    );
    // Keys out of range, of another technique, or of a fixed filter name themselves.
    for (keys, at, needles) in [
        (
            "technique = \"cssm\"\nsharpen = -1.0",
            "sharpen",
            &["light[0].shadow.sharpen", "-1"][..],
        ),
        (
            "technique = \"cssm\"\nsharpen_falloff = 1e5",
            "sharpen_falloff",
            &["light[0].shadow.sharpen_falloff"],
        ),
        (
            "technique = \"cssm\"\nterms = 17",
            "terms",
            &["light[0].shadow.terms"],
        ),
        (
            "technique = \"vssm\"\nmax_search = 0.0",
            "max_search",
            &["light[0].shadow.max_search"],
        ),
        (
            "technique = \"vssm\"\nsat_sums = \"double\"",
            "sat_sums",
            &["light[0].shadow.sat_sums", "\"fixed\""],
        ),
        (
            "technique = \"vssm\"\nformat = \"unorm16\"",
            "format",
            &["light[0].shadow.format", "\"f16\""],
        ),
        (
            "technique = \"vssm\"\nfilter = \"sat\"",
            "filter",
            &["light[0].shadow.filter", "\"vssm\""],
        ),
        (
            "technique = \"msm_soft\"\nfilter_width = 4.0",
            "filter_width",
            &["light[0].shadow.filter_width", "\"msm_soft\""],
        ),
        (
            "technique = \"csm\"\nsharpen = 1.0",
            "sharpen",
            &["light[0].shadow.sharpen", "\"csm\""],
        ),
    ] {
        expect(&soft(keys, "size = 0.5"), at, needles);
    }
    // A search cap whose squares no fixed-point table can sum names `max_search`.
    let text = soft(
        "technique = \"vssm\"\nmax_search = 1.0",
        "size = 0.5\nshadow_map = 60000",
    );
    expect(
        &text,
        "max_search",
        &["light[0].shadow.max_search", "sat_sums"],
    );
    let text = soft(
        "technique = \"vssm\"\nmax_search = 1.0\nsat_sums = \"float\"",
        "size = 0.5\nshadow_map = 60000",
    );
    parse(&text).expect("f32 sums have no window limit");
}

/// The cascade keys: ranges by the one checker, the technique (`smrt`) and light kinds that
/// cannot have cascades, each named with its key and line; a valid table gives its values,
/// PCSS's, the soft techniques' and the second-depth techniques' too.
#[test]
fn cascade_keys_are_checked() {
    let tech = "technique = \"hard\"";
    for (edit, at, needles) in [
        (
            "technique = \"hard\"\ncascades = 9",
            "cascades = 9",
            &["cascades", "8"][..],
        ),
        (
            "technique = \"hard\"\ncascades = 0",
            "cascades = 0",
            &["cascades"][..],
        ),
        (
            "technique = \"hard\"\ncascades = 3\ncascade_lambda = 1.5",
            "cascade_lambda = 1.5",
            &["cascade_lambda"][..],
        ),
        (
            "technique = \"pcf\"\ncascades = 3\ncascade_blend = 0.6",
            "cascade_blend = 0.6",
            &["cascade_blend"][..],
        ),
        (
            "technique = \"smrt\"\ncascades = 4",
            "cascades = 4",
            &["cascades", "smrt", "guard band"][..],
        ),
    ] {
        let text = scene_with(&[(tech, edit)]);
        expect(&text, at, needles);
    }
    let spot = scene_with(&[
        (
            "kind = \"directional\"",
            "kind = \"spot\"\nfov_degrees = 60.0",
        ),
        ("extent = 4.0\n", ""),
        (tech, "technique = \"vsm\"\ncascades = 2"),
    ]);
    expect(&spot, "cascades = 2", &["cascades", "directional"]);
    let ok = scene_with(&[(
        tech,
        "technique = \"msm\"\ncascades = 4\ncascade_lambda = 0.8\ncascade_blend = 0.2",
    )]);
    let c = parse(&ok).expect("valid cascades").lights[0]
        .shadow
        .cascades;
    assert_eq!((c.count, c.lambda, c.blend), (4, 0.8, 0.2));
    // A guard band past a quarter of each cascade's map (normal_bias 80: 80 + 3 texels of a
    // 256² map) is named at normal_bias's line with the smallest map that fits.
    let wide = scene_with(&[
        (
            "extent = 4.0\n",
            "extent = 4.0\nsize = 0.2\nshadow_map = 256\n",
        ),
        (
            tech,
            "technique = \"vssm\"\ncascades = 3\nnormal_bias = 80.0",
        ),
    ]);
    expect(
        &wide,
        "normal_bias = 80.0",
        &["guard band of 83 texels", "256", "332", "normal_bias"],
    );
    // PCSS and the soft techniques take cascades (each with a guard band), and so do the
    // second-depth techniques (each cascade peeled).
    for t in [
        "pcss",
        "vssm",
        "msm_soft",
        "cssm",
        "midpoint",
        "second_depth",
    ] {
        let text = scene_with(&[
            ("extent = 4.0\n", "extent = 4.0\nsize = 0.2\n"),
            (tech, &format!("technique = \"{t}\"\ncascades = 3")),
        ]);
        let c = parse(&text).unwrap_or_else(|e| panic!("{t}: {e}")).lights[0]
            .shadow
            .cascades;
        assert_eq!(c.count, 3, "{t}");
    }
    let c = parse(BASE).expect("base").lights[0].shadow.cascades;
    assert_eq!(c, shadowgraph::Cascades::SINGLE);
}
