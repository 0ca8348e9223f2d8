//! Values out of range: sizes, transforms, the other ranges, a scene without objects.

use super::*;

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

#[test]
fn scene_without_objects() {
    let end = BASE.find("[[object]]").unwrap();
    let err = parse(&BASE[..end]).unwrap_err();
    let shown = err.to_string();
    assert!(shown.starts_with("inline.toml"), "{shown}");
    assert!(shown.contains("[[object]]"), "{shown}");
}
