//! The table of Pareto fronts in docs/MEASURED.md (which the README's headline figures link
//! to) is the summary of the committed reports (`benches/evaluation/<scene>/report.csv`,
//! `evaluate::summary`), so it cannot drift from them: `SHADOWGRAPH_BLESS=1 cargo test
//! --release --test readme_fronts` rewrites it after the reports are regenerated.

use std::path::Path;

const BEGIN: &str = "<!-- fronts:begin";
const END: &str = "<!-- fronts:end -->";

#[test]
fn fronts_table_is_the_committed_reports_summary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = shadowgraph::low_level::evaluate::summary::fronts_table_of(
        &root.join("benches/evaluation"),
    )
    .expect("summary of the committed reports");
    assert!(
        table.lines().count() >= 2 + 9,
        "fewer than nine scenes' reports:\n{table}"
    );
    let doc_path = root.join("docs/MEASURED.md");
    let doc = std::fs::read_to_string(&doc_path).expect("docs/MEASURED.md");
    let begin = doc
        .find(BEGIN)
        .expect("docs/MEASURED.md has the fronts:begin marker");
    let body = begin + doc[begin..].find('\n').expect("marker line") + 1;
    let end = doc
        .find(END)
        .expect("docs/MEASURED.md has the fronts:end marker");
    assert!(body <= end, "markers out of order");
    if std::env::var_os("SHADOWGRAPH_BLESS").is_some() {
        let new = format!("{}{table}{}", &doc[..body], &doc[end..]);
        std::fs::write(&doc_path, new).expect("rewrite docs/MEASURED.md");
        return;
    }
    assert!(
        doc[body..end] == table,
        "docs/MEASURED.md's fronts table is stale: regenerate it with `SHADOWGRAPH_BLESS=1 \
         cargo test --release --test readme_fronts`\n--- docs/MEASURED.md\n{}\n--- reports\n{table}",
        &doc[body..end]
    );
}
