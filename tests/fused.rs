//! The fused encodings: each reads the rasterized depth and linearizes it itself
//! (`kernels/shared/linear_depth.wgsl`), `csm` writes up to four basis maps from one read
//! (CSSM's tables, which compute the basis in their own passes, are in `tests/csm_sat/`), and
//! the `*_blur` kernels encode and blur in one dispatch (two past `ENCODE_BLUR_TILE_RADIUS`).
//! Run through the technique's own graph builder on a perspective (spot) depth buffer with
//! NaN and ±Inf texels, every map is compared against the f64 pipeline
//! `cpu::linearize` → the technique's `cpu` encoding, and every step must count each
//! non-finite texel exactly once.

mod common;

use std::collections::HashMap;

use rand::Rng;
use shadowgraph::Light;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{read_resource_texture, submit_and_wait, write_texture};
use shadowgraph::low_level::graph::{Graph, plan, texel_bytes};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique;

/// Not a multiple of the 16 × 16 tiles, and wider than one 256-texel row workgroup, so every
/// kind of edge of the fused blurs' workgroups is crossed.
const MAP: u32 = 300;
/// f32's unit roundoff.
const U: f64 = 1.0 / (1u64 << 24) as f64;
/// The perspective linearization is five roundings (`src/stability/stages.rs`, case 7).
const LINEAR_RTOL: f64 = 5.0 * U;

/// A spot light (perspective depth) from `scenes/techniques/cssm.toml` with `shadow` as its
/// technique keys, on a `MAP`² map.
fn spot(shadow: &str) -> Light {
    spot_sized(shadow, MAP)
}

/// [`spot`] on an `n`² map.
fn spot_sized(shadow: &str, n: u32) -> Light {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/cssm.toml");
    let text = std::fs::read_to_string(&path)
        .expect("cssm.toml")
        .replace("technique = \"cssm\"\nterms = 8", shadow)
        .replace("shadow_map = 512", &format!("shadow_map = {n}"));
    let scene = Scene::parse(&path, &text).unwrap_or_else(|e| panic!("{shadow}: {e}"));
    scene.lights[0].clone()
}

/// A raw depth buffer: values spread over [0, 1] (perspective depth crowds near 1), with
/// `bad` NaN and ±Inf texels at random and three on the map's last column and row.
fn raw_depth(bad: usize) -> Vec<f32> {
    raw_depth_sized(bad, MAP)
}

/// [`raw_depth`] of an `n`² map.
fn raw_depth_sized(bad: usize, n: u32) -> Vec<f32> {
    let mut rng = common::rng(0xF05E);
    let mut raw: Vec<f32> = (0..n * n)
        .map(|_| 1.0 - rng.random_range(0.0f32..1.0).powi(3))
        .collect();
    for k in 0..bad {
        let at = rng.random_range(0..raw.len());
        raw[at] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][k % 3];
    }
    // And on the last column, the last row and the corner: a ragged tile's or row's texels
    // past the map read these at clamped coordinates, and must not count them again.
    let n = n as usize;
    raw[n / 2 * n + n - 1] = f32::NAN;
    raw[(n - 1) * n + n / 3] = f32::INFINITY;
    raw[n * n - 1] = f32::NEG_INFINITY;
    raw
}

/// Runs `light`'s graph on `raw` for `outputs` (each in its own texture, poisoned with NaN
/// first so unwritten texels show); returns them and each step's non-finite count.
fn run(light: &Light, raw: &[f32], outputs: &[String]) -> (Vec<Texels>, Vec<(String, u32)>) {
    run_in(light, raw, outputs, None)
}

