//! The Rust snippets of README.md and docs/PLUGIN.md compile and run. Every code line of their
//! ```` ```rust ```` blocks (trailing comments cut; comment lines, and lines holding `…`, aside)
//! is a whole line of a `#[rustfmt::skip]` function between this file's `snippets:begin` and
//! `snippets:end` markers, which the compiler checks and the tests below run on the adapter;
//! every method or path call a block's comments name (`stage.record_light(…)`,
//! `DepthLayer::new(…)`, `config.with_cascades(…)`, …) is called there too. A snippet that
//! stops compiling fails here: PLUGIN.md's `RenderOptions { aux: true, repeat: 1 }` did once
//! the struct had grown its `dump` field.

mod common;

use std::path::Path;

use glam::{Mat4, Vec3};
use shadowgraph::cascades::CascadeCamera;
use shadowgraph::low_level::gpu::{Gpu, submit_and_wait};
use shadowgraph::{DepthLayer, PrefilterOutput};

/// The markdown files whose ```` ```rust ```` blocks are usage snippets (EVALUATION.md's is a
/// list of signatures).
const DOCS: [&str; 2] = ["README.md", "docs/PLUGIN.md"];

/// The host's fragment shader of the snippets: the light's uniform and a pixel's visibility.
const MY_SHADER: &str = "
@group(0) @binding(0) var<uniform> light: sg_Light;
@fragment
fn fs_main(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(vec3<f32>(shadowgraph_visibility(light, p, normalize(n))), 1.0);
}
";

/// A depth texture (or array of `layers`) the snippets' stages read, cleared to `depth`.
fn depth_texture(g: &Gpu, (width, height): (u32, u32), layers: u32, depth: f32) -> wgpu::Texture {
    let texture = g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("snippet.depth"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let mut encoder = g.device.create_command_encoder(&Default::default());
    for layer in 0..layers {
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer,
            array_layer_count: Some(1),
            ..Default::default()
        });
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("snippet.clear"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(depth),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
    }
    submit_and_wait(&g.device, &g.queue, encoder, "snippet.clear").expect("clear");
    texture
}

/// The light's view of the snippets: from above, looking down at the origin.
fn view() -> Mat4 {
    Mat4::look_at_rh(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::Z)
}

// snippets:begin

/// README.md's plug-in stage: the stage, its WGSL in the host's shader, one frame recorded.
#[rustfmt::skip]
fn readme_stage(g: &Gpu) -> anyhow::Result<(String, PrefilterOutput, Vec<u8>)> {
use shadowgraph::{LightParams, Prefilter, PrefilterConfig};
let (device, view) = (g.device.clone(), view());
let shadow = depth_texture(g, (1024, 1024), 1, 0.5);
let mut encoder = device.create_command_encoder(&Default::default());
let mut stage = Prefilter::new(&device, &PrefilterConfig::vsm(1024))?;
let shader = format!("{}{MY_SHADER}", stage.wgsl(1, 0)?);
let out = stage.record(&device, &mut encoder, &shadow, &LightParams::orthographic(view, 5.0, 4.0, 20.0))?;
submit_and_wait(&device, &g.queue, encoder, "readme")?;
let light = bytemuck::bytes_of(&out.light).to_vec();
Ok((shader, out, light))
}

/// README.md's comments: many lights in the layers of one array, a point light's faces, a sun
/// in cascades (and in soft cascades).
#[rustfmt::skip]
fn readme_comments(g: &Gpu) -> anyhow::Result<(Vec<PrefilterOutput>, String, usize, usize)> {
use shadowgraph::{LightParams, Prefilter, PrefilterConfig};
let (device, n, first_binding) = (g.device.clone(), 128, 2);
let shadow_array = depth_texture(g, (n, n), 2, 0.5);
let mut stage = Prefilter::new(&device, &PrefilterConfig::vsm(n))?;
let mut encoder = device.create_command_encoder(&Default::default());
let mut outs = Vec::new();
for k in 0..2 {
    let light_k = LightParams::orthographic(view(), 5.0 + k as f32, 4.0, 20.0);
    outs.push(stage.record_light(k, &device, &mut encoder, DepthLayer::new(&shadow_array, k as u32), &light_k)?);
}
submit_and_wait(&device, &g.queue, encoder, "readme.lights")?;
let block = stage.wgsl_light("key", 1, first_binding)?;
let (pos, near, far) = (Vec3::new(0.0, 2.0, 0.0), 0.1, 20.0);
let light = LightParams::point(pos, near, far);
let faces = stage.point_views(&light, n)?.len();
let config = PrefilterConfig::vsm(n).with_cascades(4, 0.75, 0.1);
let sun = Prefilter::new(&device, &config)?;
let camera = CascadeCamera { view: view(), fov_y: 1.0, aspect: 1.5, near: 0.1, far: 50.0 };
let cascades = sun.fit_cascades(&camera, Vec3::new(0.3, -1.0, 0.2), 5.0)?.len();
let stage = Prefilter::new(&device, &PrefilterConfig::vssm(n, 0.5).with_cascades(4, 0.75, 0.1))?;
let sun = LightParams::orthographic(view(), 25.0, 1.0, 60.0);
let soft = stage.fit_light_cascades(&camera, &sun)?;
assert!(soft.iter().all(|c| c.light.max_search.is_some()), "soft cascades carry their cap");
let b = 0;
let sun_block = stage.wgsl_cascades("sun", 1, b)?;
assert!(sun_block.contains("fn shadowgraph_visibility_cascaded_sun("), "the cascades' function");
Ok((outs, block, faces, cascades.min(soft.len())))
}

