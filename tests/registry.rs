//! The technique registry's entries: names unique (scene files and `--techniques` look them
//! up), each entry's example scene loads and lights something with its technique, and
//! `docs/PARAMETERS.md` is generated from the tables. No GPU.

use std::path::Path;

use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique::{REGISTRY, names, parameters_markdown};

#[test]
fn names_are_unique_and_examples_use_their_technique() {
    let names = names();
    for (k, name) in names.iter().enumerate() {
        assert!(!names[k + 1..].contains(name), "{name} registered twice");
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for def in REGISTRY {
        let scene = Scene::load(root.join(def.example)).expect(def.example);
        assert!(
            scene
                .lights
                .iter()
                .any(|l| l.shadow.technique.name() == def.name),
            "{} lights no {} light",
            def.example,
            def.name
        );
    }
}

/// `docs/PARAMETERS.md` is the registry's tables as written (ranges, defaults, conditions): a
/// changed range or default changes the documented one in the same commit, or this fails.
#[test]
fn parameters_doc_is_the_registry() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/PARAMETERS.md");
    let generated = parameters_markdown();
    if std::env::var_os("SHADOWGRAPH_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write docs/PARAMETERS.md");
    }
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        on_disk == generated,
        "docs/PARAMETERS.md is stale: regenerate it with \
         `SHADOWGRAPH_BLESS=1 cargo test --release --test registry`"
    );
}

/// The registry is closed: no file of `src/` outside `src/technique/` (the entries) and
/// `src/model/technique.rs` (the enum's definition and its data accessors, each naming every
/// variant) matches on `Technique`, so what a technique does — its reach, cascades, maps,
/// encoding, nodes, shading — is read from its entry and a new technique changes no front end.
///
/// The rule, on the code with comments and string literals blanked: a path `Technique::V` (or
/// `A::V` where the file says `Technique as A`) is a pattern when what follows it — past its
/// `{ … }` or `( … )` — is `=>` (a match arm), `|` (one of alternatives), `if` (a guard) or a
/// single `=` (`let`, `if let`, `while let`, `let … else`), or when it lies in the pattern of a
/// `matches!(value, pattern)`. A glob import of the variants (`Technique::*`) fails too, since
/// bare variants could not be seen. Building a technique (`Technique::Hard`, a struct literal
/// as an argument or value) is not a pattern. No file is allowed otherwise.
#[test]
fn no_match_on_technique_outside_the_registry() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.len() > 50, "found only {} files", files.len());
    let mut found = Vec::new();
    for file in files {
        let rel = file
            .strip_prefix(&src)
            .expect("under src")
            .to_string_lossy();
        let rel = rel.replace('\\', "/");
        if rel.starts_with("technique/") || rel == "model/technique.rs" {
            continue;
        }
        let code = code_only(&std::fs::read_to_string(&file).expect("readable source"));
        for (line, what) in technique_patterns(&code) {
            found.push(format!("src/{rel}:{line}: {what}"));
        }
    }
    assert!(
        found.is_empty(),
        "matches on Technique outside src/technique/ (read the entry instead: \
         technique::of, reach, encoding, value, …):\n  {}",
        found.join("\n  ")
    );
}

/// The rule's own check on code written for it: each pattern form is found, and building a
/// technique is not.
#[test]
fn the_match_rule_finds_each_pattern_form() {
    let code = "use crate::model::Technique as T;\n\
        match t { Technique::Hard => 1, T::Pcf { radius, .. } | Technique::Pcss { .. } => 2 }\n\
        if let Technique::Vsm { bleed, .. } = t {}\n\
        let Technique::Msm { prefilter, .. } = t else { return };\n\
        assert!(matches!(t, Technique::Esm { .. }));\n\
        match t { Technique::Csm { terms, .. } if terms > 2 => 1 }\n\
        let a = Technique::Hard; f(Technique::Pcf { radius: 1, kernel }, 2);\n\
        let b = matches!(Technique::Hard, _); t == Technique::Hard;";
    let lines: Vec<usize> = technique_patterns(code).iter().map(|&(l, _)| l).collect();
    assert_eq!(
        lines,
        [2, 2, 2, 3, 4, 5, 6],
        "{:?}",
        technique_patterns(code)
    );
    assert_eq!(
        technique_patterns("use crate::model::Technique::*;").len(),
        1
    );
}

