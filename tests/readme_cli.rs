//! The README's command-line table and the binary agree: every option `shadowgraph <command>
//! --help` lists is named in that command's rows of the table, and every `--option` a row names
//! is one the command takes. A flag added without its README line, or a README flag renamed or
//! removed in the code, fails here.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

/// The `--options` named in `text`: `--` then a lowercase letter, letters, digits and `-`.
fn flags(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (at, _) in text.match_indices("--") {
        let rest = &text[at + 2..];
        if !rest.starts_with(|c: char| c.is_ascii_lowercase()) {
            continue;
        }
        let end = rest
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(rest.len());
        out.insert(format!("--{}", rest[..end].trim_end_matches('-')));
    }
    out
}

/// The options `shadowgraph <command> --help` lists (its option lines), less `--help`, each
/// with its short form if it has one (`-o, --output`: `("--output", Some("-o"))`).
fn help_flags(command: &str) -> Vec<(String, Option<String>)> {
    let o = Command::new(env!("CARGO_BIN_EXE_shadowgraph"))
        .args([command, "--help"])
        .output()
        .expect("run shadowgraph");
    assert!(o.status.success(), "{command} --help");
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    help.lines()
        .filter(|l| l.trim_start().starts_with('-'))
        .filter_map(|l| {
            // The flag and its value names, before the description.
            let l = l.trim_start();
            let end = l.find("  ").unwrap_or(l.len());
            let long = flags(&l[..end]).into_iter().next()?;
            let short = l
                .strip_prefix('-')
                .filter(|s| s.chars().nth(1) == Some(','))
                .map(|s| format!("-{}", &s[..1]));
            (long != "--help").then_some((long, short))
        })
        .collect()
}

/// Whether a README row names the short option `-x` (as `[-x `, `` `-x`` or ` -x `).
fn names_short(row: &str, short: &str) -> bool {
    [' ', '[', '`']
        .iter()
        .any(|before| row.contains(&format!("{before}{short} ")))
}

/// Per command, the `--options` its README rows name (`| \`shadowgraph <command> …` rows) and
/// the rows' text.
fn readme_rows(readme: &str) -> Vec<(String, BTreeSet<String>, String)> {
    let mut rows: Vec<(String, BTreeSet<String>, String)> = Vec::new();
    for line in readme.lines() {
        let Some(row) = line.strip_prefix("| `shadowgraph ") else {
            continue;
        };
        let command = row.split([' ', '`']).next().unwrap_or("").to_string();
        let named = flags(row);
        match rows.iter_mut().find(|(c, _, _)| *c == command) {
            Some((_, set, text)) => {
                set.extend(named);
                text.push_str(row);
            }
            None => rows.push((command, named, row.to_string())),
        }
    }
    rows
}

#[test]
fn readme_cli_table_names_every_option_and_no_other() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let rows = readme_rows(&readme);
    let commands: Vec<&str> = rows.iter().map(|(c, _, _)| c.as_str()).collect();
    for expected in [
        "render",
        "plan",
        "dump",
        "info",
        "evaluate",
        "bench",
        "stability",
    ] {
        assert!(
            commands.contains(&expected),
            "no README row for `{expected}`: {commands:?}"
        );
    }
    let mut wrong = Vec::new();
    for (command, named, text) in &rows {
        let takes = help_flags(command);
        for (long, short) in &takes {
            let shown =
                named.contains(long) || short.as_ref().is_some_and(|s| names_short(text, s));
            if !shown {
                wrong.push(format!(
                    "`shadowgraph {command}` takes {long}: not in its README row"
                ));
            }
        }
        let takes: BTreeSet<String> = takes.into_iter().map(|(long, _)| long).collect();
        for f in named.difference(&takes) {
            wrong.push(format!(
                "the README's `shadowgraph {command}` row names {f}: not an option of it"
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The parser finds what it must: options in prose and in `[--a x|--b-c]`, not `---` or `--`.
#[test]
fn flags_are_read_from_prose_and_usage() {
    let got = flags("`[--sizes 1,2] [--kernel-dirs shipped,DIR,…]` then --only: x -- y --- z");
    let want: BTreeSet<String> = ["--sizes", "--kernel-dirs", "--only"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(got, want);
}
