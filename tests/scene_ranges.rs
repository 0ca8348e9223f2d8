//! Every number of a scene file is checked in the type it is used in (f32) against a range that
//! keeps the math finite; keys that do not apply to a shape are errors; wrong types name the
//! key; numbers in messages print short; the file size is capped. No GPU needed.

use std::path::Path;
use std::time::Duration;

use shadowgraph::Error;
use shadowgraph::low_level::scene::Scene;

/// A scene with most keys a scene can have, each number on a line of its own, so that the
/// sweep below can change one at a time and know which key and line it changed.
const FULL: &str = r#"ambient = [0.1, 0.1, 0.12]

[output]
width = 64
height = 48
background = [0.5, 0.6, 0.7]

[camera]
position = [0.5, 3.0, 6.0]
target = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov_y_degrees = 45.0

[[light]]
kind = "directional"
position = [-3.0, 6.0, 2.0]
target = [0.0, 0.0, 0.0]
extent = 4.0
near = 1.0
far = 20.0
size = 0.3
color = [1.0, 0.9, 0.8]
intensity = 1.5
shadow_map = 256

[light.shadow]
technique = "pcss"
bias = 0.003
slope_bias = 1.5
normal_bias = 1.0
blocker_samples = 16
filter_samples = 32
max_search = 0.1

[[light]]
kind = "spot"
position = [2.0, 5.0, 3.0]
target = [0.0, 0.0, 0.0]
fov_degrees = 50.0
near = 0.5
far = 30.0
shadow_map = 128

[light.shadow]
technique = "vsm"
filter_radius = 2.5
filter_sigma = 1.2
bleed_reduction = 0.2
min_variance = 1e-5

[[light]]
kind = "directional"
position = [3.0, 7.0, -2.0]
target = [0.0, 0.0, 0.0]
extent = 5.0
shadow_map = 128

[light.shadow]
technique = "msm"
filter = "sat"
filter_width = 5.0
moment_bias = 1e-4

[[light]]
kind = "directional"
position = [-1.0, 7.0, -4.0]
target = [0.0, 0.0, 0.0]
extent = 5.0
shadow_map = 128

[light.shadow]
technique = "csm"
filter = "mips"
filter_width = 2.0
max_anisotropy = 4
terms = 6
attenuation = 1.0
offset = 0.05
scale = 2.0

[[light]]
kind = "spot"
position = [0.0, 6.0, 1.0]
target = [0.0, 0.0, 0.0]
fov_degrees = 60.0
size = 0.5
shadow_map = 128

[light.shadow]
technique = "cssm"
terms = 4
sharpen = 4.0
sharpen_falloff = 10.0

[[light]]
kind = "directional"
position = [1.0, 8.0, 1.0]
target = [0.0, 0.0, 0.0]
extent = 5.0
shadow_map = 128

[light.shadow]
technique = "evsm4"
exponent_pos = 30.0
exponent_neg = 4.0

[[light]]
kind = "point"
position = [0.5, 2.5, -0.5]
near = 0.2
far = 15.0
size = 0.2
shadow_map = 128

[light.shadow]
technique = "vsm"
filter_radius = 2.0

[[object]]
shape = "plane"
size = [8.0, 8.0]
color = [0.8, 0.8, 0.8]

[[object]]
shape = "box"
size = [1.0, 0.5, 1.0]
translate = [0.0, 0.5, 0.0]
rotate_degrees = [0.0, 30.0, 0.0]
scale = [1.0, 2.0, 1.0]

[[object]]
shape = "sphere"
radius = 0.5
translate = [1.5, 0.5, 0.0]
scale = 1.5

[[object]]
shape = "cylinder"
radius = 0.3
height = 1.2
translate = [-1.5, 0.6, 0.0]
rotate_degrees = [10.0, 0.0, 20.0]
"#;

const INLINE: &str = "ranges.toml";

fn parse(text: &str) -> shadowgraph::Result<Scene> {
    Scene::parse(Path::new(INLINE), text)
}

