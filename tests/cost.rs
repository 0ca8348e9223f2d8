//! The cost model (`shadowgraph plan`'s traffic and fetches) against hand counts, and its
//! declarations against the code they describe: every compute kernel declares what each of
//! its bindings moves, every fetching function declares its fetches, and the shading kernel,
//! rewritten so that every texture fetch adds one to a per-pixel counter, fetches exactly what
//! the declarations say. Structural costs are exact, so the tolerances are float rounding.

mod common;

use std::path::{Path, PathBuf};

use shadowgraph::low_level::graph::cost;
use shadowgraph::low_level::graph::cost::fetches::Fetches;
use shadowgraph::low_level::render::{RenderOptions, Renderer, plan_lights};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::{kernels, technique};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn scene(name: &str) -> Scene {
    Scene::load(scene_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// One node of a hand count: name suffix, dispatches, bytes read and written per texel.
type Row = (&'static str, u32, f64, f64);

/// Checks light 0's traffic in scene file `name` against `rows` (in plan order) and the totals.
fn assert_traffic(name: &str, rows: &[Row], total: f64, ideal: f64) {
    assert_scene_traffic(name, &scene(name), rows, total, ideal);
}

/// [`assert_traffic`] of the loaded scene `s` (`name` labels failures).
fn assert_scene_traffic(name: &str, s: &Scene, rows: &[Row], total: f64, ideal: f64) {
    let plan = plan_lights(&s.lights).expect("plan").plan;
    let texels = cost::map_texels(&plan, 0);
    let nodes = cost::light_traffic(&plan, 0).expect("traffic");
    let got: Vec<(String, u32, f64, f64)> = nodes
        .iter()
        .map(|(n, t)| {
            (
                n.name.clone(),
                t.dispatches,
                t.read / texels,
                t.written / texels,
            )
        })
        .collect();
    assert_eq!(got.len(), rows.len(), "{name}: nodes {got:#?}");
    for (g, r) in got.iter().zip(rows) {
        // Dyadic fractions of the map's texels: exact in f64.
        let same = g.0.ends_with(r.0) && g.1 == r.1 && g.2 == r.2 && g.3 == r.3;
        assert!(same, "{name}: got {g:?}, hand count {r:?}");
    }
    let sum: f64 = got.iter().map(|g| g.2 + g.3).sum();
    assert_eq!(sum, total, "{name}: total B/texel");
    assert_eq!(
        cost::ideal_bytes(&plan, 0),
        ideal,
        "{name}: one read + one write"
    );
}

/// `vsm.toml`: a 512² map, f32 moments, a Gaussian blur of radius 3: one dispatch, the
/// encoding fused into both blur passes (the target: ≤ 2 dispatches, ≤ 28 B/texel).
#[test]
fn vsm_with_blur_moves_what_the_hand_count_says() {
    assert_traffic(
        "techniques/vsm.toml",
        &[
            // `vsm_blur` reads the depth32float buffer itself: ⌈512 / 24⌉² = 22² tiles of 24 × 24
            // outputs, each with a halo of r + 1 = 4 texels each side, (24 + 8)² × 4 B a tile
            // (the last row and column of tiles cover 8 texels of the map); rg32float out once.
            (
                "vsm.blur",
                1,
                22.0 * 22.0 * 32.0 * 32.0 * 4.0 / (512.0 * 512.0),
                8.0,
            ),
        ],
        15.5625,
        // one read of the depth (4 B) + one write of the blurred moments (8 B)
        12.0,
    );
}

/// `vsm.toml` with a blur of radius 12, past the one-dispatch tile's 8: two dispatches, the
/// encoding fused into the horizontal pass, then `blur`'s vertical pass.
#[test]
fn vsm_with_a_wide_blur_takes_two_dispatches() {
    let path = scene_path("techniques/vsm.toml");
    let text = std::fs::read_to_string(&path)
        .expect("vsm.toml")
        .replace("filter_radius = 3", "filter_radius = 12")
        .replace("filter_sigma = 1.5", "filter_sigma = 6");
    let s = Scene::parse(&path, &text).expect("parse");
    assert_scene_traffic(
        "vsm.toml at r = 12",
        &s,
        &[
            // A row workgroup of 512 outputs (two an invocation) loads three rows (the
            // derivatives' neighbours) of 512 + 2 × 13 depths: 1614/512 × 4 B; rg32float out.
            ("vsm.blur_h", 1, 12.609375, 8.0),
            // A column workgroup loads 64 columns of 32 + 2 × 12 texels: 56/32 × 8 B.
            ("vsm.blur", 1, 14.0, 8.0),
        ],
        42.609375,
        12.0,
    );
}

/// `vsm_mips.toml`: a 512² map, a mip chain of 10 levels, up to six per dispatch.
#[test]
fn vsm_with_mips_moves_every_level() {
    let level = |k: i32| 8.0 / 4f64.powi(k); // rg32float bytes of level k per level-0 texel
    assert_traffic(
        "techniques/vsm_mips.toml",
        &[
            // The depth32float buffer with the derivatives' halo (as in `vsm.toml`).
            ("vsm", 1, 5.0, 8.0),
            // Dispatch 1 reads the moments and writes levels 0–6; dispatch 2 reads level 6
            // and writes levels 7–9.
            ("vsm.mips", 2, 8.0 + level(6), (0..10).map(level).sum()),
        ],
        13.0 + 8.0 + level(6) + (0..10).map(level).sum::<f64>(),
        4.0 + (0..10).map(level).sum::<f64>(),
    );
}

/// `vsm_f16.toml`: VSM's two moments in f16, a box blur of radius 2.5 (3 taps each side): the
/// fused kernel as in `vsm.toml`, the moments written packed, two f16 in one r32uint word.
#[test]
fn vsm_f16_writes_four_bytes_a_texel() {
    assert_traffic(
        "techniques/vsm_f16.toml",
        &[
            // The depth tiles with their halo of 4 (7.5625 B, as in `vsm.toml`); 4 B out, not
            // the 8 of rgba16float (before the packing) or rg32float.
            ("vsm.blur", 1, 7.5625, 4.0),
        ],
        11.5625,
        // one read of the depth (4 B) + one write of the packed moments (4 B)
        8.0,
    );
    let plan = plan_lights(&scene("techniques/vsm_f16.toml").lights)
        .expect("plan")
        .plan;
    let blurred = plan.resource("light0.vsm.blur").expect("planned");
    assert_eq!(blurred.resource.format, shadowgraph::PACKED_F16X2);
    assert_eq!(blurred.bytes, 512 * 512 * 4);
}

/// `vsm_mips.toml` in f16: every level of the chain packed, 4 B a texel.
#[test]
fn vsm_f16_mips_move_half_the_bytes() {
    let path = scene_path("techniques/vsm_mips.toml");
    let text = std::fs::read_to_string(&path)
        .expect("vsm_mips.toml")
        .replace("filter = \"mips\"", "format = \"f16\"\nfilter = \"mips\"");
    let s = Scene::parse(&path, &text).expect("parse");
    let level = |k: i32| 4.0 / 4f64.powi(k); // packed bytes of level k per level-0 texel
    assert_scene_traffic(
        "vsm_mips.toml in f16",
        &s,
        &[
            ("vsm", 1, 5.0, 4.0),
            ("vsm.mips", 2, 4.0 + level(6), (0..10).map(level).sum()),
        ],
        9.0 + 4.0 + level(6) + (0..10).map(level).sum::<f64>(),
        4.0 + (0..10).map(level).sum::<f64>(),
    );
}

/// Side of the SAT's tiles (`shadowgraph::low_level::sat::SAT_TILE`).
const SAT_TILE: f64 = 32.0;

/// A summed-area table at 512² of a representation of `src` bytes per texel into a table of
/// `table` bytes per texel, in 32 × 32 tiles (16 × 16 of them): the three passes.
fn sat_rows(src: f64, table: f64) -> [Row; 3] {
    // A tile's last row and last column (pass 1), and as many carries (pass 2): each one
    // table texel per 32 map texels, twice.
    let edges = 2.0 * table / SAT_TILE;
    [
        // Read the representation, write the tiles' edge sums.
        ("sat.tile_sums", 1, src, edges),
        // Read the edge sums, write the carries.
        ("sat.carries", 1, edges, edges),
        // Read the representation again and 32 carries of either kind per tile (the same
        // bytes as the carries); write the table.
        ("sat", 1, src + edges, table),
    ]
}

/// `msm_sat.toml`: a 512² map, 16-bit quantized moments (rgba16float), a fixed-point table.
/// The moments are computed from the depth in the table's own tile passes (one layer of
/// `sat::layers`, `technique::add_msm_table`), never stored: the target, at most 3
/// dispatches after the encode and 48 B/texel, with no encode at all.
#[test]
fn msm_with_sat_moves_what_the_hand_count_says() {
    // Each tile pass reads the depth32float buffer (4 B); the edges and carries as
    // `sat_rows`'s.
    let mut rows = sat_rows(4.0, 16.0);
    rows[0].0 = "msm.sat.tile_sums";
    rows[1].0 = "msm.sat.carries";
    rows[2].0 = "msm.sat.0";
    // 5 + 2 + 21: it was 48 with the stored map (12 + 9 + 2 + 25).
    assert_traffic("techniques/msm_sat.toml", &rows, 28.0, 4.0 + 16.0);
}

/// `cssm.toml`: M = 8 terms at 512². With the default moment search, four CSM maps and the
/// power moments' map; with the paper's CSM-Z search, the four CSM maps and five CSM-Z maps
/// (four of four channels, the 17th channel alone). Never stored: their tables (rgba32uint)
/// are built as one layered table (`sat::layers`), whose tile passes compute each layer's basis
/// from the depth (linearize fused), whose edges are stacked, and whose tables lie interleaved
/// in one texture (512² × 5 or × 9 is within 8192 texels a side: `basis_interleave`), written
/// by one pass-3 dispatch. The target: at most 12 dispatches and 300 B/texel.
#[test]
fn cssm_moves_what_the_hand_count_says() {
    // A tile's last row and last column (pass 1) and as many carries (pass 2), one rgba32uint
    // texel (16 B) per 32 map texels each, twice, for every layer.
    let edges = |layers: f64| layers * 2.0 * 16.0 / SAT_TILE;
    // Pass 3 reads 32 carries of either kind per tile and layer (1/32 of a texel each, 16 B).
    let carries = |maps: f64| maps * 2.0 * 16.0 / SAT_TILE;

    // Moments: five layers, one pass-3 dispatch.
    let rows: Vec<Row> = vec![
        // The depth32float buffer once a layer; the stacked edges.
        ("csm.sat.tile_sums", 1, 5.0 * 4.0, edges(5.0)),
        ("csm.sat.carries", 1, edges(5.0), edges(5.0)),
        // A workgroup a tile and layer: the depth again once a layer, its carries, the
        // interleaved tables.
        ("csm.sat.0", 1, 5.0 * 4.0 + carries(5.0), 5.0 * 16.0),
    ];
    // 2 × 20 of depth, 3 × 5 of edges and carries written and read in pass 2, 5 of carries
    // read in pass 3, 80 of tables.
    let total = 40.0 + 15.0 + 5.0 + 80.0;
    assert!(rows.len() <= 12 && total <= 300.0, "the issue's target");
    // One read of the depth, one write of five rgba tables.
    assert_traffic("techniques/cssm.toml", &rows, total, 4.0 + 5.0 * 16.0);

    // CSM-Z: nine layers, one pass-3 dispatch; the 17th channel's table, interleaved with
    // rgba tables, is as wide (16 B, where alone it was an r32uint table of 4).
    let path = scene_path("techniques/cssm.toml");
    let text = std::fs::read_to_string(&path).expect("cssm.toml").replace(
        "technique = \"cssm\"",
        "technique = \"cssm\"\nblocker_search = \"csm_z\"",
    );
    let s = Scene::parse(&path, &text).expect("parse");
    let rows: Vec<Row> = vec![
        ("csm.sat.tile_sums", 1, 9.0 * 4.0, edges(9.0)),
        ("csm.sat.carries", 1, edges(9.0), edges(9.0)),
        ("csm.sat.0", 1, 9.0 * 4.0 + carries(9.0), 9.0 * 16.0),
    ];
    // 2 × 36 of depth, 3 × 9 of edges and carries written and read in pass 2, 9 of carries
    // read in pass 3, 144 of tables.
    let total = 72.0 + 27.0 + 9.0 + 144.0;
    assert!(rows.len() <= 12 && total <= 300.0, "the issue's target");
    // One read of the depth, one write of the texture of nine rgba tables.
    assert_scene_traffic("cssm.toml, csm_z", &s, &rows, total, 4.0 + 9.0 * 16.0);
}

/// The hand counts of the shading fetches: one bilinear lookup (4 loads) for VSM with a blur,
/// one table lookup (16 loads: the 4 × 4 texels around the rectangle's corners) for MSM with
/// a table, and for CSSM with M = 8 the power moments' table over the search square snapped
/// outward (4 loads) plus the ⌈M/2⌉ = 4 CSM tables and the moments' table again (the two-depth
/// resolve's blockers over the filter square) over the filter square with its edges at the
/// nearest texel edges (4 loads each): 6 × 4 = 24 (20 with `resolve = "two_depth_search"`;
/// with the CSM-Z search, the 4 CSM and ⌈(2M + 1)/4⌉ = 5 CSM-Z tables over the search square
/// too and no second read: 13 × 4 = 52); VSSM and soft MSM one table, the search square in
/// 2 × 2 cells (the 3 × 3 corners: 9 loads) and the exact filter square (16 loads from a
/// fixed-point table, 4 filtered fetches from an f32 one): 9 + 4 for vssm.toml's f32 table,
/// 9 + 16 for msm_soft.toml's fixed-point one; PCSS 16 blocker + 32 filter taps; anisotropic mips 8 taps of 8 loads
/// (trilinear).
#[test]
fn shading_fetches_match_the_hand_counts() {
    for (name, fetches) in [
        ("techniques/vsm.toml", 4.0),
        // Packed f16 moments: the same four loads, each one word unpacked.
        ("techniques/vsm_f16.toml", 4.0),
        ("techniques/msm_sat.toml", 16.0),
        ("techniques/cssm.toml", 24.0),
        ("techniques/vssm.toml", 13.0),
        ("techniques/msm_soft.toml", 25.0),
        ("sphere_on_plane.toml", 48.0),
        ("techniques/vsm_mips_aniso.toml", 64.0),
    ] {
        let s = scene(name);
        let got = shadowgraph::low_level::cli::shading_fetches(&s.lights).expect("fetches");
        assert_eq!(got, [fetches], "{name}");
    }
    let path = scene_path("techniques/cssm.toml");
    let text = std::fs::read_to_string(&path).expect("cssm.toml").replace(
        "technique = \"cssm\"",
        "technique = \"cssm\"\nblocker_search = \"csm_z\"",
    );
    let s = Scene::parse(&path, &text).expect("parse");
    let got = shadowgraph::low_level::cli::shading_fetches(&s.lights).expect("fetches");
    assert_eq!(got, [52.0], "cssm.toml, csm_z");
    let text = std::fs::read_to_string(&path).expect("cssm.toml").replace(
        "technique = \"cssm\"",
        "technique = \"cssm\"\nresolve = \"two_depth_search\"",
    );
    let s = Scene::parse(&path, &text).expect("parse");
    let got = shadowgraph::low_level::cli::shading_fetches(&s.lights).expect("fetches");
    assert_eq!(got, [20.0], "cssm.toml, two_depth_search");
}

/// `plan` prints each node's traffic, the closing total and the shading fetches.
#[test]
fn plan_prints_traffic_and_fetches() {
    let text =
        shadowgraph::low_level::cli::plan(&scene_path("techniques/vsm.toml"), false).expect("plan");
    for needle in [
        "traffic per texel of the 512² map:",
        "reads    7.56 B, writes    8.00 B",
        "total: 1 dispatch, 15.56 B/texel (one read + one write of the result: 12.00 B/texel)",
        "shade: vsm 4 fetches/pixel",
    ] {
        assert!(text.contains(needle), "`{needle}` missing:\n{text}");
    }
    let text = shadowgraph::low_level::cli::plan(&scene_path("techniques/vsm_f16.toml"), false)
        .expect("plan");
    for needle in [
        "light0.vsm.blur          R32Uint f16x2    512x512      1.0 MiB",
        "reads    7.56 B, writes    4.00 B",
        "total: 1 dispatch, 11.56 B/texel (one read + one write of the result: 8.00 B/texel)",
        "memory: 1.0 MiB in 1 pooled texture(s)",
    ] {
        assert!(text.contains(needle), "`{needle}` missing:\n{text}");
    }
}

/// A point light's atlas is one map to the graph: `point_vsm.toml`'s six 512² faces are a
/// 1536×1024 texture, VSM with a radius-3 blur moves the same bytes per texel as on a square
/// map (the 16 × 16 tiles divide 1536 and 1024), and `plan` names the atlas's shape.
#[test]
fn a_point_lights_atlas_is_planned_like_one_map() {
    assert_traffic(
        "techniques/point_vsm.toml",
        // 64 × 43 tiles of 24² outputs over the 1536 × 1024 atlas, (24 + 8)² depths each.
        &[(
            "vsm.blur",
            1,
            64.0 * 43.0 * 32.0 * 32.0 * 4.0 / (1536.0 * 1024.0),
            8.0,
        )],
        64.0 * 43.0 * 32.0 * 32.0 * 4.0 / (1536.0 * 1024.0) + 8.0,
        12.0,
    );
    let plan = plan_lights(&scene("techniques/point_vsm.toml").lights)
        .expect("plan")
        .plan;
    assert_eq!(cost::map_dims(&plan, 0), (1536, 1024));
    let text = shadowgraph::low_level::cli::plan(&scene_path("techniques/point_vsm.toml"), false)
        .expect("plan");
    for needle in [
        "light 0: point, vsm shadows, six 512² faces, guard band 5 texels (90° cores of 502²)",
        "light0.depth             Depth32Float    1536x1024",
        "traffic per texel of the 1536×1024 map:",
        "total: 1 dispatch, 15.17 B/texel",
    ] {
        assert!(text.contains(needle), "`{needle}` missing:\n{text}");
    }
}

/// The resolved WGSL of kernel `name` (the shading kernel with a block of every technique).
fn resolved(name: &str) -> String {
    let generated = (name == "shade").then(|| {
        let s = scene("two_lights.toml");
        technique::shading_block(&s.lights)
    });
    kernels::resolve(name, generated.as_deref()).expect("resolve")
}

/// Every compute kernel in `kernels/` declares every texture and storage buffer it binds, so
/// a kernel added without its `// #traffic` lines fails here, naming the binding.
#[test]
fn every_compute_kernel_declares_its_traffic() {
    let mut checked = Vec::new();
    let mut failures = Vec::new();
    for s in kernels::SOURCES.iter().filter(|s| !s.name.contains('/')) {
        let (_, reflection) = kernels::reflect(s.name, &resolved(s.name)).expect("reflect");
        if !reflection.stages.contains(wgpu::ShaderStages::COMPUTE) {
            continue;
        }
        match cost::check_declarations(s.name, s.text, &reflection) {
            Ok(_) => checked.push(s.name),
            Err(e) => failures.push(e.to_string()),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(checked.len() >= 17, "{checked:?}");
    // Negative control: the blur without its `src` line is named.
    let blur = kernels::source("blur").expect("blur");
    let (_, reflection) = kernels::reflect("blur", &resolved("blur")).expect("reflect");
    let stripped: String = blur
        .lines()
        .filter(|l| !l.starts_with("// #traffic src"))
        .map(|l| format!("{l}\n"))
        .collect();
    let e = cost::check_declarations("blur", &stripped, &reflection).unwrap_err();
    assert!(e.to_string().contains("binding `src`"), "{e}");
}

/// Lights that exercise every declaration's fields: PCF radius 2, PCSS 16 + 32, anisotropic
/// mips of 4 taps, a table.
fn test_lights() -> Vec<Vec<u8>> {
    [
        "bunny.toml",
        "sphere_on_plane.toml",
        "techniques/vsm_mips_aniso.toml",
    ]
    .iter()
    .flat_map(|n| scene(n).lights)
    .map(|l| bytemuck::bytes_of(&shadowgraph::LightGpu::new(&l)).to_vec())
    .collect()
}

/// Every function of the exported library (every `shared/vis_*` module and what it imports)
/// that fetches has a `// #fetches` declaration, and each declaration of a function that does
/// not loop equals the sum of its own loads and its callees' declarations.
#[test]
fn every_fetching_function_declares_its_fetches() {
    let library = shadowgraph::wgsl::library().expect("library");
    let mut consistent = 0;
    for light in test_lights() {
        let mut f = Fetches::new("library", &library, &light).expect("declarations");
        for name in f.functions() {
            let declared = f.count_declared(&name).unwrap_or_else(|e| panic!("{e}"));
            if f.declared().contains(&name) {
                if let Some(from_body) = f.count_from_body(&name).expect("body") {
                    assert_eq!(
                        declared, from_body,
                        "`{name}`: declaration against its body"
                    );
                    consistent += 1;
                }
            }
        }
    }
    assert!(
        consistent > 30,
        "{consistent} declarations checked against their bodies"
    );
    // Negative control: without its declaration, `sg_load_depth` is named.
    let stripped = library.replace("// #fetches sg_load_depth: 1\n", "");
    assert_ne!(stripped, library);
    let light = &test_lights()[0];
    let mut f = Fetches::new("library", &stripped, light).expect("declarations");
    let e = f.count_declared("sg_load_depth").unwrap_err().to_string();
    assert!(e.contains("sg_load_depth"), "{e}");
}

/// Counting helpers: one per return type of a fetch in the shading kernel.
const COUNTERS: &str = "
var<private> sg_fetches: u32;
fn sg_count_vec4f(v: vec4<f32>) -> vec4<f32> { sg_fetches += 1u; return v; }
fn sg_count_vec4u(v: vec4<u32>) -> vec4<u32> { sg_fetches += 1u; return v; }
fn sg_count_f32(v: f32) -> f32 { sg_fetches += 1u; return v; }
";

/// `wgsl` (the resolved shading kernel) with every `textureLoad`, `textureSample*` and
/// `textureGather*` call wrapped in a counter, the counter reset before each light's
/// visibility and stored in that light's visibility output instead.
fn count_fetches(wgsl: &str) -> String {
    let module = naga::front::wgsl::parse_str(wgsl).expect("parse");
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .expect("validate");
    let mut wraps = Vec::new();
    let mut collect = |f: &naga::Function, fi: &naga::valid::FunctionInfo| {
        for (h, e) in f.expressions.iter() {
            if !matches!(
                e,
                naga::Expression::ImageLoad { .. } | naga::Expression::ImageSample { .. }
            ) {
                continue;
            }
            // naga's span is the callee's name: extend it to the closing parenthesis.
            let name = f.expressions.get_span(h).to_range().expect("span");
            let range = name.start..call_end(wgsl, name.end);
            let counter = match fi[h].ty.inner_with(&module.types) {
                naga::TypeInner::Vector { scalar, .. } if scalar.kind == naga::ScalarKind::Uint => {
                    "sg_count_vec4u"
                }
                naga::TypeInner::Vector { .. } => "sg_count_vec4f",
                _ => "sg_count_f32",
            };
            wraps.push((range, counter));
        }
    };
    for (h, f) in module.functions.iter() {
        collect(f, &info[h]);
    }
    for (i, ep) in module.entry_points.iter().enumerate() {
        collect(&ep.function, info.get_entry_point(i));
    }
    wraps.sort_by_key(|(r, _)| std::cmp::Reverse(r.start));
    let mut out = wgsl.to_string();
    for (r, counter) in &wraps {
        assert!(
            wgsl[r.clone()].starts_with("texture"),
            "{}",
            &wgsl[r.clone()]
        );
        out.insert(r.end, ')');
        out.insert_str(r.start, &format!("{counter}("));
    }
    let reset = "let v = light_visibility(";
    let store = "out_visibility[base + i] = v;";
    assert!(
        out.contains(reset) && out.contains(store),
        "shade.wgsl changed: update"
    );
    out = out.replace(reset, &format!("sg_fetches = 0u;\n        {reset}"));
    out = out.replace(store, "out_visibility[base + i] = f32(sg_fetches);");
    format!("{COUNTERS}{out}")
}

/// One past the `)` closing the argument list that opens at `at`.
fn call_end(text: &str, at: usize) -> usize {
    assert_eq!(&text[at..at + 1], "(", "a call's arguments follow its name");
    let mut depth = 0;
    for (i, c) in text[at..].char_indices() {
        match c {
            '(' => depth += 1,
            ')' if depth == 1 => return at + i + 1,
            ')' => depth -= 1,
            _ => {}
        }
    }
    panic!("unclosed call at {at}")
}

/// Every bundled and technique scene rendered with the counting shading kernel: per light, no
/// pixel fetches more than the declared count and some pixel fetches exactly that (PCSS
/// without a blocker stops after its search; a table lookup at the map's edge skips texels).
#[test]
fn counted_fetches_match_the_declarations() {
    let g = common::gpu();
    let mut names: Vec<String> = std::fs::read_dir(scene_path("techniques"))
        .expect("scenes")
        .map(|e| {
            format!(
                "techniques/{}",
                e.expect("entry").file_name().to_string_lossy()
            )
        })
        .collect();
    names.extend(
        [
            "bunny",
            "sphere_on_plane",
            "pole",
            "stacked",
            "grazing",
            "two_lights",
        ]
        .map(|n| format!("{n}.toml")),
    );
    names.sort();
    let mut renderer = Renderer::new(&g.device);
    let mut checked = 0;
    for name in &names {
        let mut s = scene(name);
        if shadowgraph::low_level::limits::check_features(&g.device, &s.lights).is_err() {
            continue;
        }
        (s.width, s.height) = (96, 72);
        let block = technique::shading_block(&s.lights);
        let wgsl = kernels::resolve("shade", Some(&block)).expect("shade");
        renderer
            .insert_shade_kernel(&g.device, &s.lights, &count_fetches(&wgsl))
            .expect("counting kernel");
        let frame = renderer
            .render(&g.device, &g.queue, &s, RenderOptions::default())
            .expect("render");
        let declared = shadowgraph::low_level::cli::shading_fetches(&s.lights).expect("declared");
        let lights = s.lights.len();
        for (l, &d) in declared.iter().enumerate() {
            let counts: Vec<f32> = frame
                .visibility
                .iter()
                .skip(l)
                .step_by(lights)
                .copied()
                .collect();
            let most = counts.iter().copied().fold(0.0, f32::max);
            assert_eq!(
                f64::from(most),
                d,
                "{name} light {l}: most fetches of a pixel"
            );
            checked += 1;
        }
    }
    assert!(checked >= 25, "{checked} lights checked");
}
