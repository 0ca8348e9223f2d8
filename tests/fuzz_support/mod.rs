//! A mutation fuzzer of scene files, shared by `tests/fuzz.rs` (a few thousand cases) and
//! `examples/fuzz_scenes.rs` (millions). Each case mutates one of the bundled scenes as TOML
//! (values, types, keys, sections, meshes, mutated OBJ and glTF files; sometimes the text
//! itself), then loads and plans it in-process. It asserts: no panic; a refused scene is one
//! line naming the file, with a line number unless the fault is the whole file's; an accepted
//! scene has finite numbers and unit normals; and a sample of accepted scenes, rendered at
//! 16×12, gives finite visibility in [0, 1] and finite normals (or a one-line device-limit
//! error).
#![allow(dead_code, reason = "the test and the example use different parts")]

pub mod mutate;
pub mod mutate_gltf;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rand::rngs::SmallRng;
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use shadowgraph::Error;
use shadowgraph::low_level::render::{RenderOptions, Renderer, plan_lights};
use shadowgraph::low_level::scene::Scene;
use toml::{Table, Value};

/// What to run.
#[derive(Clone, Debug)]
pub struct Options {
    /// Cases to run.
    pub cases: u64,
    /// Seed of case 0 (case `i` has its own seed from this and `i`, so any case reproduces
    /// alone with `--first i --cases 1`).
    pub seed: u64,
    /// First case number.
    pub first: u64,
    /// Worker threads.
    pub threads: usize,
    /// Render every this many accepted scenes (0: never).
    pub render_every: u64,
    /// Folder for the fuzzer's meshes and for failing inputs.
    pub dir: PathBuf,
    /// Print progress to stderr every this many cases (0: never).
    pub progress: u64,
}

/// What happened.
#[derive(Debug, Default)]
pub struct Summary {
    /// Cases run.
    pub cases: u64,
    /// Scenes accepted (and planned).
    pub accepted: u64,
    /// Scenes refused with a good error.
    pub refused: u64,
    /// Accepted scenes rendered.
    pub rendered: u64,
    /// Renders refused with a device-limit error.
    pub render_refused: u64,
    /// Cases with a mutated glTF file whose scene was accepted.
    pub gltf_accepted: u64,
    /// Cases with a mutated glTF file whose scene was refused with a good error.
    pub gltf_refused: u64,
    /// Failures: `(case, what)`; the inputs are written to `dir/failures`.
    pub failures: Vec<(u64, String)>,
    /// Wall time.
    pub elapsed: Duration,
}

enum Outcome {
    Refused,
    Accepted(Box<Scene>),
}

struct Shared<'a> {
    opts: &'a Options,
    seeds: Vec<Table>,
    gpu: Option<Mutex<(shadowgraph::low_level::gpu::Gpu, Renderer)>>,
    summary: Mutex<Summary>,
    done: AtomicU64,
    accepted: AtomicU64,
}

/// The seeds: every bundled scene, mesh paths pointed at the fuzzer's own small mesh of the
/// same kind (OBJ or glTF).
pub fn seeds() -> Vec<Table> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files = Vec::new();
    for d in [root.clone(), root.join("techniques")] {
        for e in std::fs::read_dir(d).expect("scenes/").flatten() {
            if e.path().extension().is_some_and(|x| x == "toml") {
                files.push(e.path());
            }
        }
    }
    files.sort();
    files
        .iter()
        .map(|f| {
            let mut t: Table = toml::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
            if let Some(Value::Array(objects)) = t.get_mut("object") {
                for o in objects.iter_mut().filter_map(Value::as_table_mut) {
                    let gltf = o.get("path").and_then(Value::as_str).map(|p| {
                        let p = p.to_ascii_lowercase();
                        p.ends_with(".gltf") || p.ends_with(".glb")
                    });
                    if let Some(gltf) = gltf {
                        let fuzz = if gltf { "fuzz.gltf" } else { "fuzz.obj" };
                        o.insert("path".into(), Value::String(fuzz.into()));
                    }
                }
            }
            t
        })
        .collect()
}