/// [`run`] with the kernels in `layout` (`None`: the device's).
fn run_in(
    light: &Light,
    raw: &[f32],
    outputs: &[String],
    layout: Option<KernelLayout>,
) -> (Vec<Texels>, Vec<(String, u32)>) {
    let n = side(raw);
    let g = common::gpu();
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, light);
    let names: Vec<&str> = outputs.iter().map(String::as_str).collect();
    let plan = plan(&graph, &names).expect("plan").unaliased();
    let depth = common::upload(
        &g.device,
        &g.queue,
        "test.depth",
        (n, n),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(raw),
    );
    let imports = HashMap::from([(technique::depth_name(0), depth)]);
    let mut exec = Executor::new();
    if let Some(layout) = layout {
        exec.kernels.set_layout(layout);
    }
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = exec
        .record(&g.device, &mut enc, &plan, &imports, None)
        .expect("record");
    for name in outputs {
        let t = &out.textures[name];
        let bytes = texel_bytes(t.format()) as usize * (n * n) as usize;
        // 0xFF bytes: NaN in every float format.
        write_texture(&g.queue, t, &vec![0xFF; bytes]);
    }
    out.copy_stats(&mut enc);
    submit_and_wait(&g.device, &g.queue, enc, "fused").expect("submit");
    let maps = outputs
        .iter()
        .map(|name| {
            // Packed f16 pairs unpacked (0xFF words: two NaN halves, so the poison shows).
            let format = plan.resource(name).expect("planned").resource.format;
            let (c, v) = read_resource_texture(&g.device, &g.queue, &out.textures[name], 0, format)
                .expect("read back");
            Texels::from_f32(n as usize, n as usize, c, &v)
        })
        .collect();
    (maps, out.read_stats(&g.device).expect("stats"))
}

/// The side of the square map `raw`.
fn side(raw: &[f32]) -> u32 {
    (raw.len() as f64).sqrt().round() as u32
}

/// The f64 linear depth of `raw` for `light`, and the texels it replaces.
fn linear(light: &Light, raw: &[f32]) -> (Texels, u32) {
    let n = side(raw) as usize;
    let (z, replaced) = cpu::linearize::linearize(raw, true, light.near.into(), light.far.into());
    let t = Texels {
        width: n,
        height: n,
        channels: 1,
        data: z,
    };
    (t, replaced)
}

/// Channels `first .. first + n` of every texel.
fn channels(t: &Texels, first: usize, n: usize) -> Vec<f64> {
    t.data
        .chunks(t.channels)
        .flat_map(|c| c[first..first + n].to_vec())
        .collect()
}

/// Every step of the run counted the `want` non-finite texels once.
fn assert_counted(what: &str, stats: &[(String, u32)], steps: usize, want: u32) {
    assert!(want > 0, "{what}: the input has no non-finite texel");
    assert_eq!(stats.len(), steps, "{what}: steps that counted: {stats:?}");
    for (step, n) in stats {
        assert_eq!(*n, want, "{what}: {step} counted {n}");
    }
}

