//! The kernels run without wgpu's zeroing of workgroup memory (`exec::WorkgroupInit::AsLeft`),
//! which is sound only if each kernel writes every workgroup entry before it reads it. Here
//! every kernel that declares workgroup memory runs with that memory first filled with a NaN
//! bit pattern (`common::poison`), through the plans of the bundled technique scenes (and the
//! five-pass table `shadowgraph bench` keeps as its baseline), and every resource of every plan,
//! and the shaded frame, must be the same bit for bit as without the poison. No tolerance: a
//! kernel either reads what it wrote or reads the poison, which every sum, mean and table
//! carries into its output. The scenes run in every kernel layout (`exec::KernelLayout`), each
//! kernel poisoned as the layout resolves it (in `Redesign`, with the redesigned modules the
//! device's features allow), so the GPU's variants and the redesigns are checked here too. The test fails if a kernel with workgroup memory is
//! run by none of the plans, so a new one cannot go unchecked.

mod common;

use std::collections::{BTreeSet, HashMap};
use std::path::Path;
use std::sync::Arc;

use shadowgraph::low_level::exec::{Executor, KernelLayout};
use shadowgraph::low_level::gpu::{Gpu, read_texture, submit_and_wait};
use shadowgraph::low_level::graph::{Graph, plan};
use shadowgraph::low_level::kernels::{self, Replacements};
use shadowgraph::low_level::render::{Frame, RenderOptions, Renderer};
use shadowgraph::low_level::sat::five_pass::add_sat_five_pass;
use shadowgraph::low_level::sat::{SatCoding, add_sat, lookup_area};
use shadowgraph::low_level::scene::Scene;

/// A bundled technique scene with its text edited (`edits`: each `from` must occur), shaded at
/// 64 × 48 (the maps are what is checked; the frame only has to read them).
fn scene(file: &str, edits: &[(&str, &str)]) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/techniques")
        .join(file);
    let mut text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
    for (from, to) in edits {
        assert!(text.contains(from), "{file}: `{from}` not found");
        text = text.replace(from, to);
    }
    let mut s = Scene::parse(&path, &text).unwrap_or_else(|e| panic!("{file} {edits:?}: {e}"));
    s.width = 64;
    s.height = 48;
    s
}

/// The scenes whose plans run every kernel with workgroup memory: the fused blurs in tiles and
/// (past the tile's radius, on maps wide enough for the row kernels) in rows, both mip chains,
/// and the tables of every representation, fixed point and f32.
fn scenes() -> Vec<(String, Scene)> {
    let r12 = [("filter_radius = 3", "filter_radius = 12")];
    let float_sat = "filter = \"sat\"\nsat_sums = \"float\"";
    let f32_sums = "format = \"f32\"\nsat_sums = \"float\"";
    let cases: Vec<(&str, Vec<(&str, &str)>)> = vec![
        ("vsm.toml", vec![]),
        (
            "vsm.toml",
            vec![r12[0], ("shadow_map = 512", "shadow_map = 1024")],
        ),
        ("evsm4.toml", vec![]),
        ("evsm4.toml", r12.to_vec()),
        ("msm.toml", vec![]),
        (
            "msm.toml",
            vec![("filter_radius = 2", "filter_radius = 12")],
        ),
        ("vsm_mips.toml", vec![]),
        ("esm_mips_aniso.toml", vec![]),
        ("vssm.toml", vec![]),
        (
            "vssm.toml",
            vec![("sat_sums = \"float\"", "sat_sums = \"fixed\"")],
        ),
        ("vsm_sat.toml", vec![]),
        ("vsm_sat_float.toml", vec![]),
        ("msm_soft.toml", vec![]),
        ("msm_soft.toml", vec![("format = \"f16\"", f32_sums)]),
        ("msm_sat.toml", vec![]),
        ("msm_sat.toml", vec![("format = \"f16\"", f32_sums)]),
        ("esm_sat.toml", vec![]),
        ("esm_sat.toml", vec![("filter = \"sat\"", float_sat)]),
        ("evsm4_sat.toml", vec![]),
        ("evsm4_sat.toml", vec![("filter = \"sat\"", float_sat)]),
        ("cssm.toml", vec![]),
        (
            "cssm.toml",
            vec![("terms = 8", "terms = 8\nsat_sums = \"float\"")],
        ),
        ("csm_sat.toml", vec![]),
        ("csm_sat.toml", vec![("filter = \"sat\"", float_sat)]),
    ];
    cases
        .into_iter()
        .map(|(file, edits)| (format!("{file} {edits:?}"), scene(file, &edits)))
        .collect()
}

fn render(g: &Gpu, r: &mut Renderer, what: &str, s: &Scene) -> Frame {
    let opts = RenderOptions {
        aux: false,
        repeat: 1,
        dump: true,
    };
    r.render(&g.device, &g.queue, s, opts)
        .unwrap_or_else(|e| panic!("{what}: {e}"))
}