/// Each numeric key of `text`: (line index, dotted key path, the value's text).
fn numeric_keys(text: &str) -> Vec<(usize, String, String)> {
    let mut table = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if let Some(name) = line.strip_prefix("[[").and_then(|l| l.strip_suffix("]]")) {
            let i = counts.entry(name.to_string()).or_insert(0);
            table = format!("{name}[{i}]");
            *i += 1;
        } else if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            table = match name.split_once('.') {
                Some((parent, child)) => {
                    format!("{parent}[{}].{child}", counts[parent] - 1)
                }
                None => name.to_string(),
            };
        } else if let Some((key, value)) = line.split_once(" = ") {
            let v = value.trim_start_matches('[');
            if v.starts_with(|c: char| c.is_ascii_digit() || c == '-') {
                let path = if table.is_empty() {
                    key.to_string()
                } else {
                    format!("{table}.{key}")
                };
                out.push((n, path, value.to_string()));
            }
        }
    }
    out
}

/// Whether a `Debug` rendering holds a non-finite float.
fn has_non_finite(debug: &str) -> bool {
    debug
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '.'))
        .any(|t| matches!(t, "inf" | "-inf" | "NaN"))
}

/// Everything the renderer will turn into f32 math is finite, normals are unit length, and no
/// object collapsed to a point or a line.
#[track_caller]
fn assert_finite_scene(s: &Scene, what: &str) {
    let c = &s.camera;
    assert!(
        !has_non_finite(&format!("{c:?} {:?} {:?}", s.ambient, s.background)),
        "{what}: camera or colours not finite: {c:?}"
    );
    for (i, l) in s.lights.iter().enumerate() {
        assert!(
            !has_non_finite(&format!("{l:?}")),
            "{what}: light[{i}] {l:?}"
        );
        assert!(
            l.projection().is_finite() && l.view().is_finite(),
            "{what}: light[{i}]'s matrices"
        );
    }
    for (i, o) in s.objects.iter().enumerate() {
        let m = &o.mesh;
        assert!(o.color.is_finite(), "{what}: object[{i}].color");
        assert!(
            m.positions.iter().all(|p| p.is_finite()),
            "{what}: object[{i}] positions"
        );
        for n in &m.normals {
            assert!(
                n.is_finite() && (n.length() - 1.0).abs() < 1e-3,
                "{what}: object[{i}] has normal {n}"
            );
        }
        let lo = m
            .positions
            .iter()
            .fold(glam::Vec3::INFINITY, |a, &p| a.min(p));
        let hi = m
            .positions
            .iter()
            .fold(glam::Vec3::NEG_INFINITY, |a, &p| a.max(p));
        let extent = hi - lo;
        let axes = (0..3).filter(|&k| extent[k] > 0.0).count();
        assert!(axes >= 2, "{what}: object[{i}] collapsed to {extent}");
    }
    assert!(
        s.camera
            .view_proj(s.width as f32 / s.height as f32)
            .is_finite(),
        "{what}: camera matrix"
    );
    // What the shading computes in f32: squared distances from every vertex to the eye and to
    // every light, and every vertex in every light's clip space.
    for o in &s.objects {
        for &v in &o.mesh.positions {
            assert!(
                (v - c.position).length_squared().is_finite(),
                "{what}: eye distance"
            );
            for l in &s.lights {
                let clip = l.projection() * l.view() * v.extend(1.0);
                assert!(
                    (v - l.position).length_squared().is_finite() && clip.is_finite(),
                    "{what}: a vertex seen from the light at {}",
                    l.position
                );
            }
        }
    }
}

/// An error message: one line, numbers printed short (no run of more than 20 digits).
#[track_caller]
fn assert_short_line(shown: &str) {
    assert!(!shown.contains('\n'), "more than one line: {shown}");
    let mut run = 0;
    for ch in shown.chars() {
        run = if ch.is_ascii_digit() { run + 1 } else { 0 };
        assert!(run <= 20, "a number printed in full: {shown}");
    }
}