#[test]
fn fused_encodings_match_linearize_then_encode() {
    let raw = raw_depth(12);
    // (technique keys, encoded map, f64 encoding of the linear map, atol, rtol). The linear
    // depth carries LINEAR_RTOL; a moment z^k carries k times that plus its own roundings.
    type Encoding = fn(&Texels) -> Texels;
    let cases: [(&str, &str, Encoding, f64, f64); 4] = [
        // VSM's derivative term ¼(dx² + dy²) of differences of two linear depths: ≤ ½·2·(2·5u)
        // absolute for |dx| ≤ 1.
        (
            "technique = \"vsm\"\nformat = \"f32\"",
            "light0.vsm",
            cpu::vsm::vsm,
            10.0 * U,
            2.0 * LINEAR_RTOL + 3.0 * U,
        ),
        (
            "technique = \"msm\"\nformat = \"f32\"",
            "light0.msm",
            |t| cpu::msm::msm(t, false),
            0.0,
            4.0 * LINEAR_RTOL + 4.0 * U,
        ),
        // exp(c (2z − 1)) with c = 5: the argument's error c·2·5u·z, then SPIR-V's exp
        // (3 + 2|x|) ULP; the square doubles both.
        (
            "technique = \"evsm4\"\nformat = \"f32\"\nexponent_pos = 5.0\nexponent_neg = 5.0",
            "light0.evsm",
            |t| cpu::evsm::evsm(t, 5.0, 5.0),
            0.0,
            2.0 * (10.0 * LINEAR_RTOL + 13.0 * U),
        ),
        (
            "technique = \"esm\"\nexponent = 80.0",
            "light0.esm",
            |t| cpu::esm::esm(t, 80.0),
            0.0,
            LINEAR_RTOL + U,
        ),
    ];
    // VSM and EVSM2 in f16, packed: one f16 store of the moments (2⁻¹⁰ relative, 2⁻¹⁴
    // absolute: see `fused_blurs_match_encode_then_blur`).
    let f16: [(&str, &str, Encoding, f64, f64); 2] = [
        (
            "technique = \"vsm\"\nformat = \"f16\"",
            "light0.vsm",
            cpu::vsm::vsm,
            10.0 * U + 2f64.powi(-14),
            2.0 * LINEAR_RTOL + 3.0 * U + 2f64.powi(-10),
        ),
        (
            "technique = \"evsm2\"\nformat = \"f16\"\nexponent_pos = 5.0",
            "light0.evsm",
            |t| {
                let m = cpu::evsm::evsm(t, 5.0, 5.0);
                let data = m.data.chunks(m.channels).flat_map(|c| c[..2].to_vec());
                Texels {
                    channels: 2,
                    data: data.collect(),
                    ..m
                }
            },
            2f64.powi(-14),
            2.0 * (10.0 * LINEAR_RTOL + 13.0 * U) + 2f64.powi(-10),
        ),
    ];
    for (shadow, map, encode, atol, rtol) in cases.into_iter().chain(f16) {
        let light = spot(shadow);
        let (maps, stats) = run(&light, &raw, &[map.to_string()]);
        let (lin, replaced) = linear(&light, &raw);
        let want = encode(&lin);
        let got = &maps[0];
        let n = want.channels;
        let got: Vec<f32> = channels(got, 0, n).iter().map(|&v| v as f32).collect();
        common::assert_close(map, &got, &want.data, atol, rtol);
        assert_counted(map, &stats, 1, replaced);
    }
}

#[test]
fn csm_writes_basis_maps_from_one_read() {
    let raw = raw_depth(9);
    let terms = 7;
    // Blurred CSM stores its maps (through a table, as CSSM, they are never stored).
    let light = spot(&format!(
        "technique = \"csm\"\nterms = {terms}\nfilter = \"blur\""
    ));
    let basis = technique::csm_maps(terms) as usize;
    let z_maps = 0;
    let names: Vec<String> = (0..basis)
        .map(|k| format!("light0.csm{k}"))
        .chain((0..z_maps).map(|k| format!("light0.csm_z{k}")))
        .collect();
    let (maps, stats) = run(&light, &raw, &names);
    let (lin, replaced) = linear(&light, &raw);
    let (sin_cos, z_seq) = (cpu::csm::csm(&lin, terms), cpu::csm_z::csm_z(&lin, terms));
    // Vulkan's sin/cos: 2⁻¹¹ absolute on [−π, π]; the linear depth's error moves the argument
    // by c_M·5u (c_M = 13π), and the CSM-Z product adds a rounding.
    let atol = 2f64.powi(-11) + 13.0 * std::f64::consts::PI * LINEAR_RTOL + U;
    for (k, (name, got)) in names.iter().zip(&maps).enumerate() {
        let (reference, first) = match k.checked_sub(basis) {
            None => (&sin_cos, 4 * k),
            Some(z) => (&z_seq, 4 * z),
        };
        let n = got.channels.min(reference.channels - first);
        let got32: Vec<f32> = channels(got, 0, n).iter().map(|&v| v as f32).collect();
        common::assert_close(name, &got32, &channels(reference, first, n), atol, 0.0);
        // Channels past the sequence are zeros.
        assert!(
            channels(got, n, got.channels - n).iter().all(|&v| v == 0.0),
            "{name}: padding channels are not zero"
        );
    }
    // 4 basis maps: one dispatch of four outputs.
    assert_eq!(basis, 4);
    assert_counted("csm", &stats, 1, replaced);
}

/// One encoding through a fused blur: its technique keys, its encoded map, the row kernel of its
/// wide maps, the f64 reference at (radius, σ), the encoding's atol and rtol as in
/// `fused_encodings_match_linearize_then_encode`, and whether its two moments are stored in f16.
#[derive(Clone, Copy)]
struct BlurCase {
    shadow: &'static str,
    encoded: &'static str,
    row_kernel: &'static str,
    reference: fn(&Texels, f64, f64) -> Texels,
    atol: f64,
    rtol: f64,
    f16: bool,
}

