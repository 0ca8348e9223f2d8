//! Every kernel file is registered and parses; missing imports and blocks are named errors.

use super::*;

#[test]
fn every_file_in_kernels_is_registered() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels");
    let mut on_disk = BTreeSet::new();
    for sub in ["", "shared/"] {
        for e in std::fs::read_dir(dir.join(sub)).expect("kernels/ readable") {
            let p = e.expect("dir entry").path();
            if p.extension().is_some_and(|x| x == "wgsl") {
                let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
                on_disk.insert(format!("{sub}{stem}"));
            }
        }
    }
    let registered: BTreeSet<String> = SOURCES.iter().map(|s| s.name.to_string()).collect();
    assert_eq!(
        on_disk, registered,
        "kernels/ and kernels::SOURCES disagree"
    );
}

/// The ids `build.rs` generates match the folder as it is now (a stale build, or a file the
/// script skipped, fails here), and each id's source is its file's text, which naga parses
/// once its imports are resolved (`shade` with a generated block).
#[test]
fn every_kernel_file_has_an_id_whose_source_parses() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels");
    let mut on_disk = BTreeSet::new();
    for e in std::fs::read_dir(&dir).expect("kernels/ readable") {
        let p = e.expect("dir entry").path();
        if p.extension().is_some_and(|x| x == "wgsl") {
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            on_disk.insert(stem.to_string());
        }
    }
    let ids: BTreeSet<String> = KernelId::ALL.iter().map(|k| k.name().to_string()).collect();
    assert_eq!(on_disk, ids, "kernels/*.wgsl and KernelId::ALL disagree");
    let block = shading_block(&[light(Technique::Hard)]);
    let mut failures = Vec::new();
    for &id in KernelId::ALL {
        let file = std::fs::read_to_string(dir.join(format!("{}.wgsl", id.name())));
        assert_eq!(file.ok().as_deref(), Some(id.source()), "{id}: source");
        assert_eq!(KernelId::from_name(id.name()), Some(id));
        let generated = (id == KernelId::Shade).then_some(block.as_str());
        let parsed = kernels::resolve(id.name(), generated)
            .map_err(|e| e.to_string())
            .and_then(|wgsl| {
                naga::front::wgsl::parse_str(&wgsl).map_err(|e| e.emit_to_string(&wgsl))
            });
        if let Err(e) = parsed {
            failures.push(format!("{id}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn missing_import_and_missing_block_are_named_errors() {
    assert!(kernels::resolve("nonexistent", None).is_err());
    let e = kernels::resolve("shade", None).unwrap_err().to_string();
    assert!(e.contains("shade") && e.contains("generated"), "{e}");
}