/// docs/PLUGIN.md's library API: a scene loaded, planned and rendered.
#[rustfmt::skip]
fn plugin_library() -> anyhow::Result<(usize, usize)> {
use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::render::{RenderOptions, Renderer, plan_lights};
use shadowgraph::low_level::scene::Scene;
let gpu = Gpu::new()?;
let scene = Scene::load("scenes/bunny.toml")?;
let plan = plan_lights(&scene.lights)?;
let mut renderer = Renderer::new(&gpu.device);
let frame = renderer.render(&gpu.device, &gpu.queue, &scene,
                            RenderOptions { aux: true, repeat: 1, ..Default::default() })?;
Ok((plan.plan.steps.len(), frame.rgba.len() / 4))
}

/// docs/PLUGIN.md's plug-in stage: configured, laid out, its WGSL, one frame recorded.
#[rustfmt::skip]
fn plugin_stage(g: &Gpu) -> anyhow::Result<(String, PrefilterOutput, usize)> {
use shadowgraph::{LightParams, Prefilter, PrefilterConfig, Storage};
let (device, view) = (g.device.clone(), view());
let shadow = depth_texture(g, (1024, 1024), 1, 0.5);
let mut encoder = device.create_command_encoder(&Default::default());
let mut stage = Prefilter::new(&device, &PrefilterConfig::vsm(1024))?;
let f16 = Prefilter::new(&device, &PrefilterConfig::vsm(1024).with_storage(Storage::F16).with_blur(3.0))?;
let maps_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
    label: None, entries: &stage.layout_entries(0, wgpu::ShaderStages::FRAGMENT)?,
});
let shader = format!("{}{MY_SHADER}", stage.wgsl(1, 0)?);
let light = LightParams::orthographic(view, 5.0, 4.0, 20.0);
let out = stage.record(&device, &mut encoder, &shadow, &light)?;
submit_and_wait(&device, &g.queue, encoder, "plugin")?;
drop(maps_layout);
Ok((shader, out, stage.warnings().len() + f16.warnings().len()))
}

/// docs/PLUGIN.md's device setup: the features the stage can use that the adapter offers, the
/// adapter's limits, timing where the device has timestamps.
#[rustfmt::skip]
fn plugin_device(g: &Gpu) -> anyhow::Result<(wgpu::Features, bool)> {
use shadowgraph::{Prefilter, PrefilterConfig};
let adapter = &g.adapter;
let wanted = shadowgraph::TIMER_FEATURES
    | wgpu::Features::FLOAT32_FILTERABLE
    | wgpu::Features::TEXTURE_FORMAT_16BIT_NORM;
let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
    required_features: adapter.features() & wanted,
    required_limits: adapter.limits(),
    ..Default::default()
}))?;
let mut stage = Prefilter::new(&device, &PrefilterConfig::vsm(1024))?;
if device.features().contains(shadowgraph::TIMER_FEATURES) {
    stage.enable_timing(&device, &queue)?;
}
Ok((device.features(), stage.timings(&device)?.is_empty()))
}

// snippets:end

/// This file's lines between the markers, trimmed, comments cut.
fn compiled_lines() -> (Vec<String>, String) {
    let me = include_str!("doc_snippets.rs");
    let begin = me.find("// snippets:begin\n").expect("begin marker");
    let end = me.rfind("// snippets:end\n").expect("end marker");
    let region = &me[begin..end];
    (region.lines().map(code).collect(), region.to_string())
}

