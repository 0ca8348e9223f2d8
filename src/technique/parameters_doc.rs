//! The parameter reference (`docs/PARAMETERS.md`), written from the registry's tables, so the
//! documented ranges and defaults are the checked ones: `tests/registry.rs` fails when the
//! file differs from [`parameters_markdown`] (regenerate it with `SHADOWGRAPH_BLESS=1`).

use std::fmt::Write;

use super::{REGISTRY, params};
use crate::model::{ParamDefault, ParamKind, ParamSpec};

/// Markdown: every technique's name, doc line and `[light.shadow]` keys (what each accepts,
/// its default, when it applies, its doc line), the keys every technique takes first.
pub fn parameters_markdown() -> String {
    let mut s = String::from(
        "# Parameters of each technique\n\n[← README](../README.md) · [scene format](SCENES.md)\n\n\
         Generated from the technique registry (`src/technique/`), the one place each key's \
         range and default are written; the scene parser and the plug-in's `PrefilterConfig` \
         check values against the same tables. `tests/registry.rs` fails when this file is \
         stale: regenerate it with `SHADOWGRAPH_BLESS=1 cargo test --release --test registry`.\n\n\
         ## Every technique\n\n",
    );
    table(&mut s, &[params::COMMON]);
    s.push_str(
        "\n## Directional cascades\n\nKeys of every technique's table on a directional light; \
         refused on a spot or a point light, more than one cascade for `smrt`; PCSS and the soft \
         techniques give each cascade a guard band of their reach — see \
         [Cascades](SCENES.md#cascades).\n\n",
    );
    table(&mut s, &[params::CASCADES]);
    for def in REGISTRY {
        let _ = write!(s, "\n## `{}`\n\n{}\n\n", def.name, def.doc);
        if def.params.iter().all(|t| t.is_empty()) {
            s.push_str("No keys of its own.\n");
        } else {
            table(&mut s, def.params);
        }
    }
    s
}

fn table(s: &mut String, tables: &[&[ParamSpec]]) {
    s.push_str("| key | accepts | default | applies when | what it does |\n");
    s.push_str("| --- | --- | --- | --- | --- |\n");
    for spec in tables.iter().flat_map(|t| t.iter()) {
        let needs: Vec<String> = spec
            .needs
            .iter()
            .map(|n| format!("`{}` is {}", n.key, quoted(n.one_of)))
            .collect();
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {} |",
            spec.key,
            accepts(spec.kind),
            default(spec.default),
            if needs.is_empty() {
                "always".to_string()
            } else {
                needs.join(" and ")
            },
            spec.doc.replace('|', "\\|")
        );
    }
}

fn accepts(kind: ParamKind) -> String {
    match kind {
        ParamKind::Int { lo, hi } => format!("integer {lo} to {hi}"),
        ParamKind::Float { lo, hi } => format!("number {lo} to {hi}"),
        ParamKind::Choice(options) => quoted(options),
    }
}

fn default(d: ParamDefault) -> String {
    match d {
        ParamDefault::Int(v) => v.to_string(),
        ParamDefault::Float(v) => v.to_string(),
        ParamDefault::Choice(c) => format!("`\"{c}\"`"),
        ParamDefault::Rule(_) => "computed (see its line)".to_string(),
    }
}

fn quoted(options: &[&str]) -> String {
    let q: Vec<String> = options.iter().map(|o| format!("`\"{o}\"`")).collect();
    q.join(", ")
}
