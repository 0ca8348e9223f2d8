//! The technique registry's entries: names unique (scene files and `--techniques` look them
//! up), and each entry's example scene loads and lights something with its technique. No GPU.

use std::path::Path;

use shadowgraph::scene::Scene;
use shadowgraph::technique::{REGISTRY, names};

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