/// `(line, text)` of every pattern on `Technique`'s variants in `code` (see the rule above).
fn technique_patterns(code: &str) -> Vec<(usize, String)> {
    let mut names = vec!["Technique".to_string()];
    let mut rest = code;
    while let Some(at) = rest.find("Technique as ") {
        rest = &rest[at + "Technique as ".len()..];
        names.push(
            rest.chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect(),
        );
    }
    let in_matches = matches_patterns(code);
    let line = |at: usize| code[..at].matches('\n').count() + 1;
    let mut out = Vec::new();
    for name in &names {
        let path = format!("{name}::");
        for (at, _) in code.match_indices(&path) {
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let after = &code[at + path.len()..];
            if after.starts_with('*') {
                out.push((line(at), format!("{path}* imports the variants")));
                continue;
            }
            let variant: String = after
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let tail = skip_group(after[variant.len()..].trim_start()).trim_start();
            let arm = tail.starts_with("=>") || tail.starts_with('|') || tail.starts_with("if ");
            let binds = tail.starts_with('=') && !tail.starts_with("==");
            if arm || binds || in_matches.iter().any(|r| r.contains(&at)) {
                out.push((line(at), format!("{path}{variant} in a pattern")));
            }
        }
    }
    out.sort();
    out
}

/// `s` past a leading balanced `{ … }` or `( … )`, if it starts with one.
fn skip_group(s: &str) -> &str {
    let Some(open) = s.chars().next().filter(|c| *c == '{' || *c == '(') else {
        return s;
    };
    let close = if open == '{' { '}' } else { ')' };
    let mut depth = 0;
    for (i, c) in s.char_indices() {
        if c == open {
            depth += 1;
        } else if c == close {
            depth -= 1;
            if depth == 0 {
                return &s[i + 1..];
            }
        }
    }
    ""
}

/// The byte ranges of the pattern arguments of every `matches!(value, pattern)` in `code`.
fn matches_patterns(code: &str) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    for (at, m) in code.match_indices("matches!(") {
        let start = at + m.len();
        let mut depth = 1;
        let mut comma = None;
        for (i, c) in code[start..].char_indices() {
            match c {
                '(' | '{' | '[' => depth += 1,
                ')' | '}' | ']' => depth -= 1,
                ',' if depth == 1 && comma.is_none() => comma = Some(start + i),
                _ => {}
            }
            if depth == 0 {
                if let Some(comma) = comma {
                    out.push(comma..start + i);
                }
                break;
            }
        }
    }
    out
}

/// The code of a Rust file with comments, string and char literals replaced by spaces (line
/// breaks kept, so that line numbers hold).
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let blank = |s: &str| {
        s.chars()
            .map(|c| if c == '\n' { '\n' } else { ' ' })
            .collect::<String>()
    };
    while i < b.len() {
        let end = if b[i..].starts_with(b"//") {
            text[i..].find('\n').map_or(b.len(), |e| i + e)
        } else if b[i..].starts_with(b"/*") {
            text[i + 2..].find("*/").map_or(b.len(), |e| i + 2 + e + 2)
        } else if b[i] == b'"' || (b[i] == b'r' && b[i..].starts_with(b"r\"")) {
            let mut j = i + if b[i] == b'r' { 2 } else { 1 };
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            (j + 1).min(b.len())
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            i + 3
        } else if b[i..].starts_with(b"'\\") {
            text[i + 2..].find('\'').map_or(b.len(), |e| i + 2 + e + 1)
        } else {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
            continue;
        };
        out.push_str(&blank(&text[i..end]));
        i = end;
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
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

/// `PrefilterConfig::named` builds every registered technique at a scene's defaults (its
/// entry's `default_of`, and the named constructors' techniques), and an unknown name is a
/// config error naming the key and listing the registered names.
#[test]
fn configs_are_built_by_name() {
    use shadowgraph::PrefilterConfig;
    use shadowgraph::low_level::technique::default_of;
    for def in REGISTRY {
        let config = PrefilterConfig::named(def.name, 256).expect(def.name);
        assert_eq!(config.technique, default_of(def), "{}", def.name);
        assert_eq!(config.size, 256);
    }
    let same = |a: PrefilterConfig, name: &str| {
        let b = PrefilterConfig::named(name, 128).expect(name);
        assert_eq!(a.technique, b.technique, "{name}");
    };
    same(PrefilterConfig::vsm(128), "vsm");
    same(PrefilterConfig::evsm4(128), "evsm4");
    same(PrefilterConfig::msm_soft(128, 0.5), "msm_soft");
    let err = PrefilterConfig::named("vsn", 128)
        .expect_err("unknown name")
        .to_string();
    assert!(
        err.contains("technique") && err.contains("\"vsn\"") && err.contains("msm_soft"),
        "{err}"
    );
}
