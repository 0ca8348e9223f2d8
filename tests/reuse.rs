//! Nothing is rebuilt per frame: after the first frame of a scene, frames and further
//! `render` calls of the same scene create no buffer, texture, view, bind group, layout,
//! shader module, pipeline, sampler or query set (`shadowgraph::low_level::gpu_objects` counts every one the
//! renderer, the executor, the timer and the plug-in stage create); the shading kernel is found
//! by a key that determines its generated block; timestamps come back for every frame, read a
//! frame later. Counts are exact: no tolerance.

mod common;

use std::path::Path;

use shadowgraph::Filter;
use shadowgraph::low_level::gpu_objects::{Created, created};
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique;

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Scenes covering the executor's node kinds (a blur, a mip chain read along the footprint,
/// summed-area tables, the soft techniques' tables, PCSS, two lights with hardware PCF), made
/// small: what is counted does not depend on the size.
fn scenes() -> Vec<(&'static str, Scene)> {
    [
        "techniques/vsm.toml",
        "techniques/vsm_mips_aniso.toml",
        "techniques/msm_sat.toml",
        "techniques/vssm.toml",
        "techniques/cssm.toml",
        "sphere_on_plane.toml",
        "two_lights.toml",
    ]
    .into_iter()
    .map(|name| {
        let mut s = scene(name);
        (s.width, s.height) = (48, 36);
        for l in &mut s.lights {
            l.shadow_map = 64;
        }
        (name, s)
    })
    .collect()
}

fn render(renderer: &mut Renderer, g: &shadowgraph::low_level::gpu::Gpu, s: &Scene, repeat: u32) {
    let opts = RenderOptions {
        repeat,
        ..Default::default()
    };
    renderer
        .render(&g.device, &g.queue, s, opts)
        .expect("render");
}

/// 100 frames after the first, as 100 `render` calls and as one call of 100 frames: nothing
/// created, for every scene in turn with one renderer (and back to the first scene: a scene of
/// another shape is rebuilt, the first one's pipelines are kept).
#[test]
fn frames_after_the_first_create_nothing() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    for (name, s) in scenes() {
        render(&mut renderer, &g, &s, 1);
        let after_first = created();
        for _ in 0..100 {
            render(&mut renderer, &g, &s, 1);
        }
        assert_eq!(created(), after_first, "{name}: 100 render calls");
        render(&mut renderer, &g, &s, 100);
        assert_eq!(created(), after_first, "{name}: one call of 100 frames");
    }
    // Back to the first scene: its targets are made again (the shape changed), its pipelines
    // are not.
    let (name, first) = &scenes()[0];
    let before = created();
    render(&mut renderer, &g, first, 1);
    let made = created();
    assert_eq!(made.pipelines, before.pipelines, "{name}: pipelines kept");
    assert_eq!(
        made.shader_modules, before.shader_modules,
        "{name}: modules kept"
    );
    render(&mut renderer, &g, first, 1);
    assert_eq!(created(), made, "{name}: second frame after the switch");
}

/// The counter counts: a fresh renderer's first frame creates pipelines, textures, bind
/// groups and buffers (a negative control for the assertions above).
#[test]
fn a_first_frame_creates_and_is_counted() {
    let g = common::gpu();
    let (_, s) = &scenes()[0];
    let before = created();
    render(&mut Renderer::new(&g.device), &g, s, 1);
    let d = created();
    let grew = |f: fn(&Created) -> u64| f(&d) > f(&before);
    assert!(
        grew(|c| c.pipelines) && grew(|c| c.textures),
        "{before:?} → {d:?}"
    );
    assert!(
        grew(|c| c.bind_groups) && grew(|c| c.buffers),
        "{before:?} → {d:?}"
    );
}

/// Every frame's timestamps come back, in order, though each is read a frame later: 12 frames
/// give 12 rows with the same passes (on a device that can time).
#[test]
fn every_frame_is_timed() {
    let g = common::gpu();
    if !g.can_time() {
        return;
    }
    let (_, s) = &scenes()[0];
    let mut renderer = Renderer::new(&g.device);
    let opts = RenderOptions {
        repeat: 12,
        ..Default::default()
    };
    let frame = renderer
        .render(&g.device, &g.queue, s, opts)
        .expect("render");
    assert_eq!(frame.timings.len(), 12);
    let names = |t: &[(String, f64)]| t.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    let first = names(&frame.timings[0]);
    assert!(first.contains(&"shade".to_string()), "{first:?}");
    for t in &frame.timings {
        assert_eq!(names(t), first);
        assert!(
            t.iter().all(|(_, ms)| ms.is_finite() && *ms >= 0.0),
            "{t:?}"
        );
    }
}