/// The mesh files a case may write beside its scene.
const CASE_MESHES: [&str; 3] = ["case.obj", "case.gltf", "case.glb"];

/// A mesh file a case writes beside its scene: its name and bytes.
pub type MeshFile = (&'static str, Vec<u8>);

/// Case `i`: the scene text and, for some cases, a mutated mesh file (`case.obj`, `case.gltf`
/// or `case.glb`) that its last object loads.
pub fn case(seeds: &[Table], seed: u64, i: u64) -> (String, Option<MeshFile>) {
    let mut rng = SmallRng::seed_from_u64(seed ^ i.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let mut t = seeds.choose(&mut rng).cloned().unwrap_or_default();
    let mesh = rng.random_bool(0.14).then(|| {
        // Two in three OBJ, one in three glTF (text or binary).
        let (name, bytes) = if rng.random_range(0..3) < 2 {
            ("case.obj", mutate::mutate_obj(&mut rng).into_bytes())
        } else {
            mutate_gltf::mutate_gltf(&mut rng)
        };
        if let Some(Value::Array(objects)) = t.get_mut("object") {
            if let Some(o) = objects.last_mut().and_then(Value::as_table_mut) {
                o.retain(|k, _| !matches!(k, "size" | "radius" | "height"));
                o.insert("shape".into(), Value::String("mesh".into()));
                o.insert("path".into(), Value::String(name.into()));
            }
        }
        (name, bytes)
    });
    let mutations = [1, 1, 1, 1, 1, 2, 2, 3, 4, 6];
    for _ in 0..*mutations.choose(&mut rng).unwrap_or(&1) {
        mutate::mutate(&mut t, &mut rng);
    }
    let mut text = toml::to_string(&t).unwrap_or_default();
    if rng.random_bool(0.08) {
        mutate::damage_text(&mut text, &mut rng);
    }
    (text, mesh)
}

/// Runs the cases on `opts.threads` threads; `gpu` renders the sample when given.
pub fn run(opts: &Options, gpu: Option<shadowgraph::low_level::gpu::Gpu>) -> Summary {
    let start = Instant::now();
    let shared = Shared {
        opts,
        seeds: seeds(),
        gpu: gpu.map(|g| {
            let r = Renderer::new(&g.device);
            Mutex::new((g, r))
        }),
        summary: Mutex::new(Summary::default()),
        done: AtomicU64::new(0),
        accepted: AtomicU64::new(0),
    };
    std::thread::scope(|s| {
        for t in 0..opts.threads.max(1) {
            let shared = &shared;
            s.spawn(move || worker(shared, t));
        }
    });
    let mut summary = shared.summary.into_inner().unwrap_or_default();
    summary.elapsed = start.elapsed();
    summary.failures.sort();
    summary
}

fn worker(sh: &Shared, t: usize) {
    let opts = sh.opts;
    let dir = opts.dir.join(format!("worker{t}"));
    std::fs::create_dir_all(dir.join("dir.obj")).expect("fuzz folder");
    std::fs::write(dir.join("fuzz.obj"), mutate::GOOD_OBJ).expect("fuzz mesh");
    std::fs::write(dir.join("fuzz.gltf"), mutate_gltf::good_gltf()).expect("fuzz glTF");
    let scene_path = dir.join("case.toml");
    let threads = opts.threads.max(1) as u64;
    let mut i = opts.first + t as u64;
    let mut local = Summary::default();
    while i < opts.first + opts.cases {
        let (text, mesh) = case(&sh.seeds, opts.seed, i);
        // Only this case's mesh may exist, so that a failure reproduces alone: a mutated
        // path may name any of them.
        for name in CASE_MESHES {
            let _ = std::fs::remove_file(dir.join(name));
        }
        if let Some((name, bytes)) = &mesh {
            std::fs::write(dir.join(name), bytes).expect("case mesh");
        }
        let gltf = mesh.as_ref().is_some_and(|(name, _)| *name != "case.obj");
        local.cases += 1;
        let verdict = match check(&scene_path, &text) {
            Ok(Outcome::Refused) => {
                local.refused += 1;
                local.gltf_refused += u64::from(gltf);
                Ok(())
            }
            Ok(Outcome::Accepted(scene)) => {
                local.accepted += 1;
                local.gltf_accepted += u64::from(gltf);
                let n = sh.accepted.fetch_add(1, Ordering::Relaxed);
                match &sh.gpu {
                    Some(g) if opts.render_every > 0 && n.is_multiple_of(opts.render_every) => {
                        render_check(g, *scene, &mut local)
                    }
                    _ => Ok(()),
                }
            }
            Err(e) => Err(e),
        };
        if let Err(what) = verdict {
            save_failure(opts, i, &text, mesh.as_ref(), &what);
            local.failures.push((i, what));
        }
        let done = sh.done.fetch_add(1, Ordering::Relaxed) + 1;
        if opts.progress > 0 && done.is_multiple_of(opts.progress) {
            eprintln!("fuzz: {done} cases");
        }
        i += threads;
    }
    let mut s = sh.summary.lock().unwrap_or_else(|e| e.into_inner());
    s.cases += local.cases;
    s.accepted += local.accepted;
    s.refused += local.refused;
    s.rendered += local.rendered;
    s.render_refused += local.render_refused;
    s.gltf_accepted += local.gltf_accepted;
    s.gltf_refused += local.gltf_refused;
    s.failures.extend(local.failures);
}

fn save_failure(opts: &Options, i: u64, text: &str, mesh: Option<&MeshFile>, what: &str) {
    let d = opts.dir.join("failures");
    let _ = std::fs::create_dir_all(&d);
    let _ = std::fs::write(d.join(format!("case-{i}.toml")), text);
    if let Some((name, bytes)) = mesh {
        let ext = name.rsplit('.').next().unwrap_or("mesh");
        let _ = std::fs::write(d.join(format!("case-{i}.{ext}")), bytes);
    }
    let _ = std::fs::write(d.join(format!("case-{i}.txt")), what);
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".into())
}

/// Loads and plans one case; `Err` describes a failure of the checks.
fn check(path: &Path, text: &str) -> Result<Outcome, String> {
    let r = catch_unwind(AssertUnwindSafe(|| {
        let scene = Scene::parse(path, text)?;
        plan_lights(&scene.lights)?;
        Ok::<_, Error>(scene)
    }));
    match r {
        Err(p) => Err(format!(
            "panic while loading or planning: {}",
            panic_text(&*p)
        )),
        Ok(Err(e)) => check_error(path, text, &e).map(|()| Outcome::Refused),
        Ok(Ok(scene)) => check_scene(&scene).map(|()| Outcome::Accepted(Box::new(scene))),
    }
}

/// Refusals that concern the whole file and so have no line.
const WHOLE_FILE: &[&str] = &[
    "the scene has no `[[light]]`",
    "the scene has no `[[object]]`",
    "missing key `output`",
    "missing key `camera`",
];

fn check_error(path: &Path, text: &str, e: &Error) -> Result<(), String> {
    let shown = e.to_string();
    let fail = |why: &str| Err(format!("{why}: {shown}"));
    if shown.contains(['\n', '\r']) {
        return fail("error of more than one line");
    }
    if long_number(&shown) {
        return fail("a number printed in full");
    }
    let Error::Scene {
        path: p,
        location,
        message,
    } = e
    else {
        return fail("not a scene error");
    };
    if p != path {
        return fail("names the wrong file");
    }
    if location.is_empty() {
        if WHOLE_FILE.iter().any(|w| message.ends_with(w)) {
            return Ok(());
        }
        return fail("no line number");
    }
    let line: usize = location
        .split(':')
        .nth(1)
        .and_then(|l| l.parse().ok())
        .unwrap_or(0);
    if line == 0 || line > text.lines().count() + 1 {
        return fail("line number outside the file");
    }
    Ok(())
}

fn long_number(s: &str) -> bool {
    let mut run = 0;
    s.chars().any(|c| {
        run = if c.is_ascii_digit() { run + 1 } else { 0 };
        run > 20
    })
}

fn check_scene(s: &Scene) -> Result<(), String> {
    let non_finite = |d: String| {
        d.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '.'))
            .any(|t| matches!(t, "inf" | "-inf" | "NaN"))
    };
    if non_finite(format!("{:?} {:?} {:?}", s.camera, s.ambient, s.background)) {
        return Err(format!(
            "accepted a non-finite camera or colour: {:?}",
            s.camera
        ));
    }
    for (i, l) in s.lights.iter().enumerate() {
        if non_finite(format!("{l:?}")) || !l.projection().is_finite() || !l.view().is_finite() {
            return Err(format!(
                "accepted light[{i}] with a non-finite value: {l:?}"
            ));
        }
    }
    let lights: Vec<(glam::Vec3, glam::Mat4)> = s
        .lights
        .iter()
        .map(|l| (l.position, l.projection() * l.view()))
        .collect();
    for (i, o) in s.objects.iter().enumerate() {
        let m = &o.mesh;
        if !o.color.is_finite() || m.positions.iter().any(|p| !p.is_finite()) {
            return Err(format!(
                "accepted object[{i}] with a non-finite vertex or colour"
            ));
        }
        if let Some(n) = m
            .normals
            .iter()
            .find(|n| !(n.is_finite() && (n.length() - 1.0).abs() < 1e-3))
        {
            return Err(format!("accepted object[{i}] with normal {n}"));
        }
        // What the shading computes in f32: squared distances to the eye and the lights, and
        // every vertex in every light's clip space.
        for &v in &m.positions {
            if !(v - s.camera.position).length_squared().is_finite() {
                return Err(format!(
                    "object[{i}]: a vertex's distance to the eye overflows"
                ));
            }
            for (k, (p, clip_of)) in lights.iter().enumerate() {
                let clip = *clip_of * v.extend(1.0);
                if !((v - *p).length_squared().is_finite() && clip.is_finite()) {
                    return Err(format!("object[{i}] seen from light[{k}] overflows"));
                }
            }
        }
    }
    Ok(())
}

