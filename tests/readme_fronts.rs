//! The README's table of Pareto fronts is the summary of the committed reports
//! (`benches/evaluation/<scene>/report.csv`, `evaluate::summary`), so it cannot drift from
//! them: `SHADOWGRAPH_BLESS=1 cargo test --release --test readme_fronts` rewrites it after the
//! reports are regenerated.

use std::path::Path;

const BEGIN: &str = "<!-- fronts:begin";
const END: &str = "<!-- fronts:end -->";

#[test]
fn readme_fronts_table_is_the_committed_reports_summary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = shadowgraph::evaluate::summary::fronts_table_of(&root.join("benches/evaluation"))
        .expect("summary of the committed reports");
    assert!(
        table.lines().count() >= 2 + 9,
        "fewer than nine scenes' reports:\n{table}"
    );
    let readme_path = root.join("README.md");
    let readme = std::fs::read_to_string(&readme_path).expect("README.md");
    let begin = readme
        .find(BEGIN)
        .expect("README has the fronts:begin marker");
    let body = begin + readme[begin..].find('\n').expect("marker line") + 1;
    let end = readme.find(END).expect("README has the fronts:end marker");
    assert!(body <= end, "markers out of order");
    if std::env::var_os("SHADOWGRAPH_BLESS").is_some() {
        let new = format!("{}{table}{}", &readme[..body], &readme[end..]);
        std::fs::write(&readme_path, new).expect("rewrite README.md");
        return;
    }
    assert!(
        readme[body..end] == table,
        "README's fronts table is stale: regenerate it with `SHADOWGRAPH_BLESS=1 cargo test \
         --release --test readme_fronts`\n--- README\n{}\n--- reports\n{table}",
        &readme[body..end]
    );
}
