//! Malformed TOML, unknown keys and names, missing files: each one line naming file, key and line.

use super::*;

/// Column (1-based) of the one occurrence of `needle` within its line.
fn col_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap();
    at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1
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
