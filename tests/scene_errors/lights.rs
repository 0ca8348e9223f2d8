//! Lights: what each kind needs and refuses, and their geometry's ranges.

use super::*;

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