impl BlurCase {
    /// Its tolerance after `stores` stores: f16 adds, at each, a whole ulp (Vulkan lets the
    /// conversion round toward zero), 2⁻¹⁰ relative, and a value below f16's smallest normal may
    /// be flushed, 2⁻¹⁴ absolute (EVSM's squared moments reach e⁻¹⁰ ≈ 4.5·10⁻⁵).
    fn tolerance(&self, stores: f64) -> (f64, f64) {
        if self.f16 {
            (
                self.atol + 2f64.powi(-14),
                self.rtol + stores * 2f64.powi(-10),
            )
        } else {
            (self.atol, self.rtol)
        }
    }
}

/// VSM and EVSM2 in f32 and f16 (packed two to an r32uint word), EVSM4 and MSM in f32.
fn blur_cases() -> [BlurCase; 6] {
    use shadowgraph::BlurKernel;
    let vsm = BlurCase {
        shadow: "technique = \"vsm\"\nformat = \"f32\"",
        encoded: "light0.vsm",
        row_kernel: "vsm_blur_row",
        reference: |t, r, s| cpu::vsm_blur::vsm_blur(t, r, s, BlurKernel::Gaussian),
        atol: 10.0 * U,
        rtol: 2.0 * LINEAR_RTOL + 3.0 * U,
        f16: false,
    };
    let evsm2 = BlurCase {
        shadow: "technique = \"evsm2\"\nformat = \"f32\"\nexponent_pos = 5.0",
        encoded: "light0.evsm",
        row_kernel: "evsm_blur_row",
        reference: |t, r, s| cpu::evsm_blur::evsm_blur(t, [5.0, 5.0], r, s, BlurKernel::Gaussian),
        atol: 0.0,
        rtol: 2.0 * (10.0 * LINEAR_RTOL + 13.0 * U),
        f16: false,
    };
    [
        vsm,
        evsm2,
        BlurCase {
            shadow: "technique = \"evsm4\"\nformat = \"f32\"\nexponent_pos = 5.0\nexponent_neg = 5.0",
            ..evsm2
        },
        BlurCase {
            shadow: "technique = \"msm\"\nformat = \"f32\"",
            encoded: "light0.msm",
            row_kernel: "msm_blur_row",
            reference: |t, r, s| cpu::msm_blur::msm_blur(t, false, r, s, BlurKernel::Gaussian),
            atol: 0.0,
            rtol: 4.0 * LINEAR_RTOL + 4.0 * U,
            f16: false,
        },
        BlurCase {
            shadow: "technique = \"vsm\"\nformat = \"f16\"",
            f16: true,
            ..vsm
        },
        BlurCase {
            shadow: "technique = \"evsm2\"\nformat = \"f16\"\nexponent_pos = 5.0",
            f16: true,
            ..evsm2
        },
    ]
}

/// The encodings fused into the blur (`vsm_blur`, `evsm_blur`, `msm_blur`) against the f64
/// composition of the independent references, encoding then both blur passes
/// (`cpu::vsm_blur` and its siblings), on the random perspective depth with non-finite texels:
/// at radius 3 and 7 (one dispatch: a tile of 24² outputs for two channels, 16² for four, in
/// workgroup memory; at 7, the largest the tile takes, two channels fill six blocks of encoded
/// texels and four of horizontal sums, and the 67² map leaves ragged tiles) and 12 (past the
/// tile's 7: the encoding fused into the horizontal pass, then `blur`'s vertical pass).
#[test]
fn fused_blurs_match_encode_then_blur() {
    let raw = raw_depth(12);
    for (radius, steps) in [(3u32, 1usize), (4, 1), (5, 1), (7, 1), (12, 1)] {
        let sigma = f64::from(radius) / 2.0;
        let filter =
            format!("\nfilter = \"blur\"\nfilter_radius = {radius}\nfilter_sigma = {sigma}");
        let stores = if radius > 8 { 2.0 } else { 1.0 };
        for c in blur_cases() {
            let (shadow, encoded) = (c.shadow, c.encoded);
            let (atol, rtol) = c.tolerance(stores);
            let light = spot(&format!("{shadow}{filter}"));
            // f16 two moments are stored packed, 4 bytes a texel, not in rgba16float.
            assert_eq!(
                technique::maps_packed(&light),
                c.f16,
                "{shadow}: packed maps"
            );
            let map = format!("{encoded}.blur");
            let what = format!("{map} (r = {radius}, {shadow})");
            let tol = (atol, rtol);
            check_blur(&c, &light, &raw, &map, radius, tol, steps, &what, &ALL);
        }
    }
}

