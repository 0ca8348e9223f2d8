//! Bad input is a clear one-line error.

use super::*;

/// Bad input is one clear line and exit status 1, never a panic.
#[test]
fn bad_input_is_a_clear_error() {
    let out = temp_dir("bad");
    let o = shadowgraph(&[
        "evaluate",
        scene_path("sphere_on_plane.toml").to_str().unwrap(),
        "--quick",
        "--techniques",
        "hard,phong",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("unknown technique `phong`") && err.contains("vsm"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    for (flag, value) in [
        ("--update", "0"),
        ("--update", "sometimes"),
        ("--update", "-3"),
        ("--budget", "0"),
        ("--budget", "-1"),
        ("--budget", "NaN"),
    ] {
        let o = shadowgraph(&[
            "evaluate",
            scene_path("sphere_on_plane.toml").to_str().unwrap(),
            "--quick",
            flag,
            value,
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{flag} {value}: {err}");
        assert!(
            err.trim().lines().count() == 1 && err.contains(flag) && !err.contains("panicked"),
            "{flag} {value}: {err}"
        );
    }
    let o = shadowgraph(&[
        "evaluate",
        "no/such/scene.toml",
        "--quick",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("no/such/scene.toml") && !err.contains("panicked"),
        "{err}"
    );
    let o = shadowgraph(&[
        "evaluate",
        scene_path("pole.toml").to_str().unwrap(),
        "--sizes",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--sizes") && !err.contains("panicked"),
        "{err}"
    );
    assert!(
        !out.join("report.json").exists(),
        "a failed run wrote a report"
    );
}
