//! `shadowgraph dump`: every plan resource as EXR + per-channel PNG previews + manifest, with
//! statistics that match the files, a VSM variance view, `--only`, and the stats helper.

mod common;

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use shadowgraph::low_level::dump::{
    self, ChannelStats, channel_names, channel_stats, variance_view,
};
use shadowgraph::low_level::gpu::float_channels;
use shadowgraph::low_level::render::plan_lights;
use shadowgraph::low_level::scene::Scene;

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

/// A fresh (absent) folder under the system temp dir; `dump` must create it.
fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-dump-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn files_in(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .expect("output folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect()
}

fn manifest(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest.json");
    serde_json::from_str(&text).expect("manifest.json parses")
}

/// Every file the manifest names: each entry's EXR and each channel's preview.
fn manifest_files(m: &serde_json::Value) -> BTreeSet<String> {
    let mut files = BTreeSet::new();
    for e in m["resources"].as_array().expect("resources") {
        files.insert(e["file"].as_str().expect("file").to_string());
        for c in e["channels"].as_array().expect("channels") {
            files.insert(c["preview"].as_str().expect("preview").to_string());
        }
    }
    files
}

/// The channels of a 32-bit float EXR, by name.
fn read_exr(path: &Path) -> HashMap<String, Vec<f32>> {
    let img = exr::prelude::read_all_flat_layers_from_file(path).expect("EXR readable");
    img.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| {
            let v: Vec<f32> = c.sample_data.values_as_f32().collect();
            (c.name.to_string(), v)
        })
        .collect()
}

fn entry<'a>(m: &'a serde_json::Value, file: &str) -> &'a serde_json::Value {
    m["resources"]
        .as_array()
        .expect("resources")
        .iter()
        .find(|e| e["file"] == file)
        .unwrap_or_else(|| panic!("{file} not in the manifest"))
}

fn assert_rel(what: &str, manifest: &serde_json::Value, value: f64) {
    let m = manifest
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: {manifest}"));
    assert!(
        (m - value).abs() <= 1e-6 * value.abs().max(f64::MIN_POSITIVE),
        "{what}: manifest {m}, recomputed {value}"
    );
}