/// Every kernel layout (`exec::KernelLayout`): a GPU's tile in workgroup memory, a CPU driver's
/// strips, the redesign's columns walked down strips 240 outputs wide and 64 tall (a 300² map
/// has a ragged strip and a ragged last workgroup of each); the row path's invocations all at
/// once (the GPU's and the redesign's) or CPU_LANES at a time.
const ALL: [KernelLayout; 3] = [KernelLayout::Gpu, KernelLayout::Cpu, KernelLayout::Redesign];

/// The layouts a device may default to (where the redesign runs the GPU's kernels).
const SHIPPED: [KernelLayout; 2] = [KernelLayout::Gpu, KernelLayout::Cpu];

/// Runs `light`'s graph for `map` ([`run_in`]) in each of `layouts` and compares it with
/// `c`'s f64 reference (encoding, then both blur passes at `radius`, σ = r/2) within the
/// encoding's `tolerance` (atol, rtol) plus the blur's own, and its counts of non-finite
/// texels with `steps` counting steps.
#[expect(
    clippy::too_many_arguments,
    reason = "a case, its light, input, map, radius, tolerance, counting steps, name and layouts"
)]
fn check_blur(
    c: &BlurCase,
    light: &Light,
    raw: &[f32],
    map: &str,
    radius: u32,
    (atol, rtol): (f64, f64),
    steps: usize,
    what: &str,
    layouts: &[KernelLayout],
) {
    let (lin, replaced) = linear(light, raw);
    let want = (c.reference)(&lin, radius.into(), f64::from(radius) / 2.0);
    for &layout in layouts {
        let what = format!("{what}, {} layout", layout.name());
        let (maps, stats) = run_in(light, raw, &[map.to_string()], Some(layout));
        let got = &maps[0];
        let n = want.channels.min(got.channels);
        let got: Vec<f32> = channels(got, 0, n).iter().map(|&v| v as f32).collect();
        // The moments of one sign per channel, weighted by positive f32 weights (each rounded
        // once, u) summing to 1: a pass's sum of r + 1 terms (the centre and r symmetric
        // pairs, each pair one more addition; the strips' pairs past r add exact zeros) is off
        // by at most (r + 3)·u of its value, and two passes by twice that, on top of the
        // encoding's own error, which the normalized weights carry through unchanged.
        let blur_rtol = 2.0 * (f64::from(radius) + 3.0) * U;
        common::assert_close(&what, &got, &channels(&want, 0, n), atol, rtol + blur_rtol);
        assert_counted(&what, &stats, steps, replaced);
    }
}

