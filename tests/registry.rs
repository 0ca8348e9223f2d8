//! The technique registry's entries: names unique (scene files and `--techniques` look them
//! up), each entry's example scene loads and lights something with its technique, and
//! `docs/PARAMETERS.md` is generated from the tables. No GPU.

use std::path::Path;

use shadowgraph::scene::Scene;
use shadowgraph::technique::{REGISTRY, names, parameters_markdown};

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
