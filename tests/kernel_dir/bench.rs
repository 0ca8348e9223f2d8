//! `bench --kernel-dirs` times kernel folders side by side.

use super::*;

/// `bench --kernel-dirs shipped,<folder>,…` times each kernel compiled from each folder in one
/// process, rows `<kernel> [shipped]`, `<kernel> [<folder's name>]` and `<kernel> [zeroed]` (the
/// embedded kernels with their workgroup memory zeroed first). A folder's kernel that
/// does not validate is named; one that reads a binding no node binds is refused by the
/// executor (so the folder's kernel is what the executor compiles, not the embedded file), as
/// is a kernel dispatched a line an invocation with another workgroup size than its node's
/// lines a workgroup; a folder that replaces nothing or cannot be read, a name given twice,
/// `--layouts` beside it and `SHADOWGRAPH_KERNEL_DIR` set under it are each
/// one line and status 1.
#[test]
fn bench_times_kernel_folders_side_by_side() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let variant = root.join("benches/variants/blur_rows_run1");
    let dirs = format!("shipped,{},zeroed", variant.display());
    let bench = |dirs: &str, envs: &[(&str, &OsStr)]| {
        let args = [
            "bench",
            "--sizes",
            "64",
            "--repeat",
            "1",
            "--only",
            "blur rg32f r4",
            "--kernel-dirs",
            dirs,
        ];
        let args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
        shadowgraph(&args, envs)
    };
    let o = bench(&dirs, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Table rows only: a busy machine may add a WARNING line that names a row too.
    for row in [
        "blur rg32f r4 [shipped]",
        "blur rg32f r4 [blur_rows_run1]",
        "blur rg32f r4 [zeroed]",
    ] {
        let rows = out
            .lines()
            .filter(|l| l.trim_start().starts_with("64 ") && l.contains(row))
            .count();
        assert_eq!(rows, 1, "`{row}` in {out}");
    }
    assert!(
        out.contains("kernel folders shipped, blur_rows_run1, zeroed"),
        "{out}"
    );

    let dir = temp_dir("bench_dirs");
    let blur = std::fs::read_to_string(root.join("kernels/blur.wgsl")).unwrap();
    let broken = dir.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    std::fs::write(
        broken.join("blur.wgsl"),
        format!("{blur}\nfn f() -> u32 {{\n    return 1.5;\n}}\n"),
    )
    .unwrap();
    refused(
        &bench(&format!("shipped,{}", broken.display()), &[]),
        &["--kernel-dirs", "broken", "kernel `blur`"],
    );
    // The tables' carries, dispatched a line an invocation (`Dispatch::Lines`, 64 lines a
    // workgroup): a variant with another workgroup size is refused by the executor.
    let wide = dir.join("wide");
    std::fs::create_dir_all(&wide).unwrap();
    let carries = std::fs::read_to_string(root.join("kernels/sat_carries.wgsl")).unwrap();
    let from = "@compute @workgroup_size(WG_SIZE)";
    assert!(carries.contains(from), "sat_carries.wgsl: `{from}` moved");
    assert!(blur.contains(from), "blur.wgsl: `{from}` moved");
    std::fs::write(
        wide.join("sat_carries.wgsl"),
        carries.replace(from, "@compute @workgroup_size(32)"),
    )
    .unwrap();
    let wide_dirs = std::ffi::OsString::from(format!("shipped,{}", wide.display()));
    let args: Vec<&OsStr> = [
        "bench",
        "--sizes",
        "64",
        "--repeat",
        "1",
        "--only",
        "sat fixed",
        "--kernel-dirs",
    ]
    .iter()
    .map(OsStr::new)
    .chain([wide_dirs.as_os_str()])
    .collect();
    refused(
        &shadowgraph(&args, &[]),
        &[
            "kernel `sat_carries`",
            "64 lines a workgroup",
            "32 invocations",
        ],
    );
    // A variant that validates and keeps the geometry but reads a binding no node binds: only
    // the executor's pipeline meets it, so the refusal says the folder's kernel is what runs.
    let extra = dir.join("extra");
    std::fs::create_dir_all(&extra).unwrap();
    let entry = "fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {\n";
    assert!(blur.contains(entry), "blur.wgsl: its `main` moved");
    let with_extra = blur
        .replace(entry, &format!("{entry}    _ = sg_extra[li];\n"))
        .replace(
            from,
            &format!("@group(0) @binding(9) var<storage, read> sg_extra: array<u32>;\n\n{from}"),
        );
    std::fs::write(extra.join("blur.wgsl"), with_extra).unwrap();
    refused(
        &bench(&format!("shipped,{}", extra.display()), &[]),
        &["binds nothing to `sg_extra`"],
    );
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    refused(
        &bench(&format!("shipped,{}", empty.display()), &[]),
        &["--kernel-dirs", "empty", "replaces no kernel"],
    );
    let missing = dir.join("missing");
    refused(
        &bench(&format!("shipped,{}", missing.display()), &[]),
        &["--kernel-dirs: ", "missing"],
    );
    refused(
        &bench("shipped,shipped", &[]),
        &["--kernel-dirs", "`shipped` twice"],
    );
    refused(
        &bench(&dirs, &[(KERNEL_DIR_ENV, variant.as_os_str())]),
        &["--kernel-dirs", KERNEL_DIR_ENV],
    );
    let args: Vec<&OsStr> = [
        "bench",
        "--sizes",
        "64",
        "--layouts",
        "gpu",
        "--kernel-dirs",
        "shipped",
    ]
    .iter()
    .map(OsStr::new)
    .collect();
    refused(&shadowgraph(&args, &[]), &["cannot be used with"]);
    let _ = std::fs::remove_dir_all(&dir);
}
