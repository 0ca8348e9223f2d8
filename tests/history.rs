//! The product speaks of the product, not of how it was made: README.md and every file under
//! docs/, src/, kernels/, tests/, scenes/, examples/ and benches/ name no numbered period of
//! work (an ordinal and the word for one), no issue by its number and no issue's filing. A
//! figure is dated by its date and commit; the history of changes is in git and CHANGELOG.md
//! (not checked: it is history). A few meanings of these words are the product's own (a
//! browser's DevTools connection is named by the same word as a period of work); each is
//! allowed by an exact phrase, in one file, with its reason. No GPU.
//!
//! This file is not checked: it names the words it looks for.

use std::path::{Path, PathBuf};

/// The folders and files checked, from the repository's root.
const ROOTS: [&str; 8] = [
    "README.md",
    "docs",
    "src",
    "kernels",
    "tests",
    "scenes",
    "examples",
    "benches",
];

/// A meaning of a flagged word that belongs to the product: within `path` (a file, from the
/// repository's root), `phrase` (lowercase) is not a hit.
struct Allowed {
    path: &'static str,
    phrase: &'static str,
    /// Why the phrase is the product's, not its history's.
    #[expect(dead_code, reason = "documentation of each entry, read by people")]
    reason: &'static str,
}

/// This file, which names the words it looks for.
const THIS_FILE: &str = "tests/history.rs";

const ALLOWED: [Allowed; 3] = [
    Allowed {
        path: "tests/report_html.rs",
        phrase: "session",
        reason: "the Chrome DevTools Protocol's session: the browser test attaches to the page \
                 through one (`sessionId`, a field and a parameter named after it)",
    },
    Allowed {
        path: "benches/RESULTS.md",
        phrase: "blur_filing.wgsl",
        reason: "the file name of an uncommitted build's old blur kernel, recorded as it ran",
    },
    Allowed {
        path: "benches/RESULTS.md",
        phrase: "sg_filing_blur",
        reason: "the environment variable of that uncommitted build, in the command as it ran",
    },
];

/// `ses` + `sion`: a period of work, in the words the rule looks for.
fn period() -> String {
    ["ses", "sion"].concat()
}

/// The ordinals a work period was numbered by: tenth to twentieth and twenty-first on.
fn ordinals() -> Vec<String> {
    let stems = [
        "ten",
        "eleven",
        "twelf",
        "thirteen",
        "fourteen",
        "fifteen",
        "sixteen",
        "seventeen",
        "eighteen",
        "nineteen",
        "twentie",
    ];
    let mut out: Vec<String> = stems.iter().map(|s| format!("{s}th")).collect();
    for unit in [
        "first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth",
    ] {
        out.push(format!("twenty-{unit}"));
    }
    out
}

/// The words of a lowercase line: letters, digits, `-` and `'`, a trailing `'s` cut.
fn words(line: &str) -> Vec<&str> {
    line.split(|c: char| !(c.is_alphanumeric() || c == '-' || c == '\''))
        .map(|w| w.trim_matches(|c| c == '\'' || c == '-'))
        .map(|w| w.strip_suffix("'s").unwrap_or(w))
        .filter(|w| !w.is_empty())
        .collect()
}

/// What in `line` (of the file `path`) speaks of the project's history: a work period, an
/// ordinal, an issue's number, a filing. Allowed phrases are cut first.
fn hits(path: &str, line: &str) -> Vec<String> {
    let mut line = line.to_lowercase();
    for a in ALLOWED.iter().filter(|a| a.path == path) {
        line = line.replace(a.phrase, " ");
    }
    let (period, ordinals) = (period(), ordinals());
    let filing = ["fil", "ing"].concat();
    let issue = ["iss", "ue"].concat();
    let w = words(&line);
    let mut out = Vec::new();
    for (i, word) in w.iter().enumerate() {
        let plural = word.strip_suffix('s').unwrap_or(word);
        if plural == period || *word == filing || ordinals.iter().any(|o| o == word) {
            out.push(word.to_string());
        }
        let numbered = w
            .get(i + 1)
            .is_some_and(|next| next.starts_with(|c: char| c.is_ascii_digit()));
        if plural == issue && numbered {
            out.push(format!("{word} {}", w[i + 1]));
        }
    }
    out
}

/// Every file under `path` (or `path` itself), sorted.
fn files(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        entries.sort();
        for e in entries {
            files(&e, out);
        }
    } else {
        out.push(path.to_path_buf());
    }
}

#[test]
fn the_product_names_no_work_period_issue_or_filing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut all = Vec::new();
    for r in ROOTS {
        files(&root.join(r), &mut all);
    }
    assert!(all.len() > 100, "only {} files found", all.len());
    let mut bad = Vec::new();
    for file in &all {
        // Binary files (images, meshes) hold no prose.
        let Ok(text) = std::fs::read_to_string(file) else {
            continue;
        };
        let name = file
            .strip_prefix(root)
            .unwrap_or(file)
            .display()
            .to_string();
        if name == THIS_FILE {
            continue;
        }
        for (n, line) in text.lines().enumerate() {
            let found = hits(&name, line);
            if !found.is_empty() {
                let shown: String = line.trim().chars().take(120).collect();
                bad.push(format!("{name}:{}: {}: {shown}", n + 1, found.join(", ")));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} lines speak of how the project was made (date a figure by its date and commit; \
         history belongs in git and CHANGELOG.md):\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// The checker sees what it must and nothing else: each kind of word, in any case, and not
/// the allowed phrase, a count ("one in twenty-one"), an issue without a number, a colour.
#[test]
fn the_checker_finds_each_kind() {
    let ordinal = format!("the {}", ordinals()[4]);
    let period = period();
    let filing = ["fil", "ing"].concat();
    let issue = ["Iss", "ue"].concat();
    let cases = [
        (format!("in {ordinal} {period}"), 2),
        (format!("{}S of 2026", period.to_uppercase()), 1),
        (format!("as at its {filing}, {issue} 15's target"), 2),
        (format!("({issue}s 14 and 15)"), 1),
        (format!("the twenty-first {period}'s run"), 2),
        (
            "one case in twenty-one; an issue of precision; fill #222".to_string(),
            0,
        ),
    ];
    for (line, want) in &cases {
        assert_eq!(
            hits("docs/X.md", line).len(),
            *want,
            "{line}: {:?}",
            hits("docs/X.md", line)
        );
    }
    let devtools = format!("one DevTools {period} on a page");
    assert!(hits("tests/report_html.rs", &devtools).is_empty());
    assert_eq!(
        hits("tests/other.rs", &devtools).len(),
        1,
        "allowed in its file only"
    );
}
