//! The command line's documentation and the binary agree. `docs/CLI.md` has a section for
//! every command `shadowgraph --help` lists; every option `shadowgraph <command> --help` lists
//! is named in that command's section, and every `--option` a section names is one the command
//! takes. The README's one line per command names every command, and only options the command
//! takes. A flag added without its CLI.md line, or a documented flag renamed or removed in the
//! code, fails here.

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

/// `shadowgraph <args>`'s standard output.
fn help(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_shadowgraph"))
        .args(args)
        .output()
        .expect("run shadowgraph");
    assert!(o.status.success(), "{args:?}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The commands `shadowgraph --help` lists, less `help`.
fn commands() -> Vec<String> {
    let text = help(&["--help"]);
    let listed = text
        .split("Commands:")
        .nth(1)
        .expect("a Commands: list")
        .split("Options:")
        .next()
        .unwrap_or("");
    listed
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

/// The options `shadowgraph <command> --help` lists (its option lines), less `--help`, each
/// with its short form if it has one (`-o, --output`: `("--output", Some("-o"))`).
fn help_flags(command: &str) -> Vec<(String, Option<String>)> {
    help(&[command, "--help"])
        .lines()
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

/// Whether a text names the short option `-x` (as `[-x `, `` `-x`` or ` -x `).
fn names_short(text: &str, short: &str) -> bool {
    [' ', '[', '`']
        .iter()
        .any(|before| text.contains(&format!("{before}{short} ")))
}

/// Per command, the `--options` its CLI.md section names and the section's text: a section is
/// a ``## `shadowgraph <command>` `` heading and everything up to the next `## ` heading (its
/// `###` subsections included).
fn cli_sections(doc: &str) -> Vec<(String, BTreeSet<String>, String)> {
    let mut sections: Vec<(String, BTreeSet<String>, String)> = Vec::new();
    let mut current: Option<usize> = None;
    for line in doc.lines() {
        if line.starts_with("## ") {
            current = line.strip_prefix("## `shadowgraph ").map(|rest| {
                let command = rest.split([' ', '`']).next().unwrap_or("").to_string();
                sections.push((command, BTreeSet::new(), String::new()));
                sections.len() - 1
            });
            continue;
        }
        if let Some(i) = current {
            sections[i].1.extend(flags(line));
            sections[i].2.push_str(line);
            sections[i].2.push('\n');
        }
    }
    sections
}

/// Per README line of the command-line list (``- `shadowgraph <command> …` ``), the command
/// and the `--options` the line names.
fn readme_lines(readme: &str) -> Vec<(String, BTreeSet<String>)> {
    readme
        .lines()
        .filter_map(|l| l.strip_prefix("- `shadowgraph "))
        .map(|rest| {
            let command = rest.split([' ', '`']).next().unwrap_or("").to_string();
            (command, flags(rest))
        })
        .collect()
}

fn read(name: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(root.join(name)).expect(name)
}

#[test]
fn cli_doc_names_every_option_and_no_other() {
    let doc = read("docs/CLI.md");
    let sections = cli_sections(&doc);
    let documented: Vec<&str> = sections.iter().map(|(c, _, _)| c.as_str()).collect();
    let commands = commands();
    assert!(commands.len() >= 7, "shadowgraph --help lists {commands:?}");
    for expected in &commands {
        assert!(
            documented.contains(&expected.as_str()),
            "no docs/CLI.md section for `{expected}`: {documented:?}"
        );
    }
    let mut wrong = Vec::new();
    for (command, named, text) in &sections {
        let takes = help_flags(command);
        for (long, short) in &takes {
            let shown =
                named.contains(long) || short.as_ref().is_some_and(|s| names_short(text, s));
            if !shown {
                wrong.push(format!(
                    "`shadowgraph {command}` takes {long}: not in its docs/CLI.md section"
                ));
            }
        }
        let takes: BTreeSet<String> = takes.into_iter().map(|(long, _)| long).collect();
        for f in named.difference(&takes) {
            wrong.push(format!(
                "docs/CLI.md's `shadowgraph {command}` section names {f}: not an option of it"
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn readme_lists_every_command_with_its_own_options() {
    let readme = read("README.md");
    let lines = readme_lines(&readme);
    let listed: Vec<&str> = lines.iter().map(|(c, _)| c.as_str()).collect();
    for expected in commands() {
        assert!(
            listed.contains(&expected.as_str()),
            "no README line for `shadowgraph {expected}`: {listed:?}"
        );
    }
    let mut wrong = Vec::new();
    for (command, named) in &lines {
        let takes: BTreeSet<String> = help_flags(command).into_iter().map(|(l, _)| l).collect();
        for f in named.difference(&takes) {
            wrong.push(format!(
                "the README's `shadowgraph {command}` line names {f}: not an option of it"
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The parser finds what it must: options in prose and in `[--a x|--b-c]`, not `---` or `--`;
/// a section runs to the next `## ` heading, subsections included, and other sections are no
/// command's.
#[test]
fn flags_and_sections_are_read() {
    let got = flags("`[--sizes 1,2] [--kernel-dirs shipped,DIR,…]` then --only: x -- y --- z");
    let want: BTreeSet<String> = ["--sizes", "--kernel-dirs", "--only"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(got, want);
    let doc = "## `shadowgraph a`\n--x\n### `shadowgraph a --y`\n--z\n## Tools\n--w\n";
    let sections = cli_sections(doc);
    assert_eq!(sections.len(), 1);
    let want: BTreeSet<String> = ["--x", "--y", "--z"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!((sections[0].0.as_str(), &sections[0].1), ("a", &want));
}
