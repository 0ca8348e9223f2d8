//! Every relative link of README.md and docs/*.md resolves: the file exists and, for a link with
//! `#anchor`, the target has a heading with that GitHub anchor (lowercase, punctuation dropped,
//! spaces as hyphens). Links inside code blocks and inline code are not links. No GPU.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The markdown files the rule covers: README.md and every docs/*.md.
fn documents() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    let docs = root().join("docs");
    let mut more: Vec<PathBuf> = std::fs::read_dir(&docs)
        .unwrap_or_else(|e| panic!("docs/: {e}"))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    more.sort();
    files.extend(more);
    files
}

/// Lines outside fenced code blocks, with inline code removed.
fn prose(text: &str) -> Vec<(usize, String)> {
    let mut fenced = false;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || line.starts_with("    ") {
            continue;
        }
        let mut kept = String::new();
        for (k, part) in line.split('`').enumerate() {
            if k % 2 == 0 {
                kept.push_str(part);
            }
        }
        out.push((i + 1, kept));
    }
    out
}

/// GitHub's anchor of a heading.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '-' || *c == ' ' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a markdown file's headings (inline code kept, as GitHub does).
fn anchors(text: &str) -> HashSet<String> {
    let mut fenced = false;
    let mut set = HashSet::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        if let Some(h) = line.strip_prefix('#') {
            let h = h.trim_start_matches('#');
            if h.starts_with(' ') {
                set.insert(slug(h));
            }
        }
    }
    set
}

/// `(line, target)` of every `](target)` link.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in prose(text) {
        let mut rest = line.as_str();
        while let Some(at) = rest.find("](") {
            rest = &rest[at + 2..];
            let end = rest.find(')').unwrap_or(rest.len());
            out.push((n, rest[..end].to_string()));
            rest = &rest[end..];
        }
    }
    out
}

fn check(doc: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(doc).unwrap();
    let name = doc.strip_prefix(root()).unwrap().display().to_string();
    let mut bad = Vec::new();
    for (line, target) in links(&text) {
        if target.starts_with("http://") || target.starts_with("https://") {
            continue;
        }
        let (path, anchor) = match target.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (target.as_str(), None),
        };
        let file = if path.is_empty() {
            doc.to_path_buf()
        } else {
            doc.parent().unwrap().join(path)
        };
        if !file.exists() {
            bad.push(format!(
                "{name}:{line}: `{target}`: no file {}",
                file.display()
            ));
            continue;
        }
        if let Some(a) = anchor {
            let body = std::fs::read_to_string(&file).unwrap_or_default();
            if !anchors(&body).contains(a) {
                bad.push(format!(
                    "{name}:{line}: `{target}`: no heading with anchor `{a}`"
                ));
            }
        }
    }
    bad
}

#[test]
fn every_relative_link_resolves() {
    let docs = documents();
    assert!(docs.len() >= 2, "README.md and docs/*.md");
    let bad: Vec<String> = docs.iter().flat_map(|d| check(d)).collect();
    assert!(bad.is_empty(), "broken links:\n{}", bad.join("\n"));
}

#[test]
fn the_checker_sees_a_broken_link() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-links-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let doc = dir.join("a.md");
    std::fs::write(
        &doc,
        "# Title `x`\n\n[ok](#title-x) [bad](#nowhere) [gone](missing.md) `[code](#no)`\n",
    )
    .unwrap();
    let text = std::fs::read_to_string(&doc).unwrap();
    let found: Vec<String> = links(&text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(found, ["#title-x", "#nowhere", "missing.md"]);
    assert!(anchors(&text).contains("title-x"));
    std::fs::remove_dir_all(&dir).ok();
}