/// Same length and the same bits at every index; names the first difference.
#[track_caller]
fn same_bits<T: Copy + PartialEq + std::fmt::Debug>(what: &str, a: &[T], b: &[T]) {
    assert_eq!(a.len(), b.len(), "{what}: length");
    if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
        let n = (0..a.len()).filter(|&i| a[i] != b[i]).count();
        panic!(
            "{what}: {n} of {} values differ with poisoned workgroup memory, first at {i}: {:?} \
             against {:?}",
            a.len(),
            a[i],
            b[i]
        );
    }
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The texts the kernels resolve with in `layout` on `g`'s device: `variant`'s, and the
/// redesigned modules the layout imports in place of the shipped ones where the device has
/// their feature (`KernelLayout::module_sources`), as the executor resolves them. Poisoned
/// kernels are resolved texts, their imports inlined: resolved without these, a kernel would
/// poison the shipped modules where the plain run compiles the redesign.
fn layout_sources(
    g: &Gpu,
    variant: Option<&Replacements>,
    layout: Option<KernelLayout>,
) -> Option<Replacements> {
    let modules = layout.map_or_else(Vec::new, |l| l.module_sources(g.device.features()));
    if modules.is_empty() {
        return variant.cloned();
    }
    let mut all = variant.cloned().unwrap_or_default();
    for (shipped, redesign) in modules {
        if !all.contains_key(shipped) {
            let text =
                kernels::source_in(redesign, variant).unwrap_or_else(|e| panic!("{redesign}: {e}"));
            all.insert(shipped.to_string(), text.to_string());
        }
    }
    Some(all)
}

/// Renders each scene of `scenes` with `variant`'s kernels (the shipped ones with `None`), once
/// as they are and once with their workgroup memory poisoned, and requires every resource of
/// every plan, the visibility and the frame to be the same bit for bit. Returns the kernels
/// that wrote the resources.
fn same_with_poison(
    g: &Gpu,
    variant: Option<&Replacements>,
    scenes: &[(String, Scene)],
    layout: Option<KernelLayout>,
) -> BTreeSet<String> {
    let mut plain = Renderer::new(&g.device);
    let mut poison = Renderer::new(&g.device);
    if let Some(layout) = layout {
        plain.executor.kernels.set_layout(layout);
        poison.executor.kernels.set_layout(layout);
    }
    if let Some(v) = variant {
        plain.executor.kernels.set_replacements(Arc::new(v.clone()));
    }
    let sources = layout_sources(g, variant, layout);
    let poisoned = common::poison::poisoned_kernels_in(sources.as_ref());
    // Each redesigned module the layout imports is inlined in some poisoned kernel (its text
    // below its imports, as `kernels::resolve_in` copies it): the redesign is what is checked.
    for (_, redesign) in layout.map_or_else(Vec::new, |l| l.module_sources(g.device.features())) {
        let text = kernels::source_in(redesign, variant).unwrap_or_else(|e| panic!("{e}"));
        let body = text
            .rsplit_once("// #import ")
            .map_or(text, |(_, rest)| rest);
        let body = body.split_once('\n').map_or(body, |(_, rest)| rest);
        assert!(
            poisoned.values().any(|k| k.contains(body)),
            "`{redesign}`: no poisoned kernel imports it"
        );
    }
    poison.executor.kernels.set_replacements(Arc::new(poisoned));
    let mut ran = BTreeSet::new();
    for (what, s) in scenes {
        let a = render(g, &mut plain, what, s);
        let b = render(g, &mut poison, what, s);
        assert_eq!(a.resources.len(), b.resources.len(), "{what}: resources");
        for (x, y) in a.resources.iter().zip(&b.resources) {
            assert_eq!(x.texture, y.texture, "{what}");
            if let Some(k) = &x.producer {
                ran.insert(k.clone());
            }
            assert_eq!(x.levels.len(), y.levels.len(), "{what}: {}", x.texture);
            for (level, (m, n)) in x.levels.iter().zip(&y.levels).enumerate() {
                let name = format!("{what}: `{}` level {level}", m.resource);
                same_bits(&name, &bits(&m.data), &bits(&n.data));
            }
        }
        same_bits(
            &format!("{what}: visibility"),
            &bits(&a.visibility),
            &bits(&b.visibility),
        );
        same_bits(&format!("{what}: frame"), &a.rgba, &b.rgba);
        // Maps of a lit scene: the comparisons compare something.
        let nonzero = a
            .resources
            .iter()
            .flat_map(|r| &r.levels)
            .any(|m| m.data.iter().any(|&v| v != 0.0));
        assert!(nonzero, "{what}: every map is all zeros");
    }
    ran
}