/// The shading kernel's key determines its block: over every bundled and technique scene's
/// lights, each technique with each of its filters, lights with equal keys get equal blocks.
/// (The converse need not hold: EVSM2 and EVSM4 share a block under two keys, which costs one
/// more pipeline, never a wrong one.)
#[test]
fn equal_shade_keys_mean_equal_blocks() {
    let mut lights = Vec::new();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for sub in ["", "techniques"] {
        for e in std::fs::read_dir(dir.join(sub)).expect("scenes") {
            let p = e.expect("entry").path();
            if p.extension().is_some_and(|x| x == "toml") {
                lights.extend(Scene::load(&p).expect("scene").lights);
            }
        }
    }
    // Each light's technique with the other filters too.
    let filters = [
        Filter::None,
        Filter::Mips {
            width: 3.0,
            max_anisotropy: 0,
        },
        Filter::Mips {
            width: 2.0,
            max_anisotropy: 4,
        },
    ];
    let mut variants = Vec::new();
    for l in &lights {
        for f in filters {
            let mut v = l.clone();
            if set_filter(&mut v.shadow.technique, f) {
                variants.push(v);
            }
        }
    }
    lights.extend(variants);
    // Each light's technique with every option of each of its choice keys (a choice may change
    // the generated code without changing the maps: CSSM's `resolve`).
    let mut choices = Vec::new();
    for l in &lights {
        let def = technique::of(&l.shadow.technique);
        for spec in def.params.iter().flat_map(|p| p.iter()) {
            let shadowgraph::low_level::model::ParamKind::Choice(options) = spec.kind else {
                continue;
            };
            for &option in options {
                let mut values = (def.values)(&l.shadow.technique);
                if values.get(spec.key).is_none() {
                    continue;
                }
                values.set(
                    spec.key,
                    shadowgraph::low_level::model::ParamValue::Choice(option),
                );
                let mut v = l.clone();
                v.shadow.technique = (def.build)(&values);
                choices.push(v);
            }
        }
    }
    lights.extend(choices);
    let mut seen: Vec<(String, String)> = Vec::new();
    for l in &lights {
        let one = std::slice::from_ref(l);
        let (key, block) = (technique::shade_key(one), technique::shading_block(one));
        for (k, b) in &seen {
            assert!(k != &key || b == &block, "key {key}: two blocks");
        }
        seen.push((key, block));
    }
    let distinct: std::collections::HashSet<&String> = seen.iter().map(|(k, _)| k).collect();
    assert!(distinct.len() >= 15, "{} distinct kernels", distinct.len());
}

/// Gives a prefiltered technique filter `f`; false for the others.
fn set_filter(t: &mut shadowgraph::Technique, f: Filter) -> bool {
    use shadowgraph::Technique as T;
    match t {
        T::Vsm { prefilter, .. }
        | T::Evsm { prefilter, .. }
        | T::Msm { prefilter, .. }
        | T::Csm { prefilter, .. } => prefilter.filter = f,
        T::Esm { filter, .. } => *filter = f,
        _ => return false,
    }
    true
}

/// The renderer, the executor, the timer and the plug-in stage create GPU objects only
/// through `shadowgraph::low_level::gpu_objects` (so that the counts above see everything): no direct
/// `create_*` call in their sources.
#[test]
fn creation_goes_through_the_counter() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let calls = [
        ".create_buffer(",
        "create_buffer_init(",
        ".create_texture(",
        ".create_view(",
        ".create_bind_group(",
        ".create_bind_group_layout(",
        ".create_pipeline_layout(",
        ".create_shader_module(",
        ".create_compute_pipeline(",
        ".create_render_pipeline(",
        ".create_sampler(",
        ".create_query_set(",
    ];
    let mut found = Vec::new();
    for file in [
        "render.rs",
        "render/renderer.rs",
        "render/targets.rs",
        "render/visibility_at.rs",
        "exec/mod.rs",
        "exec/pipelines.rs",
        "exec/pool.rs",
        "exec/record.rs",
        "timer.rs",
        "prefilter.rs",
    ] {
        let text = std::fs::read_to_string(root.join(file)).expect("source");
        for (n, line) in text.lines().enumerate() {
            if calls.iter().any(|c| line.contains(c)) && !line.trim_start().starts_with("//") {
                found.push(format!("{file}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "direct creation:\n{}", found.join("\n"));
}
