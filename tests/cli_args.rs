//! Unbounded command-line inputs are refused up front, the same way by every command: `--repeat`
//! is 1 to 1000 for `render`, `evaluate` and `bench`; `evaluate --truth-resolution 0` says what
//! is wrong; `plan /dev/zero` stops reading; `bench --layouts` takes `gpu` and `cpu` only, each
//! once. Each is one line and status 1, within seconds (no GPU work starts); so are an `evaluate
//! --out` folder that cannot be made, a `render` output that is not a PNG, an `--aux` folder
//! that cannot be made, a `dump --out` that names a file, an empty `bench --only` entry, and a
//! `bench --image`, `evaluate --image` or `evaluate --sizes` past the device.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs the CLI, killing it after 60 s (a refusal must come long before).
fn shadowgraph(args: &[&str]) -> Output {
    shadowgraph_env(args, &[])
}

/// [`shadowgraph`] with `envs` set.
fn shadowgraph_env(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_shadowgraph"))
        .args(args)
        .envs(envs.iter().copied())
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run shadowgraph");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("`shadowgraph {}` still running after 60 s", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().expect("output")
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/sphere_on_plane.toml")
        .display()
        .to_string()
}

/// Status 1 and one line on stderr containing every needle.
#[track_caller]
fn refused(args: &[&str], needles: &[&str]) {
    let o = shadowgraph(args);
    let err = String::from_utf8_lossy(&o.stderr);
    let what = args.join(" ");
    assert_eq!(o.status.code(), Some(1), "`{what}`: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "`{what}`: {err}");
    for n in needles {
        assert!(err.contains(n), "`{what}`: `{n}` missing from {err}");
    }
}

#[test]
fn repeat_is_bounded_the_same_way_everywhere() {
    let s = scene();
    let out = std::env::temp_dir().join(format!("shadowgraph-args-{}", std::process::id()));
    let out = out.to_str().unwrap();
    for repeat in ["0", "1001", "4294967295"] {
        refused(
            &["render", &s, "-o", "/dev/null", "--repeat", repeat],
            &["--repeat", "1..=1000"],
        );
        refused(
            &["evaluate", &s, "--out", out, "--repeat", repeat],
            &["--repeat", "1..=1000"],
        );
        refused(
            &["bench", "--sizes", "64", "--repeat", repeat],
            &["--repeat", "1..=1000"],
        );
        refused(
            &["bench", "--lookup", "--repeat", repeat],
            &["--repeat", "1..=1000"],
        );
    }
}

#[test]
fn truth_resolution_zero_says_so() {
    let s = scene();
    let out = std::env::temp_dir().join(format!("shadowgraph-truth-{}", std::process::id()));
    let o = shadowgraph(&[
        "evaluate",
        &s,
        "--out",
        out.to_str().unwrap(),
        "--truth-resolution",
        "0",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--truth-resolution") && !err.contains("device allows"),
        "{err}"
    );
}

#[cfg(unix)]
#[test]
fn plan_of_an_endless_file_stops() {
    refused(&["plan", "/dev/zero"], &["/dev/zero", "KiB"]);
}

/// The library refuses what the command line cannot pass: a render of more frames than
/// `MAX_REPEAT`, an evaluation of `repeat` 0 or `truth_resolution` 0.
#[test]
fn library_entry_points_check_the_same_bounds() {
    let mut opts = shadowgraph::low_level::evaluate::EvaluateOptions {
        repeat: 0,
        ..Default::default()
    };
    let shown = shadowgraph::low_level::evaluate::check_options(&opts)
        .unwrap_err()
        .to_string();
    assert!(shown.contains("--repeat 0"), "{shown}");
    opts.repeat = 1;
    opts.truth_resolution = Some(0);
    let shown = shadowgraph::low_level::evaluate::check_options(&opts)
        .unwrap_err()
        .to_string();
    assert!(shown.contains("--truth-resolution 0"), "{shown}");
    opts.truth_resolution = None;
    opts.samples = Some(shadowgraph::low_level::truth::MAX_EMITTER_SAMPLES as u32 + 1);
    let shown = shadowgraph::low_level::evaluate::check_options(&opts)
        .unwrap_err()
        .to_string();
    assert!(shown.contains("--k 65537"), "{shown}");
    opts.samples = None;
    shadowgraph::low_level::evaluate::check_options(&opts).expect("defaults are valid");
}

/// The lookup benchmark's options apply to `--lookup` only: given without it they are refused
/// naming `--lookup` (clap's message on one line), as is a `--map` of 32768 (past lavapipe's
/// texture side, named as `--map`; past the memory budget where a device allows that side) and
/// an `--only` that names no soft configuration or a light size that is not a positive width
/// in a scene's `light.size` range, both before any table is printed.
#[test]
fn lookup_options_need_the_lookup_and_sane_values() {
    for extra in [
        &["--map", "256"][..],
        &["--image", "64x48"],
        &["--light-sizes", "0.5"],
    ] {
        let mut args = vec!["bench", "--sizes", "64", "--repeat", "1"];
        args.extend_from_slice(extra);
        refused(&args, &["required arguments were not provided", "--lookup"]);
    }
    refused(
        &["bench", "--lookup", "3", "--repeat", "1", "--map", "32768"],
        &["32768"],
    );
    // The kernel bench's sizes do not apply to the lookup (its map is `--map`): refused, not
    // ignored.
    refused(
        &["bench", "--lookup", "3", "--repeat", "1", "--sizes", "64"],
        &["--sizes", "kernel bench", "--map"],
    );
    // Refused before the first table (the PCF lookup table), not after it: nothing on stdout.
    for (extra, needles) in [
        (
            &["--only", "nosuch"][..],
            &["--only nosuch", "matches no soft configuration", "vssm"][..],
        ),
        (&["--light-sizes", "nan"], &["light size NaN", "positive"]),
        (&["--light-sizes", "0.5,-1"], &["light size -1", "positive"]),
        (&["--light-sizes", "0"], &["light size 0", "positive"]),
        // Past a scene's `light.size` range (it rendered, a light 10³⁰ wide).
        (
            &["--light-sizes", "1e30"],
            &["light size 1", "up to 1000000"],
        ),
    ] {
        let mut args = vec!["bench", "--lookup", "3", "--repeat", "1"];
        args.extend_from_slice(extra);
        refused(&args, needles);
        let out = shadowgraph(&args).stdout;
        assert!(
            out.is_empty(),
            "`{}`: {}",
            args.join(" "),
            String::from_utf8_lossy(&out)
        );
    }
}

#[test]
fn layouts_are_named_and_not_for_the_lookup() {
    refused(
        &[
            "bench",
            "--sizes",
            "64",
            "--repeat",
            "1",
            "--layouts",
            "gpu,fast",
        ],
        &[
            "--layouts",
            "`fast`",
            "expected `gpu`, `cpu`, `redesign` or `redesign-textures`",
        ],
    );
    refused(
        &[
            "bench",
            "--lookup",
            "3",
            "--repeat",
            "1",
            "--layouts",
            "gpu",
        ],
        &["--lookup", "cannot be used with", "--layouts"],
    );
    refused(
        &[
            "bench",
            "--sizes",
            "64",
            "--repeat",
            "1",
            "--layouts",
            "cpu,gpu,cpu",
        ],
        &["--layouts", "`cpu` twice", "entry 3"],
    );
}

/// `evaluate --out` that cannot be made (its parent is a file) is refused before the sweep: with
/// a sweep that would run for minutes (`--k 4096 --repeat 1000`), the refusal comes within the
/// helper's 60 s and names the folder, with nothing on stdout.
#[test]
fn evaluate_refuses_an_output_folder_before_the_sweep() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-cli-args-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a_file");
    std::fs::write(&file, b"not a folder").unwrap();
    let out = file.join("report");
    let out = out.to_str().unwrap();
    let scene = scene();
    let args = [
        "evaluate",
        &scene,
        "--techniques",
        "hard,pcss",
        "--k",
        "4096",
        "--repeat",
        "1000",
        "--out",
        out,
    ];
    refused(&args, &["a_file"]);
    assert!(shadowgraph(&args).stdout.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `render -o` that is not a `.png` file, or an `--aux` folder that cannot be made, is refused
/// before the frames (with `--repeat 1000`, minutes of them on a CPU driver): one line naming
/// it, nothing on stdout.
#[test]
fn render_refuses_its_outputs_before_the_frames() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-cli-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a_file");
    std::fs::write(&file, b"not a folder").unwrap();
    let jpg = dir.join("out.jpg");
    let png = dir.join("out.png");
    let aux = file.join("aux");
    let scene = scene();
    for (args, needles) in [
        (
            vec![
                "render",
                &scene,
                "-o",
                jpg.to_str().unwrap(),
                "--repeat",
                "1000",
            ],
            &["out.jpg", "PNG"][..],
        ),
        (
            vec![
                "render",
                &scene,
                "-o",
                png.to_str().unwrap(),
                "--aux",
                aux.to_str().unwrap(),
                "--repeat",
                "1000",
            ],
            &["a_file"][..],
        ),
        (
            vec![
                "render",
                &scene,
                "-o",
                png.to_str().unwrap(),
                "--aux",
                file.to_str().unwrap(),
                "--repeat",
                "1000",
            ],
            &["a_file", "exists and is not a folder"][..],
        ),
    ] {
        refused(&args, needles);
        assert!(shadowgraph(&args).stdout.is_empty());
    }
    assert!(!png.exists() && !jpg.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `dump --out` naming a file is refused before the frame, saying it is not a folder (the OS's
/// own words are "File exists").
#[test]
fn dump_refuses_a_file_as_its_folder() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-cli-dump-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a_file");
    std::fs::write(&file, b"not a folder").unwrap();
    let scene = scene();
    let args = ["dump", &scene, "--out", file.to_str().unwrap()];
    refused(&args, &["a_file", "exists and is not a folder"]);
    assert!(shadowgraph(&args).stdout.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An empty entry of `bench --only` (`sat,`, `,`) would keep every kernel, since every name
/// contains it: refused naming the entry, with and without `--lookup`, before any table. An
/// `--image` past the device's texture side is named as `--image`, not as the bench's own
/// scene file, and so are `evaluate`'s `--image` and `--sizes`; a negative `evaluate
/// --moment-bias` gets its range, not clap's "unexpected argument".
#[test]
fn empty_filters_and_oversized_images_are_named() {
    for (args, needles) in [
        (
            &["bench", "--sizes", "64", "--repeat", "1", "--only", "sat,"][..],
            &["--only sat,", "entry 2 is empty"][..],
        ),
        (
            &["bench", "--lookup", "3", "--repeat", "1", "--only", ","],
            &["--lookup --only ,", "entry 1 is empty"],
        ),
        (
            &[
                "bench",
                "--lookup",
                "3",
                "--repeat",
                "1",
                "--image",
                "100000x48",
            ],
            &["--image (width)", "100000"],
        ),
        (
            &[
                "bench",
                "--lookup",
                "3",
                "--repeat",
                "1",
                "--image",
                "64x100000",
            ],
            &["--image (height)", "100000"],
        ),
    ] {
        refused(args, needles);
        assert!(shadowgraph(args).stdout.is_empty(), "{}", args.join(" "));
    }
    let s = scene();
    let out = std::env::temp_dir().join(format!("shadowgraph-bias-{}", std::process::id()));
    refused(
        &[
            "evaluate",
            &s,
            "--out",
            out.to_str().unwrap(),
            "--moment-bias",
            "0.1,-1",
        ],
        &["--moment-bias", "-1", "[0, 0.5]"],
    );
    // A bias no configuration of the sweep takes, and more emitter samples than the truth
    // takes (10⁸ aborted on a 50 GB allocation).
    for (extra, needles) in [
        (
            &["--techniques", "hard,pcss", "--moment-bias", "0.1"][..],
            &["--moment-bias", "no technique", "msm, msm_soft"][..],
        ),
        (&["--k", "100000000"], &["--k 100000000", "at most 65536"]),
        // Sides past the device (65 536 is past every device's largest texture side) are named
        // by their flags, not by the scene file's `output.width` or `light[0].shadow_map`.
        (
            &["--image", "100000x48"],
            &["evaluate --image (width)", "100000"],
        ),
        (
            &["--image", "64x100000"],
            &["evaluate --image (height)", "100000"],
        ),
        (
            &["--sizes", "512,65536"],
            &["evaluate --sizes 65536", "light[0]", "65536"],
        ),
    ] {
        let mut args = vec!["evaluate", &s, "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        refused(&args, needles);
        let o = shadowgraph(&args);
        assert!(o.stdout.is_empty());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("sphere_on_plane.toml"), "{err}");
    }
}

/// A value a flag or the sweep set, past the memory budget, is named with what set it, not
/// with the scene file's line (`scenes/bunny.toml:5:1: ... lower output.width` for
/// `--image 4000x4000`, or a line of the lookup benchmark's bundled scene), and so is the
/// truth's resolution: one line, status 1, before any frame is timed.
#[test]
fn memory_errors_name_the_flag_that_set_the_value() {
    let s = scene();
    let out = std::env::temp_dir().join(format!("shadowgraph-set-by-{}", std::process::id()));
    let out = out.to_str().unwrap();
    let evaluate = [
        "evaluate",
        &s,
        "--out",
        out,
        "--quick",
        "--techniques",
        "hard",
    ];
    let lookup = ["bench", "--lookup", "3", "--repeat", "1"];
    for (base, extra, budget, needles) in [
        (
            &evaluate[..],
            &["--image", "4000x4000"][..],
            "64MiB",
            &["(`output.width` from evaluate --image 4000x4000)"][..],
        ),
        (
            &evaluate,
            &["--sizes", "8192"],
            "64MiB",
            &["(`light[0].shadow_map` from evaluate --sizes (configuration `hard 8192`))"],
        ),
        // The truth's depth map, which no frame plan counts (8192² ran under a 64 MiB budget).
        (
            &evaluate,
            &["--truth-resolution", "8192"],
            "64MiB",
            &[
                "the truth of light[0]",
                "8192×8192 depth map",
                "lower --truth-resolution",
            ],
        ),
        (
            &lookup,
            &["--image", "2000x2000"],
            "32MiB",
            &["scenes/techniques/vsm.toml (`output.width` from bench --lookup --image 2000x2000)"],
        ),
        (
            &lookup,
            &["--map", "8192"],
            "64MiB",
            &["(`light[0].shadow_map` from bench --lookup --map 8192)"],
        ),
    ] {
        let args = [base, extra].concat();
        let what = args.join(" ");
        let o = shadowgraph_env(&args, &[("SHADOWGRAPH_MEMORY_BUDGET", budget)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "`{what}`: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "`{what}`: {err}");
        for n in needles.iter().chain(&["SHADOWGRAPH_MEMORY_BUDGET"]) {
            assert!(err.contains(n), "`{what}`: `{n}` missing from {err}");
        }
        assert!(!err.contains(".toml:"), "`{what}` names a line: {err}");
    }
}

/// `compare`: a committed report against itself agrees (status 0, every front "agree"); a
/// missing report, a file that is not a report and two scenes' reports are one line each.
#[test]
fn compare_reads_two_reports_and_refuses_what_is_not_one() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let report = |scene: &str| {
        root.join(format!("benches/evaluation/{scene}/report.json"))
            .display()
            .to_string()
    };
    let a = report("long_shadows");
    let o = shadowgraph(&["compare", &a, &a]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(out.contains("penumbra mean front: agree"), "{out}");
    assert!(!out.contains("differ."), "{out}");
    refused(
        &["compare", &a, "no/such/report.json"],
        &["no/such/report.json"],
    );
    let toml = scene();
    refused(
        &["compare", &a, &toml],
        &["sphere_on_plane.toml", "not an evaluation report"],
    );
    refused(&["compare", &a, &report("pole")], &["different scenes"]);
}