#[test]
fn every_kernel_writes_its_workgroup_memory_before_reading_it() {
    let g = common::gpu();
    let poisoned = common::poison::poisoned_kernels();
    // Every layout of the kernels that have several (`exec::KernelLayout`: the fused blurs'
    // tile or strips, the tables' pass 3, the redesigns), each kernel by the file it compiled
    // (a redesign's own: `KernelLayout::kernel_source`).
    let mut ran = BTreeSet::new();
    for layout in [KernelLayout::Gpu, KernelLayout::Cpu, KernelLayout::Redesign] {
        let kernels = same_with_poison(&g, None, &scenes(), Some(layout));
        ran.extend(kernels.iter().map(|k| layout.kernel_source(k).to_string()));
    }
    // The library's tables from an imported map and the five-pass baseline: in
    // `the_library_tables_and_the_five_pass_baseline_too`.
    let baseline = [
        "sat_tile_sums",
        "sat_tile_sums_f32",
        "sat_tiles",
        "sat_tiles_f32",
        "sat_rows",
        "sat_carry",
        "sat_cols_reduce",
        "sat_cols",
        "sat_cols_f32",
    ];
    let unchecked: Vec<&String> = poisoned
        .keys()
        .filter(|k| !ran.contains(*k) && !baseline.contains(&k.as_str()))
        .collect();
    assert!(
        unchecked.is_empty(),
        "kernels with workgroup memory that no scene here runs: {unchecked:?} (ran: {ran:?})"
    );
    for k in baseline {
        assert!(
            poisoned.contains_key(k),
            "`{k}` declares no workgroup memory now"
        );
    }
}

/// The summed-area tables of the library's `sat::add_sat` (an imported map: the generic tile
/// kernels) and of the five-pass baseline `shadowgraph bench` keeps, fixed point and f32, on a
/// random two-channel map of 1500 × 70 (ragged tiles, two column blocks of the baseline), with
/// and without the poison.
#[test]
fn the_library_tables_and_the_five_pass_baseline_too() {
    type AddSat = fn(&mut Graph, usize, &str, &SatCoding) -> String;
    let g = common::gpu();
    let mut rng = common::rng(0x9015);
    let (w, h) = (1500u32, 70u32);
    let values: Vec<f32> = (0..w * h * 2)
        .map(|_| rand::Rng::random_range(&mut rng, 0.05f32..1.0))
        .collect();
    let format = wgpu::TextureFormat::Rg32Float;
    let input = common::upload(
        &g.device,
        &g.queue,
        "test.poison.input",
        (w, h),
        format,
        bytemuck::cast_slice(&values),
    );
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut plain = Executor::new();
    let mut poison = Executor::new();
    poison
        .kernels
        .set_replacements(Arc::new(common::poison::poisoned_kernels()));
    let fixed = SatCoding::fixed(lookup_area(16.0, 16.0), [0.0; 4], [1.0; 4]).unwrap();
    let float = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
    let builds: [(&str, AddSat); 2] = [("add_sat", add_sat), ("five-pass", add_sat_five_pass)];
    for (what, add) in builds {
        for coding in [&fixed, &float] {
            let what = format!("{what} {:?}", coding.variant);
            let mut graph = Graph::default();
            graph.import("in", format, w, h, Some(0));
            let out = add(&mut graph, 0, "in", coding);
            let plan = plan(&graph, &[&out]).expect("plan");
            let run = |exec: &mut Executor| {
                let mut enc = g.device.create_command_encoder(&Default::default());
                let outputs = exec
                    .record(&g.device, &mut enc, &plan, &imports, None)
                    .expect("record");
                submit_and_wait(&g.device, &g.queue, enc, &what).expect("run");
                read_texture(&g.device, &g.queue, &outputs.textures[&out], 0).expect("readback")
            };
            let a = run(&mut plain);
            let b = run(&mut poison);
            // A table of sums of random values: the check compares something.
            assert!(a.iter().any(|&x| x != 0), "{what}: the table is all zeros");
            same_bits(&what, &a, &b);
        }
    }
}

/// The benchmark variants in `benches/variants/` run without the zeroing too (`bench
/// --kernel-dirs` compiles them as the shipped kernels): those with workgroup memory, each
/// through the scenes whose plans run its kernels, poisoned and not, bit for bit.
#[test]
fn the_benchmark_variants_write_it_before_reading_it_too() {
    let g = common::gpu();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/variants");
    let all = scenes();
    let pick = |variant: &str, names: &[&str]| -> Vec<(String, Scene)> {
        all.iter()
            .filter(|(what, _)| names.iter().any(|n| what.starts_with(n)))
            .map(|(what, s)| (format!("{variant}: {what}"), s.clone()))
            .collect()
    };
    let tables = ["vssm.toml", "msm_soft.toml", "esm_sat.toml", "cssm.toml"];
    for (variant, names) in [
        ("sat_sub2", &tables[..]),
        ("sat_vsm_texel", &["vssm.toml"][..]),
        ("sat_carries_serial", &tables[..]),
        ("mip_quads", &["vsm_mips.toml", "esm_mips_aniso.toml"][..]),
    ] {
        let files = kernels::read_replacements(&root.join(variant))
            .unwrap_or_else(|e| panic!("{variant}: {e}"));
        let ran = same_with_poison(&g, Some(&files), &pick(variant, names), None);
        assert!(!ran.is_empty(), "{variant}: nothing ran");
    }
}
