//! Keys that do not apply to a shape, wrong types and a scene without lights, named.

use super::*;

#[test]
fn keys_that_do_not_apply_to_a_shape_are_errors() {
    let cases = [
        (
            "radius = 0.5\ntranslate = [1.5",
            "radius = 0.5\nsize = nan\ntranslate = [1.5",
            "size",
            "sphere",
        ),
        (
            "radius = 0.5\ntranslate = [1.5",
            "radius = 0.5\nheight = inf\ntranslate = [1.5",
            "height",
            "sphere",
        ),
        (
            "radius = 0.5\ntranslate = [1.5",
            "radius = 0.5\npath = \"x.obj\"\ntranslate = [1.5",
            "path",
            "sphere",
        ),
        (
            "size = [8.0, 8.0]",
            "size = [8.0, 8.0]\nradius = nan",
            "radius",
            "plane",
        ),
        (
            "size = [1.0, 0.5, 1.0]",
            "size = [1.0, 0.5, 1.0]\nheight = 2.0",
            "height",
            "box",
        ),
        (
            "height = 1.2",
            "height = 1.2\nsize = 1.0",
            "size",
            "cylinder",
        ),
    ];
    for (from, to, key, shape) in cases {
        let text = FULL.replacen(from, to, 1);
        let err = parse(&text)
            .err()
            .unwrap_or_else(|| panic!("{key} on a {shape} accepted"));
        let shown = err.to_string();
        let at = text.find(to).unwrap() + to.find(&format!("{key} = ")).unwrap();
        let line = text[..at].matches('\n').count() + 1;
        assert!(
            shown.starts_with(&format!("{INLINE}:{line}:"))
                && shown.contains(&format!(".{key}`"))
                && shown.contains(shape),
            "{key} on a {shape}: {shown}"
        );
    }
}

#[test]
fn a_wrong_type_names_the_key() {
    let cases = [
        (
            "height = 48",
            "height = \"x\"",
            "`output.height`: expected an integer, found a string",
        ),
        (
            "height = 48",
            "height = 5e-324",
            "`output.height`: expected an integer, found a decimal number (5e-324)",
        ),
        (
            "shadow_map = 256",
            "shadow_map = 256.5",
            "`light[0].shadow_map`: expected an integer",
        ),
        (
            "fov_y_degrees = 45.0",
            "fov_y_degrees = \"wide\"",
            "`camera.fov_y_degrees`: expected a number, found a string",
        ),
        (
            "target = [0.0, 0.5, 0.0]",
            "target = [0.0, \"a\", 0.0]",
            "`camera.target[1]`: expected a number",
        ),
        (
            "target = [0.0, 0.5, 0.0]",
            "target = [0.0, 0.5]",
            "`camera.target`: expected an array of 3 numbers, found 2",
        ),
        (
            "width = 64",
            "width = { a = 1 }",
            "`output.width`: expected an integer, found a table",
        ),
        (
            "technique = \"msm\"",
            "technique = 3",
            "`light[2].shadow.technique`: expected a string",
        ),
        (
            "scale = 1.5",
            "scale = true",
            "`object[2].scale`: expected a number or a list of numbers",
        ),
    ];
    for (from, to, want) in cases {
        let text = FULL.replacen(from, to, 1);
        let line = text[..text.find(to).unwrap()].matches('\n').count() + 1;
        let shown = parse(&text).expect_err("wrong type accepted").to_string();
        assert_short_line(&shown);
        assert!(
            shown.starts_with(&format!("{INLINE}:{line}:")) && shown.contains(want),
            "`{to}`: {shown}\n  wanted: {want}"
        );
    }
}

#[test]
fn no_lights_names_the_file() {
    let start = FULL.find("[[light]]").unwrap();
    let end = FULL.find("[[object]]").unwrap();
    let text = format!("{}{}", &FULL[..start], &FULL[end..]);
    let shown = Scene::parse(Path::new("dir/empty.toml"), &text)
        .err()
        .unwrap()
        .to_string();
    assert_eq!(shown, "dir/empty.toml: the scene has no `[[light]]`");
}
