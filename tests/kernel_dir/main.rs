//! `SHADOWGRAPH_KERNEL_DIR`: a folder of `.wgsl` files replaces the embedded kernels of the same
//! names for one process (one build runs kernel variants). The replacement is what runs; a
//! stray file, a missing folder or broken WGSL is one line and status 1. And
//! `SHADOWGRAPH_KERNEL_LAYOUT`, which picks the kernels' layout (`exec::KernelLayout`): `info` prints it, a bad
//! value is one line.

use shadowgraph::low_level::exec::KERNEL_LAYOUT_ENV;
use shadowgraph::low_level::kernels::{self, KERNEL_DIR_ENV};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod bench;
mod replace;
mod variants;

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-kdir-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Runs the CLI with `args`, neither switch set but those in `envs`.
fn shadowgraph(args: &[&OsStr], envs: &[(&str, &OsStr)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_shadowgraph"));
    cmd.args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .env_remove(KERNEL_DIR_ENV)
        .env_remove(KERNEL_LAYOUT_ENV)
        .envs(envs.iter().copied());
    cmd.output().expect("run shadowgraph")
}

/// Status 1 and one line on stderr after the note, containing every needle.
#[track_caller]
fn refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| !l.starts_with("note: ")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    for n in needles {
        assert!(errors[0].contains(n), "`{n}` missing from {err}");
    }
}

/// `scenes/techniques/<scene>` with each `(from, to)` of `edits` replaced (each `from` must be
/// there), written into `dir` as `name`.
fn edited_scene(dir: &Path, scene: &str, edits: &[(&str, &str)], name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut text = std::fs::read_to_string(root.join("scenes/techniques").join(scene)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{scene}: `{from}` moved");
        text = text.replace(from, to);
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}
