//! Scene files: every bad input is refused with an error that names the file, the key and the
//! line; every bundled scene loads, and its lights cast shadows the camera can see. No GPU needed.

use glam::{Vec3, Vec4Swizzles};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{Error, LightKind, PcfKernel, Technique};
use std::path::{Path, PathBuf};

mod bundled;
mod lights;
mod syntax;
mod technique_keys;
mod values;

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

fn location(err: &Error) -> &str {
    match err {
        Error::Scene { location, .. } => location,
        other => panic!("expected Error::Scene, got {other:?}"),
    }
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}
