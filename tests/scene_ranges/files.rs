//! The scene file itself: read up to a cap, a directory and an endless file refused, a
//! byte-order mark skipped.

use super::*;

#[test]
fn a_scene_file_is_read_up_to_a_cap() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-ranges-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Valid TOML, just long: two MiB of comments before the scene.
    let big = dir.join("big.toml");
    let comment = "# padding padding padding padding padding padding padding padding\n";
    std::fs::write(&big, comment.repeat((2 << 20) / comment.len()) + FULL).unwrap();
    let shown = Scene::load(&big)
        .expect_err("2 MiB scene accepted")
        .to_string();
    assert!(
        shown.contains("big.toml") && shown.contains("KiB"),
        "{shown}"
    );
    // A directory is named as one.
    let shown = Scene::load(&dir)
        .expect_err("a directory loaded")
        .to_string();
    assert!(shown.contains("directory"), "{shown}");
    // A UTF-8 byte-order mark is not part of the TOML.
    let bom = dir.join("bom.toml");
    std::fs::write(&bom, format!("\u{feff}{FULL}")).unwrap();
    Scene::load(&bom).unwrap_or_else(|e| panic!("scene with a BOM: {e}"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `plan /dev/zero` read forever: now the read stops at the cap.
#[cfg(unix)]
#[test]
fn an_endless_file_is_refused() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(
            Scene::load("/dev/zero")
                .map(|_| ())
                .map_err(|e| e.to_string()),
        );
    });
    match rx.recv_timeout(Duration::from_secs(20)) {
        Ok(Err(shown)) => assert!(shown.contains("/dev/zero"), "{shown}"),
        Ok(Ok(())) => panic!("/dev/zero parsed as a scene"),
        Err(_) => panic!("reading /dev/zero did not stop within 20 s"),
    }
}