#[test]
fn full_scene_is_valid_and_finite() {
    let s = parse(FULL).expect("FULL parses");
    assert_eq!((s.lights.len(), s.objects.len()), (7, 4));
    assert_finite_scene(&s, "FULL");
    assert!(numeric_keys(FULL).len() > 60);
}

/// Each numeric key set to each extreme (and each component of a list): refused with an error
/// naming the file, the key and its line, or accepted with every f32 finite and no object
/// collapsed. Today's code casts checked f64 values to f32, so 1e39 becomes infinity and 1e-50
/// becomes 0.
#[test]
fn every_number_is_checked_as_f32() {
    let extremes = [
        "1e39", "-1e39", "1e300", "1e20", "-3e38", "1e-50", "-1e-50", "5e-324", "3.5e38", "nan",
        "inf", "-inf", "0", "-1",
    ];
    let lines: Vec<&str> = FULL.lines().collect();
    let mut refused = 0;
    let mut cases = 0;
    for (n, key, value) in numeric_keys(FULL) {
        let components = if value.starts_with('[') {
            value.matches(',').count() + 1
        } else {
            1
        };
        for x in extremes {
            for k in 0..components {
                let new_value = if value.starts_with('[') {
                    let mut parts: Vec<String> = value
                        .trim_matches(['[', ']'])
                        .split(',')
                        .map(|p| p.trim().to_string())
                        .collect();
                    parts[k] = x.to_string();
                    format!("[{}]", parts.join(", "))
                } else {
                    x.to_string()
                };
                let mut edited = lines.clone();
                let line = lines[n].replacen(&value, &new_value, 1);
                edited[n] = &line;
                let text = edited.join("\n");
                let what = format!("`{key}` = {new_value}");
                cases += 1;
                match parse(&text) {
                    Ok(s) => assert_finite_scene(&s, &what),
                    Err(e) => {
                        refused += 1;
                        let shown = e.to_string();
                        assert_short_line(&shown);
                        let Error::Scene { location, .. } = &e else {
                            panic!("{what}: expected a scene error, got {e:?}");
                        };
                        let line_no: Option<usize> =
                            location.split(':').nth(1).and_then(|l| l.parse().ok());
                        // `far` ≤ `near` may point at either; everything else at its own line.
                        let sibling = key.ends_with(".near") || key.ends_with(".far");
                        assert!(
                            line_no == Some(n + 1) || (sibling && line_no.is_some()),
                            "{what}: error at {location:?}, expected line {}: {shown}",
                            n + 1
                        );
                        let leaf = key.rsplit('.').next().unwrap_or(&key);
                        assert!(
                            shown.contains(&key) || (sibling && shown.contains(leaf)),
                            "{what}: the error does not name the key: {shown}"
                        );
                    }
                }
            }
        }
    }
    assert!(
        cases > 1000 && refused > cases / 2,
        "{refused} of {cases} refused"
    );
}