/// A line's code: trimmed, its trailing `//` comment cut (no snippet has `//` in a string).
fn code(line: &str) -> String {
    let cut = line.find("//").map_or(line, |at| &line[..at]);
    cut.trim().to_string()
}

/// The calls a comment names, as written: `.name(` (a method, whatever the receiver's name)
/// and `Path::name(` (a path's last two segments).
fn calls(comment: &str) -> Vec<String> {
    let b = comment.as_bytes();
    let mut out = Vec::new();
    for (at, _) in comment.match_indices('(') {
        let start = comment[..at]
            .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .map_or(0, |i| i + 1);
        if start == at {
            continue;
        }
        let name = &comment[start..at];
        if start >= 2 && &b[start - 2..start] == b"::" {
            let path = &comment[..start - 2];
            let from = path
                .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .map_or(0, |i| i + 1);
            out.push(format!("{}::{name}(", &path[from..]));
        } else if start >= 1 && b[start - 1] == b'.' {
            out.push(format!(".{name}("));
        }
    }
    out
}

/// Every ```` ```rust ```` block's lines of `text`: (1-based line number, line).
fn rust_blocks(text: &str) -> Vec<(usize, &str)> {
    let mut inside = false;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let fence = line.trim_start();
        if !inside && fence == "```rust" {
            inside = true;
        } else if inside && fence.starts_with("```") {
            inside = false;
        } else if inside {
            out.push((i + 1, line));
        }
    }
    out
}

#[test]
fn every_snippet_line_is_compiled_here() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (lines, region) = compiled_lines();
    let mut missing = Vec::new();
    let mut checked = 0;
    for doc in DOCS {
        let text = std::fs::read_to_string(root.join(doc)).expect(doc);
        let block = rust_blocks(&text);
        assert!(!block.is_empty(), "{doc}: no ```rust block");
        for (n, line) in block {
            let c = code(line);
            if !c.is_empty() && !c.contains('…') {
                checked += 1;
                if !lines.contains(&c) {
                    missing.push(format!(
                        "{doc}:{n}: `{c}` is not a line of a snippet function"
                    ));
                }
            }
            if let Some(at) = line.find("//") {
                for call in calls(&line[at..]) {
                    if !region.contains(&call) {
                        missing.push(format!("{doc}:{n}: a comment names `{call}`, not called"));
                    }
                }
            }
        }
    }
    assert!(checked >= 15, "only {checked} code lines found");
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// The snippets run: the stages' maps come back at the stage's size, the host shaders with the
/// stage's WGSL validate, the library renders the scene.
#[test]
fn the_snippets_run() {
    let g = common::gpu();
    let (shader, out, light) = readme_stage(&g).expect("README stage");
    shadowgraph::low_level::kernels::reflect("readme host", &shader)
        .expect("README host shader validates");
    assert_eq!(out.maps[0].texture.width(), 1024);
    assert_eq!(light.len(), std::mem::size_of_val(&out.light));

    let (outs, block, faces, cascades) = readme_comments(&g).expect("README comments");
    assert_eq!(outs.len(), 2);
    assert!(outs.iter().all(|o| o.maps[0].texture.width() == 128));
    assert!(block.contains("shadowgraph_visibility_key"), "{block}");
    assert_eq!((faces, cascades), (6, 4));

    let (shader, out, _) = plugin_stage(&g).expect("PLUGIN stage");
    shadowgraph::low_level::kernels::reflect("plugin host", &shader)
        .expect("PLUGIN host shader validates");
    assert_eq!(out.maps[0].texture.width(), 1024);

    let (features, _) = plugin_device(&g).expect("PLUGIN device");
    let offered = g.adapter.features() & shadowgraph::TIMER_FEATURES;
    assert_eq!(features & shadowgraph::TIMER_FEATURES, offered);

    let (nodes, pixels) = plugin_library().expect("PLUGIN library");
    assert!(nodes > 0 && pixels > 0, "{nodes} nodes, {pixels} pixels");
}

/// The checker sees what it must: a line not in this file, and a call no snippet makes.
#[test]
fn the_checker_finds_a_changed_line() {
    let (lines, region) = compiled_lines();
    assert!(lines.contains(&code(
        "let mut stage = Prefilter::new(&device, &PrefilterConfig::vsm(1024))?;   // note"
    )));
    assert!(!lines.contains(&code(
        "let mut stage = Prefilter::new(&device, &PrefilterConfig::vsm(512))?;"
    )));
    assert_eq!(
        calls("// stage.record_light(k, …), DepthLayer::new(&a, k) and f(x)"),
        [".record_light(", "DepthLayer::new("]
    );
    assert!(!region.contains(".record_lights("));
}
