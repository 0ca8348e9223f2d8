//! The library's layers (docs/ARCHITECTURE.md, "Layers"): every file of `src/` belongs to one
//! layer, and a `crate::` path in its code may name only a module of its own layer or one
//! below. This is the proof that the modules form no import cycle across layers: a cycle needs
//! an edge that climbs. Plain text, no GPU: comments and string literals are skipped, every
//! other `crate::<module>` (in `use` lists too) is checked.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Layers from the bottom; a path prefix under `src/` (file or folder, without `.rs`) maps to
/// the layer of the longest prefix that matches.
const LAYERS: &[(&str, u32)] = &[
    // 0: the error type.
    ("error", 0),
    // 1: plain data and plain math.
    ("model", 1),
    ("msm_quantize", 1),
    // 2: the GPU mirrors of WGSL structs.
    ("wgsl_mirrors", 2),
    // 3: kernels, the graph, the device, the executor and the kernel-level building blocks;
    // the CPU references beside them (they read `model` and `wgsl_mirrors`, never `technique`).
    ("kernels", 3),
    ("graph", 3),
    ("gpu", 3),
    ("timer", 3),
    ("gpu_objects", 3),
    ("exec", 3),
    ("filter", 3),
    ("sat", 3),
    ("limits", 3),
    ("limits/budget", 3),
    ("cpu", 3),
    ("tolerance", 3),
    // 4: the technique registry.
    ("technique", 4),
    // 5: the front ends.
    ("limits/scene", 5),
    ("scene", 5),
    ("prefilter", 5),
    ("render", 5),
    ("truth", 5),
    ("evaluate", 5),
    ("bench", 5),
    ("dump", 5),
    ("stability", 5),
    ("io", 5),
    ("cli", 5),
    ("main", 5),
    ("lib", 5),
    ("low_level", 5),
];

/// Edges that climb today, each in a file another branch owns, with the change that removes
/// it. An entry that no longer matches an edge fails the test, so the list only shrinks.
const PENDING: &[(&str, &str, &str)] = &[];

fn layer_of(rel: &str) -> u32 {
    let stem = rel.trim_end_matches(".rs");
    LAYERS
        .iter()
        .filter(|(prefix, _)| {
            stem == *prefix
                || stem
                    .strip_prefix(prefix)
                    .is_some_and(|rest| rest.starts_with('/'))
        })
        .max_by_key(|(prefix, _)| prefix.len())
        .map(|&(_, layer)| layer)
        .unwrap_or_else(|| panic!("src/{rel} belongs to no layer: add it to LAYERS"))
}

/// The top-level module a `crate::` path names, by the layer of the file it lives in: the
/// first segment, or the first two for a module split across layers (`limits::scene`).
fn target_layer(path: &[String]) -> Option<u32> {
    let first = path.first()?;
    let two = path.get(1).map(|second| format!("{first}/{second}"));
    if let Some(two) = two.filter(|t| LAYERS.iter().any(|(p, _)| p == t)) {
        return Some(layer_of(&two));
    }
    LAYERS
        .iter()
        .any(|(p, _)| p == first)
        .then(|| layer_of(first))
}

/// The code of a Rust file without comments, string and char literals (replaced by spaces).
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let end = text[i + 2..].find("*/").map_or(b.len(), |e| i + 2 + e + 2);
            i = end;
            out.push(' ');
        } else if b[i] == b'"' || (b[i] == b'r' && b.get(i + 1) == Some(&b'"')) {
            i += if b[i] == b'r' { 2 } else { 1 };
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push(' ');
        } else {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// Every module path under `crate::` in `code`: `crate::a::b` gives `[a, b]`, and a group
/// `crate::{a::x, b}` gives `[a, x]` and `[b]`.
fn crate_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find("crate::") {
        let before = rest[..at].chars().next_back();
        rest = &rest[at + "crate::".len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let end = matching_brace(group);
            for item in split_top(&group[..end]) {
                out.push(segments(item.trim()));
            }
        } else {
            out.push(segments(rest));
        }
    }
    out
}

fn matching_brace(s: &str) -> usize {
    let mut depth = 1;
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return i;
                }
            }
            _ => {}
        }
    }
    s.len()
}

fn split_top(s: &str) -> Vec<&str> {
    let (mut depth, mut start, mut out) = (0, 0, Vec::new());
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&s[start..]);
    out
}

fn segments(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = s;
    loop {
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if end == 0 {
            break;
        }
        out.push(rest[..end].to_string());
        match rest[end..].strip_prefix("::") {
            Some(r) => rest = r,
            None => break,
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for entry in entries {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every edge from a file to a module of a higher layer, as `(file stem, module)`.
fn climbing_edges() -> BTreeSet<(String, String, u32, u32)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 50,
        "found only {} files under src/",
        files.len()
    );
    let mut edges = BTreeSet::new();
    for file in files {
        let rel = file
            .strip_prefix(&src)
            .expect("under src")
            .to_string_lossy();
        let rel = rel.replace('\\', "/");
        let from = layer_of(&rel);
        let text = std::fs::read_to_string(&file).expect("readable source");
        for path in crate_paths(&code_only(&text)) {
            let Some(to) = target_layer(&path) else {
                continue;
            };
            if to > from {
                let stem = rel.trim_end_matches(".rs").to_string();
                edges.insert((stem, path[0].clone(), from, to));
            }
        }
    }
    edges
}

#[test]
fn no_module_imports_from_a_higher_layer() {
    let edges = climbing_edges();
    let pending = |stem: &str, to: &str| PENDING.iter().any(|(f, t, _)| *f == stem && *t == to);
    let climbing: Vec<String> = edges
        .iter()
        .filter(|(stem, to, _, _)| !pending(stem, to))
        .map(|(stem, to, a, b)| format!("src/{stem}.rs (layer {a}) uses crate::{to} (layer {b})"))
        .collect();
    assert!(
        climbing.is_empty(),
        "imports from a higher layer:\n  {}",
        climbing.join("\n  ")
    );
    let stale: Vec<String> = PENDING
        .iter()
        .filter(|(f, t, _)| !edges.iter().any(|(s, to, _, _)| s == f && to == t))
        .map(|(f, t, why)| format!("src/{f}.rs → {t} ({why})"))
        .collect();
    assert!(
        stale.is_empty(),
        "PENDING lists edges that are gone; remove them:\n  {}",
        stale.join("\n  ")
    );
}

#[test]
fn the_path_reader_sees_groups_and_skips_comments() {
    let code = code_only(
        "use crate::{model::Light, technique::{self, x}};\n// crate::render\nlet s = \"crate::dump\";\nfoo::crate::bar; crate::wgsl_mirrors::LightGpu",
    );
    let paths: Vec<String> = crate_paths(&code).iter().map(|p| p.join("::")).collect();
    assert_eq!(
        paths,
        ["model::Light", "technique", "wgsl_mirrors::LightGpu"]
    );
    assert_eq!(layer_of("limits/scene.rs"), 5);
    assert_eq!(layer_of("limits.rs"), 3);
    assert_eq!(layer_of("scene/validate.rs"), 5);
    assert_eq!(
        target_layer(&["limits".into(), "scene".into(), "x".into()]),
        Some(5)
    );
}
