//! Every number of a scene file is checked in the type it is used in (f32) against a range that
//! keeps the math finite; keys that do not apply to a shape are errors; wrong types name the
//! key; numbers in messages print short; the file size is capped. No GPU needed.

use std::path::Path;
use std::time::Duration;

use shadowgraph::Error;
use shadowgraph::low_level::scene::Scene;

mod files;
mod keys;
mod numbers;

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