#[test]
fn the_issues_examples_are_refused_with_key_and_line() {
    let cases = [
        (
            "position = [0.5, 3.0, 6.0]",
            "position = [0, 3, 1e39]",
            "camera.position",
            "1e39",
        ),
        (
            "position = [-3.0, 6.0, 2.0]",
            "position = [-2, 1e30, -1.5]",
            "light[0].position",
            "1e30",
        ),
        (
            "color = [1.0, 0.9, 0.8]",
            "color = [1e38, 1e38, 1e38]",
            "light[0].color",
            "1e38",
        ),
        (
            "translate = [0.0, 0.5, 0.0]",
            "translate = [0, 1e39, 0]",
            "object[1].translate",
            "1e39",
        ),
        ("scale = 1.5", "scale = 1e39", "object[2].scale", "1e39"),
        ("scale = 1.5", "scale = 1e-50", "object[2].scale", "1e-50"),
        (
            "scale = [1.0, 2.0, 1.0]",
            "scale = [1, 1e-30, 1]",
            "object[1].scale",
            "1e-30",
        ),
        (
            "rotate_degrees = [0.0, 30.0, 0.0]",
            "rotate_degrees = [1e39, 0, 0]",
            "object[1].rotate_degrees",
            "1e39",
        ),
        (
            "background = [0.5, 0.6, 0.7]",
            "background = [1e39, 0, 0]",
            "output.background",
            "1e39",
        ),
        (
            "extent = 4.0",
            "extent = 5e-324",
            "light[0].extent",
            "5e-324",
        ),
    ];
    for (from, to, key, number) in cases {
        assert_eq!(FULL.matches(from).count(), 1, "{from}");
        let text = FULL.replacen(from, to, 1);
        let line = text[..text.find(to).unwrap()].matches('\n').count() + 1;
        let err = parse(&text)
            .err()
            .unwrap_or_else(|| panic!("`{to}` was accepted"));
        let shown = err.to_string();
        assert_short_line(&shown);
        assert!(
            shown.starts_with(&format!("{INLINE}:{line}:"))
                && shown.contains(key)
                && shown.contains(number),
            "`{to}`: {shown}"
        );
    }
}

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
fn numbers_in_messages_print_short() {
    for (from, to, want) in [
        ("extent = 4.0", "extent = 5e-324", "5e-324"),
        ("intensity = 1.5", "intensity = 1e300", "1e300"),
        ("near = 1.0", "near = 1e-300", "1e-300"),
        ("bias = 0.003", "bias = -1e200", "-1e200"),
        // Integers past i64 (found by the fuzzer, which saw them printed in full).
        ("terms = 6", "terms = 10000000000000000000000", "1e22"),
        ("shape = \"box\"", "shape = -100000000000000000000", "-1e20"),
        // A mesh path with a line break stays one line.
        (
            "shape = \"cylinder\"\nradius = 0.3\nheight = 1.2",
            "shape = \"mesh\"\npath = \"x\\ny.obj\"",
            "x\\ny.obj` not found",
        ),
    ] {
        let shown = parse(&FULL.replacen(from, to, 1))
            .expect_err(to)
            .to_string();
        assert_short_line(&shown);
        assert!(shown.contains(want), "{shown}");
    }
}

#[test]
fn a_scene_file_is_read_up_to_a_cap() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-ranges-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Valid TOML, just long: two MiB of comments before the scene.
    let big = dir.join("big.toml");
    let comment = "# padding padding padding padding padding padding padding padding\n";
    std::fs::write(&big, comment.repeat((2 << 20) / comment.len()) + FULL).unwrap();
    let shown = Scene::load(&big)
        .expect_err("2 MiB scene accepted")
        .to_string();
    assert!(
        shown.contains("big.toml") && shown.contains("KiB"),
        "{shown}"
    );
    // A directory is named as one.
    let shown = Scene::load(&dir)
        .expect_err("a directory loaded")
        .to_string();
    assert!(shown.contains("directory"), "{shown}");
    // A UTF-8 byte-order mark is not part of the TOML.
    let bom = dir.join("bom.toml");
    std::fs::write(&bom, format!("\u{feff}{FULL}")).unwrap();
    Scene::load(&bom).unwrap_or_else(|e| panic!("scene with a BOM: {e}"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `plan /dev/zero` read forever: now the read stops at the cap.
#[cfg(unix)]
#[test]
fn an_endless_file_is_refused() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(
            Scene::load("/dev/zero")
                .map(|_| ())
                .map_err(|e| e.to_string()),
        );
    });
    match rx.recv_timeout(Duration::from_secs(20)) {
        Ok(Err(shown)) => assert!(shown.contains("/dev/zero"), "{shown}"),
        Ok(Ok(())) => panic!("/dev/zero parsed as a scene"),
        Err(_) => panic!("reading /dev/zero did not stop within 20 s"),
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