/// Manifest statistics of every channel of `file` against a recomputation from the EXR.
fn check_stats(dir: &Path, m: &serde_json::Value, file: &str) {
    let exr = read_exr(&dir.join(file));
    for c in entry(m, file)["channels"].as_array().expect("channels") {
        let name = c["name"].as_str().expect("name");
        let v = &exr[name];
        let finite: Vec<f64> = v
            .iter()
            .filter(|x| x.is_finite())
            .map(|&x| f64::from(x))
            .collect();
        let what = format!("{file}/{name}");
        assert_rel(
            &format!("{what} min"),
            &c["min"],
            finite.iter().copied().fold(f64::INFINITY, f64::min),
        );
        assert_rel(
            &format!("{what} max"),
            &c["max"],
            finite.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        assert_rel(
            &format!("{what} mean"),
            &c["mean"],
            finite.iter().sum::<f64>() / finite.len() as f64,
        );
        assert_eq!(
            c["nan"],
            v.iter().filter(|x| x.is_nan()).count(),
            "{what} nan"
        );
        assert_eq!(
            c["inf"],
            v.iter().filter(|x| x.is_infinite()).count(),
            "{what} inf"
        );
    }
}

#[test]
fn dump_writes_every_resource_with_matching_manifest() {
    let g = common::gpu();
    let dir = temp_dir("all");
    let path = scene("techniques/vsm.toml");
    let report = dump::dump(&g, &path, &dir, None).expect("dump");
    let sp = plan_lights(&Scene::load(&path).expect("scene").lights).expect("plan");
    let files = files_in(&dir);
    let mut expected = BTreeSet::from(["manifest.json".to_string()]);
    for r in &sp.plan.resources {
        let (name, format) = (&r.resource.name, r.resource.format);
        let channels = float_channels(format).expect("float format");
        for level in 0..r.resource.mips {
            let stem = match level {
                0 => name.clone(),
                l => format!("{name}.mip{l}"),
            };
            expected.insert(format!("{stem}.exr"));
            for c in channel_names(name, format, channels) {
                expected.insert(format!("{stem}.{c}.png"));
            }
        }
    }
    for f in &expected {
        assert!(files.contains(f), "{f} missing; wrote {files:?}");
        assert!(
            report.contains(f.as_str()),
            "{f} not in the report:\n{report}"
        );
    }
    let m = manifest(&dir);
    assert!(m["adapter"].as_str().is_some_and(|a| !a.is_empty()));
    let mut listed = manifest_files(&m);
    listed.insert("manifest.json".into());
    assert_eq!(
        listed, files,
        "the manifest lists exactly the files written"
    );

    let vsm = read_exr(&dir.join("light0.vsm.exr"));
    let names: BTreeSet<&str> = vsm.keys().map(String::as_str).collect();
    assert_eq!(names, BTreeSet::from(["z", "z2"]));
    let e = entry(&m, "light0.vsm.exr");
    assert_eq!(
        (e["name"].as_str(), e["producer"].as_str()),
        (Some("light0.vsm"), Some("vsm"))
    );
    assert_eq!(
        (e["format"].as_str(), e["light"].as_u64()),
        (Some("Rg32Float"), Some(0))
    );
    assert_eq!(
        (
            e["width"].as_u64(),
            e["height"].as_u64(),
            e["mip_level"].as_u64()
        ),
        (Some(512), Some(512), Some(0))
    );
    assert!(
        entry(&m, "light0.depth.exr")["producer"].is_null(),
        "imports have no kernel"
    );
    for f in [
        "light0.depth.exr",
        "light0.linear.exr",
        "light0.vsm.exr",
        "light0.vsm.blur.exr",
        "light0.vsm.variance.exr",
    ] {
        check_stats(&dir, &m, f);
    }
    let png = image::open(dir.join("light0.depth.depth.png"))
        .expect("png")
        .to_rgba8();
    assert_eq!(png.dimensions(), (512, 512));
    let grays: BTreeSet<u8> = png.pixels().map(|p| p[0]).collect();
    assert!(
        grays.contains(&0) && grays.contains(&255),
        "previews span the channel's own range"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn variance_view_is_clamped_sigma_squared_of_each_vsm_map() {
    let g = common::gpu();
    let dir = temp_dir("variance");
    dump::dump(&g, &scene("techniques/vsm.toml"), &dir, None).expect("dump");
    let m = manifest(&dir);
    for r in ["light0.vsm", "light0.vsm.blur"] {
        let moments = read_exr(&dir.join(format!("{r}.exr")));
        let var = read_exr(&dir.join(format!("{r}.variance.exr")));
        assert_eq!(var.keys().collect::<Vec<_>>(), ["variance"], "{r}");
        assert!(
            dir.join(format!("{r}.variance.png")).is_file(),
            "{r}.variance.png"
        );
        let e = entry(&m, &format!("{r}.variance.exr"));
        assert_eq!(e["producer"], "dump (variance view)");
        assert_eq!(e["source"].as_str(), Some(r));
        let (z, z2, v) = (&moments["z"], &moments["z2"], &var["variance"]);
        for i in 0..v.len() {
            let want = (f64::from(z2[i]) - f64::from(z[i]).powi(2)).max(0.0);
            let got = f64::from(v[i]);
            assert!((got - want).abs() <= 1e-7, "{r} texel {i}: {got} vs {want}");
        }
        assert!(
            v.iter().any(|&x| x > 0.0),
            "{r}: the scene has depth edges, so some variance"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An f16 VSM map, stored as pack2x16float words in an r32uint texture, is dumped unpacked:
/// its two named float channels, every value an f16 value, the manifest naming the packing.
#[test]
fn packed_f16_moments_are_dumped_as_named_float_channels() {
    let g = common::gpu();
    let dir = temp_dir("f16");
    dump::dump(&g, &scene("techniques/vsm_f16.toml"), &dir, None).expect("dump");
    let m = manifest(&dir);
    let e = entry(&m, "light0.vsm.blur.exr");
    assert_eq!(e["format"].as_str(), Some("R32Uint f16x2"));
    let blur = read_exr(&dir.join("light0.vsm.blur.exr"));
    let names: BTreeSet<&str> = blur.keys().map(String::as_str).collect();
    assert_eq!(names, BTreeSet::from(["z", "z2"]));
    // An f16 value: 10 mantissa bits (13 low f32 bits zero) when normal, a multiple of 2⁻²⁴
    // below 2⁻¹⁴.
    let is_f16 = |v: f32| {
        if v.abs() >= 2f32.powi(-14) {
            v.to_bits() & 0x1fff == 0
        } else {
            (v * 2f32.powi(24)).fract() == 0.0
        }
    };
    let linear = &read_exr(&dir.join("light0.linear.exr"))["z"];
    for (c, values) in &blur {
        assert!(values.iter().all(|&v| is_f16(v)), "{c}: not f16 values");
    }
    // The blurred mean depth stays within the map's depth range, and z² ≥ z̄² − f16 rounding.
    let (lo, hi) = linear
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    for (z, z2) in blur["z"].iter().zip(&blur["z2"]) {
        assert!(
            (lo - 1e-3..=hi + 1e-3).contains(z),
            "{z} outside [{lo}, {hi}]"
        );
        assert!(*z2 >= z * z * (1.0 - 3e-3) - 1e-4, "z2 {z2} < z² {}", z * z);
    }
    assert!(dir.join("light0.vsm.blur.variance.exr").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Each resource is dumped as its producer left it, not as a later resource that reused its
/// pooled texture: the VSM z moment is the linear depth itself, and its blur differs.
#[test]
fn dumped_resources_are_intact() {
    let g = common::gpu();
    let dir = temp_dir("intact");
    dump::dump(&g, &scene("techniques/vsm.toml"), &dir, None).expect("dump");
    let linear = &read_exr(&dir.join("light0.linear.exr"))["z"];
    let vsm = read_exr(&dir.join("light0.vsm.exr"));
    let differing = linear.iter().zip(&vsm["z"]).filter(|(a, b)| a != b).count();
    assert_eq!(
        differing, 0,
        "light0.vsm z differs from light0.linear at {differing} texels"
    );
    let v = read_exr(&dir.join("light0.vsm.blur.exr"));
    assert_ne!(vsm["z"], v["z"], "light0.vsm and its blur dumped identical");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn only_dumps_one_resource() {
    let g = common::gpu();
    let dir = temp_dir("only");
    let report = dump::dump(
        &g,
        &scene("techniques/vsm.toml"),
        &dir,
        Some("light0.linear"),
    )
    .expect("dump");
    let want: BTreeSet<String> = ["light0.linear.exr", "light0.linear.z.png", "manifest.json"]
        .map(String::from)
        .into();
    assert_eq!(files_in(&dir), want, "report:\n{report}");
    let m = manifest(&dir);
    assert_eq!(m["resources"].as_array().map(Vec::len), Some(1));
    assert_eq!(m["resources"][0]["producer"], "linearize");
    check_stats(&dir, &m, "light0.linear.exr");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Tables interleaved in one texture (CSM's four, `techniques/csm_sat.toml`) are dumped one by
/// one: `--only` the texture writes each of its tables (it wrote nothing, silently, before
/// 2026-11-27), and `--only` one table's name, which a full dump writes,
/// writes that table, the same values as the full dump's.
#[test]
fn only_an_interleaved_texture_or_one_of_its_tables() {
    let g = common::gpu();
    let path = scene("techniques/csm_sat.toml");
    let all = temp_dir("only_layers_all");
    dump::dump(&g, &path, &all, None).expect("dump");
    let tables = [
        "light0.csm0.sat",
        "light0.csm1.sat",
        "light0.csm2.sat",
        "light0.csm3.sat",
    ];
    for t in tables {
        assert!(
            all.join(format!("{t}.exr")).exists(),
            "{t} in the full dump"
        );
    }
    let texture = temp_dir("only_layers_texture");
    dump::dump(&g, &path, &texture, Some("light0.csm.sat.layers0")).expect("dump");
    let exrs: BTreeSet<String> = files_in(&texture)
        .into_iter()
        .filter(|f| f.ends_with(".exr"))
        .collect();
    let want: BTreeSet<String> = tables.iter().map(|t| format!("{t}.exr")).collect();
    assert_eq!(exrs, want);
    let one = temp_dir("only_layers_one");
    dump::dump(&g, &path, &one, Some("light0.csm2.sat")).expect("dump");
    let exrs: Vec<String> = files_in(&one)
        .into_iter()
        .filter(|f| f.ends_with(".exr"))
        .collect();
    assert_eq!(exrs, ["light0.csm2.sat.exr"]);
    let full = read_exr(&all.join("light0.csm2.sat.exr"));
    assert_eq!(read_exr(&one.join("light0.csm2.sat.exr")), full);
    assert!(
        full.values().flatten().any(|&v| v != 0.0),
        "csm2's table is all zeros"
    );
    for d in [all, texture, one] {
        let _ = std::fs::remove_dir_all(&d);
    }
}

#[test]
fn unknown_only_is_an_error_naming_the_resources() {
    let g = common::gpu();
    let dir = temp_dir("unknown");
    let err = dump::dump(&g, &scene("techniques/vsm.toml"), &dir, Some("light0.nope"))
        .expect_err("unknown name");
    assert!(matches!(err, shadowgraph::Error::Invalid(_)), "{err:?}");
    let msg = err.to_string();
    for name in [
        "light0.nope",
        "light0.depth",
        "light0.linear",
        "light0.vsm",
        "light0.vsm.blur",
    ] {
        assert!(msg.contains(name), "`{name}` not in: {msg}");
    }
    assert!(!dir.exists(), "nothing written on a bad name");
}

#[test]
fn stats_count_non_finite_and_summarize_the_rest() {
    let v = [
        1.0,
        f32::NAN,
        f32::INFINITY,
        -2.0,
        f32::NEG_INFINITY,
        4.0,
        f32::NAN,
    ];
    let s = channel_stats(&v);
    assert_eq!(
        s,
        ChannelStats {
            min: Some(-2.0),
            max: Some(4.0),
            mean: Some(1.0),
            nan: 2,
            inf: 2,
        }
    );
    let none = channel_stats(&[f32::NAN, f32::INFINITY]);
    assert_eq!(
        (none.min, none.max, none.mean, none.nan, none.inf),
        (None, None, None, 1, 1)
    );
    assert_eq!(channel_stats(&[]), ChannelStats::default());
    let json = serde_json::to_value(&none).expect("serializes");
    assert!(json["min"].is_null() && json["mean"].is_null());
}

#[test]
fn previews_normalize_per_channel_and_mark_non_finite_red() {
    let v = [2.0, 3.0, f32::NAN, 4.0, f32::NEG_INFINITY];
    let rgba = dump::preview_rgba(&v, &channel_stats(&v));
    let px: Vec<&[u8]> = rgba.chunks_exact(4).collect();
    assert_eq!(
        px,
        [
            &[0, 0, 0, 255][..],
            &[128, 128, 128, 255],
            &[255, 0, 0, 255],
            &[255, 255, 255, 255],
            &[255, 0, 0, 255]
        ]
    );
    let flat = [7.0f32; 3];
    let rgba = dump::preview_rgba(&flat, &channel_stats(&flat));
    assert!(
        rgba.chunks_exact(4).all(|p| p == [128, 128, 128, 255]),
        "constant → mid-gray"
    );
}

#[test]
fn variance_view_clamps_and_keeps_nan() {
    let v = variance_view(
        &[0.5, 0.5, f32::NAN, f32::INFINITY],
        &[0.3, 0.2, 0.1, f32::INFINITY],
    );
    assert!((f64::from(v[0]) - 0.05).abs() < 1e-7);
    assert_eq!(v[1], 0.0, "negative variance clamps to 0");
    assert!(
        v[2].is_nan() && v[3].is_nan(),
        "non-finite moments stay visible"
    );
}

#[test]
fn channel_names_follow_the_resource_kind() {
    use wgpu::TextureFormat as F;
    let names = |r: &str, f: F, c: usize| channel_names(r, f, c);
    assert_eq!(names("light0.depth", F::Depth32Float, 1), ["depth"]);
    assert_eq!(names("light2.linear", F::R32Float, 1), ["z"]);
    assert_eq!(names("light0.vsm", F::Rg32Float, 2), ["z", "z2"]);
    assert_eq!(
        names("light0.vsm.blur_h", F::Rgba16Float, 4),
        ["z", "z2"],
        "f16 padding dropped"
    );
    assert_eq!(names("light0.evsm", F::Rg32Float, 2), ["pos", "pos2"]);
    assert_eq!(
        names("light0.evsm4", F::Rgba32Float, 4),
        ["pos", "pos2", "neg", "neg2"]
    );
    assert_eq!(names("light0.esm.blur_v", F::R32Float, 1), ["log_exp"]);
    assert_eq!(
        names("light1.msm", F::Rgba32Float, 4),
        ["b1", "b2", "b3", "b4"]
    );
    assert_eq!(
        names("light0.csm1", F::Rgba32Float, 4),
        ["sin_3", "cos_3", "sin_4", "cos_4"]
    );
    assert_eq!(names("light0.mystery", F::Rg32Float, 2), ["c0", "c1"]);
    assert_eq!(names("not_a_light", F::R32Float, 1), ["c0"]);
    assert_eq!(dump::resource_kind("light10.vsm.blur_h"), Some("vsm"));
    assert_eq!(dump::resource_kind("lightx.vsm"), None);
}