/// Renders an accepted scene at 16×12 with shadow maps of at most 64²: finite visibility in
/// [0, 1] and finite normals, or a one-line device-limit error naming the file.
fn render_check(
    g: &Mutex<(shadowgraph::low_level::gpu::Gpu, Renderer)>,
    mut scene: Scene,
    local: &mut Summary,
) -> Result<(), String> {
    scene.width = 16;
    scene.height = 12;
    for l in &mut scene.lights {
        l.shadow_map = l.shadow_map.min(64);
    }
    let mut guard = g.lock().unwrap_or_else(|e| e.into_inner());
    let (gpu, renderer) = &mut *guard;
    // Every scene's technique mix compiles pipelines of its own: start afresh now and then so
    // that millions of cases keep a bounded cache.
    if renderer.executor.kernels.len() > 200 {
        *renderer = Renderer::new(&gpu.device);
    }
    let opts = RenderOptions {
        aux: true,
        repeat: 1,
        dump: false,
    };
    let r = catch_unwind(AssertUnwindSafe(|| {
        renderer.render(&gpu.device, &gpu.queue, &scene, opts)
    }));
    local.rendered += 1;
    match r {
        Err(p) => Err(format!("panic while rendering: {}", panic_text(&*p))),
        Ok(Err(e)) => {
            let shown = e.to_string();
            let limit = matches!(e, Error::Limit { .. } | Error::MissingFeature { .. })
                || shown.starts_with(&scene.path.display().to_string());
            if shown.contains('\n') || !limit {
                return Err(format!("render error: {shown}"));
            }
            local.render_refused += 1;
            Ok(())
        }
        Ok(Ok(frame)) => {
            if let Some(v) = frame.visibility.iter().find(|v| !(0.0..=1.0).contains(*v)) {
                return Err(format!("visibility {v} outside [0, 1]"));
            }
            if frame.normal.iter().any(|v| !v.is_finite()) {
                return Err("non-finite normal in the G-buffer".into());
            }
            Ok(())
        }
    }
}