/// The row kernels past the tile's radius 7 on a map wide enough for them (1100²:
/// `vsm_blur_row`, 1024 outputs a workgroup in runs of 4; `evsm_blur_row` and `msm_blur_row`,
/// 512 in runs of 2; the last row
/// workgroup of each row ragged, clipped to the map), then `blur`'s vertical pass, at radius 12
/// and 32, VSM and EVSM2 in f32 and f16 (packed), EVSM4 and MSM in f32, against the f64 encoding
/// then both blur passes; tolerances as `fused_blurs_match_encode_then_blur`'s (whose 300² map
/// keeps the tile kernels' own rows). The plan's kernels are checked.
#[test]
fn row_kernels_span_row_workgroups() {
    const WIDE: u32 = 1100;
    let raw = raw_depth_sized(5, WIDE);
    for radius in [12u32, 32] {
        let sigma = f64::from(radius) / 2.0;
        for c in blur_cases() {
            let (shadow, encoded, kernel) = (c.shadow, c.encoded, c.row_kernel);
            let light = spot_sized(
                &format!(
                    "{shadow}\nfilter = \"blur\"\nfilter_radius = {radius}\nfilter_sigma = {sigma}"
                ),
                WIDE,
            );
            let what = format!("{shadow} r = {radius} on {WIDE}²");
            let map = format!("{encoded}.blur");
            let mut graph = Graph::default();
            technique::add_light_nodes(&mut graph, 0, &light);
            let kernels: Vec<&str> = plan(&graph, &[map.as_str()])
                .expect("plan")
                .steps
                .iter()
                .map(|s| s.node.kernel.as_str())
                .collect();
            assert_eq!(kernels, [kernel, "blur"], "{what}");
            // Two stores, f16 in the packed cases.
            // The redesign layout's row pass is the GPU's.
            let tol = c.tolerance(2.0);
            check_blur(&c, &light, &raw, &map, radius, tol, 1, &what, &SHIPPED);
        }
    }
}

/// The redesign layout's strips (`kernels/shared/encode_blur_columns.wgsl`) at their edges: a
/// 129² map, whose strip's last workgroup has one output row (at radius 1 it stores it among
/// the zeros pushed past its 3 encoded rows), and a 241² map, whose second strip is one column
/// wide; VSM (whose columns share their depths through workgroup memory), EVSM4 and MSM at
/// radius 1 and 7, against the f64 references within `fused_blurs_match_encode_then_blur`'s
/// tolerances, each non-finite texel (three on the last column and row) counted once.
#[test]
fn redesign_strips_cover_ragged_edges() {
    for n in [129u32, 241] {
        let raw = raw_depth_sized(4, n);
        for radius in [1u32, 7] {
            let sigma = f64::from(radius) / 2.0;
            let four = blur_cases().into_iter().take(4);
            for c in four.filter(|c| !c.shadow.contains("evsm2")) {
                let filter = format!("filter = \"blur\"\nfilter_radius = {radius}");
                let shadow = format!("{}\n{filter}\nfilter_sigma = {sigma}", c.shadow);
                let light = spot_sized(&shadow, n);
                let map = format!("{}.blur", c.encoded);
                let what = format!("{map} (r = {radius}, {n}², {})", c.shadow);
                let redesign = [KernelLayout::Redesign];
                let tol = c.tolerance(1.0);
                check_blur(&c, &light, &raw, &map, radius, tol, 1, &what, &redesign);
            }
        }
    }
}

/// The strips' window (`STRIP_RADIUS`, a pipeline constant each fused tile node sets from its
/// radius through `// #override`): 9 texels up to radius 4, 15 past it, for every fused
/// kernel's tile node. No GPU: the values the executor would compile the node with.
#[test]
fn strip_windows_follow_each_nodes_radius() {
    let mut cache = shadowgraph::low_level::exec::KernelCache::default();
    for (shadow, map) in [
        ("technique = \"vsm\"\nformat = \"f32\"", "light0.vsm.blur"),
        (
            "technique = \"evsm4\"\nformat = \"f32\"\nexponent_pos = 5.0\nexponent_neg = 5.0",
            "light0.evsm.blur",
        ),
        ("technique = \"msm\"\nformat = \"f32\"", "light0.msm.blur"),
    ] {
        for (radius, want) in [(1u32, 4.0), (4, 4.0), (5, 7.0), (7, 7.0)] {
            let light = spot(&format!(
                "{shadow}\nfilter = \"blur\"\nfilter_radius = {radius}\nfilter_sigma = 1.0"
            ));
            let mut graph = Graph::default();
            technique::add_light_nodes(&mut graph, 0, &light);
            let node = graph
                .nodes
                .iter()
                .find(|n| n.name == map)
                .unwrap_or_else(|| panic!("{map}: no node"));
            let values = cache
                .node_constants(node.kernel.name(), &node.name, &node.params)
                .expect("node constants");
            assert_eq!(
                values,
                [("STRIP_RADIUS".to_string(), want)],
                "{map} at r = {radius}"
            );
        }
    }
}
