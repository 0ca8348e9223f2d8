//! A host with several lights, as real renderers keep them: one `Depth32Float` array texture
//! with a layer per shadow map, rendered by the host's own depth pass: two spot lights with
//! MSM and a directional sun with soft shadows (`vssm`) in three cascades
//! (`Prefilter::fit_light_cascades`: practical split, texel-snapped, the sun's plane kept and
//! each map widened by the penumbra's reach). One `Prefilter` per technique serves its maps
//! (one set of pipelines, `record_light(k, …, DepthLayer::new(&array, layer), …)` reads each
//! layer in place, and each map lives until its slot is recorded again); the host's shader
//! holds both techniques' functions once (`prefilter::wgsl::functions_for`) and one generated
//! block per map (`shadowgraph_visibility_key`, `…_fill`, and the sun's cascades with
//! `shadowgraph_visibility_cascaded_sun`, which picks and blends them: `wgsl_cascades`), next
//! to its own names. Ten frames: the spots are static (drawn and filtered in the first frame
//! only, their maps kept; the stage's dispatch count must not move), the sun is drawn and
//! filtered every frame, both stages timed where the device can and the timings never read;
//! every frame's picture must equal the first's byte for byte, and the array passed whole
//! must be refused (`StageError::DepthArray`). Any failure is an error, status 1 (run in CI).
//! Writes a PNG.
//!
//!     cargo run --release --example host_lights [-- out.png]     (default target/host_lights.png)

mod common;

use anyhow::Context;
use common::{
    begin_shade_pass, copy_color, depth_pass, depth_pipeline, device, read, scene, shade_pipeline,
    target, uniform_entry,
};
use glam::{Mat4, Vec3};
use shadowgraph::cascades::{CascadeCamera, pick_fields};
use shadowgraph::{
    DepthLayer, LightParams, Prefilter, PrefilterConfig, PrefilterOutput, StageError,
    TIMER_FEATURES,
};
use wgpu::util::DeviceExt;

const IMAGE: (u32, u32) = (640, 480);
const SHADOW_MAP: u32 = 512;
/// The shadow maps' names in the shader (one layer and light slot each) and the lights'
/// colours (key, fill, sun).
const MAPS: [&str; 5] = ["key", "fill", "sun0", "sun1", "sun2"];
const COLORS: [[f32; 3]; 3] = [[0.95, 0.8, 0.6], [0.35, 0.45, 0.75], [0.5, 0.5, 0.45]];

fn camera() -> CascadeCamera {
    CascadeCamera {
        view: Mat4::look_at_rh(Vec3::new(3.0, 4.0, 6.5), Vec3::new(0.2, 0.5, 0.5), Vec3::Y),
        fov_y: 0.75,
        aspect: IMAGE.0 as f32 / IMAGE.1 as f32,
        near: 0.5,
        far: 16.0,
    }
}

/// The spot lights' parameters.
fn spots() -> Vec<LightParams> {
    let spot = |eye: Vec3| {
        LightParams::perspective(Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y), 1.0, 2.0, 20.0)
    };
    vec![
        spot(Vec3::new(4.0, 6.0, 4.0)),
        spot(Vec3::new(-5.0, 4.0, 3.0)),
    ]
}

/// The sun as one orthographic map over the whole scene: its view's origin is the emitter's
/// plane (soft penumbrae are sized from depths along it), its planes hold every caster, and
/// `max_search` is a fraction of its width; `fit_light_cascades` moves it onto each slice.
fn sun() -> LightParams {
    let direction = Vec3::new(6.0, -9.0, -2.0).normalize();
    let view = Mat4::look_to_rh(-15.0 * direction, direction, Vec3::Y);
    LightParams::orthographic(view, 9.0, 1.0, 30.0)
}

/// The host's own shading and names (a `struct Light` of its own, unrelated to
/// shadowgraph's `sg_Light`); `VISIBILITY` becomes one term per light.
const SHADE: &str = "
struct Light { color: vec4<f32> }
// The lights' colours.
struct Frame { colors: array<Light, 3> }
@group(0) @binding(0) var<uniform> camera: mat4x4<f32>;
@group(0) @binding(1) var<uniform> frame: Frame;
// The maps' lights as the stage describes them (`PrefilterOutput::light`, one after another,
// in one uniform buffer; lavapipe 22.3 crashed when more than three uniform bindings fed the
// fragment shader with the visibility functions).
@group(0) @binding(2) var<uniform> shadows: array<sg_Light, 5>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
}

@vertex
fn vs_main(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>, @location(2) c: vec3<f32>) -> VsOut {
    return VsOut(camera * vec4<f32>(p, 1.0), p, n, c);
}

fn lambert(l: sg_Light, p: vec3<f32>, n: vec3<f32>) -> f32 {
    // Spot lights shine from their position, the sun along its direction.
    let to_light = select(-l.direction, normalize(l.position - p), l.kind == 1u);
    return max(dot(n, to_light), 0.0);
}

// The sun's visibility: `shadowgraph_visibility_cascaded_sun` (the stage's `wgsl_cascades`)
// picks the pixel's cascade (cascade 0's sg_Light holds the pick fields) and fades to the next
// one's across the blend band.
fn sun_visibility(p: vec3<f32>, n: vec3<f32>) -> f32 {
    let sun = array<sg_Light, 3>(shadows[2], shadows[3], shadows[4]);
    return shadowgraph_visibility_cascaded_sun(sun, p, n);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    let p = in.world;
    var light = vec3<f32>(0.08);
    let key = shadows[0];
    let fill = shadows[1];
    light += frame.colors[0].color.rgb * lambert(key, p, n) * shadowgraph_visibility_key(key, p, n);
    light += frame.colors[1].color.rgb * lambert(fill, p, n) * shadowgraph_visibility_fill(fill, p, n);
    light += frame.colors[2].color.rgb * lambert(shadows[2], p, n) * sun_visibility(p, n);
    return vec4<f32>(in.color * light, 1.0);
}
";

/// Errors as one line, causes joined (`{:#}`), status 1.
fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

/// Frames drawn: the spot lights are static (drawn and filtered in the first frame, their
/// maps kept), the sun's cascades are drawn and filtered every frame, with timing on and the
/// timings never read.
const FRAMES: u32 = 10;

fn run() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/host_lights.png".into());
    let start = std::time::Instant::now();
    let (device, queue) = pollster::block_on(device())?;
    let verts = scene();
    let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host.vertices"),
        contents: bytemuck::cast_slice(&verts),
        usage: wgpu::BufferUsages::VERTEX,
    });
    // One stage per technique: the spots' MSM, the sun's soft VSM in three cascades (each
    // cascade a light slot of its stage with its own `max_search`, and a layer of the array).
    let mut spot_stage = Prefilter::new(&device, &PrefilterConfig::msm(SHADOW_MAP))?;
    let sun_config = PrefilterConfig::vssm(SHADOW_MAP, 1.5).with_cascades(3, 0.7, 0.1);
    let mut sun_stage = Prefilter::new(&device, &sun_config)?;
    // Timed where the device can; nothing here ever reads the timings (unread frames are
    // dropped by the stage).
    let timed = device.features().contains(TIMER_FEATURES);
    if timed {
        spot_stage.enable_timing(&device, &queue)?;
        sun_stage.enable_timing(&device, &queue)?;
    }
    let cascades = sun_stage.fit_light_cascades(&camera(), &sun())?;
    let mut params: Vec<(usize, LightParams)> = spots().into_iter().enumerate().collect();
    params.extend(cascades.iter().enumerate().map(|(c, k)| (c, k.light)));
    let shadows = shadow_array(&device, MAPS.len() as u32);
    refuse_whole_array(&device, &mut spot_stage, &shadows, &params[0].1)?;

    let (wgsl, maps_layout) = host_wgsl(&device, &spot_stage, &sun_stage, sun_config.technique)?;
    let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("host.frame"),
        entries: &(0..3)
            .map(|b| {
                let stage = match b {
                    0 => wgpu::ShaderStages::VERTEX,
                    _ => wgpu::ShaderStages::FRAGMENT,
                };
                uniform_entry(b, stage)
            })
            .collect::<Vec<_>>(),
    });
    let host = Host {
        shade: shade_pipeline(
            &device,
            &format!("{wgsl}{SHADE}"),
            &[&frame_layout, &maps_layout],
        ),
        depth_pipeline: depth_pipeline(&device),
        frame_layout,
        maps_layout,
        vertices,
        count: verts.len() as u32,
    };

    let mut outputs: Vec<Option<PrefilterOutput>> = vec![None; MAPS.len()];
    let mut first: Option<Vec<u8>> = None;
    let mut spot_dispatches = 0;
    for frame in 0..FRAMES {
        let mut enc = device.create_command_encoder(&Default::default());
        for (layer, &(slot, light)) in params.iter().enumerate() {
            // The spots are static: the host records them again only when they change.
            if layer < 2 && frame > 0 {
                continue;
            }
            let view = shadows.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let geometry = (&host.vertices, host.count);
            depth_pass(
                &device,
                &mut enc,
                &host.depth_pipeline,
                geometry,
                &view,
                &light,
            );
            let depth = DepthLayer::new(&shadows, layer as u32);
            let stage = if layer < 2 {
                &mut spot_stage
            } else {
                &mut sun_stage
            };
            outputs[layer] = Some(stage.record_light(slot, &device, &mut enc, depth, &light)?);
        }
        if frame == 0 {
            spot_dispatches = spot_stage.dispatch_count();
        }
        let mut lights: Vec<PrefilterOutput> = outputs.iter().flatten().cloned().collect();
        // Cascade 0's sg_Light carries the pick: the camera, the cascades' far distances, the band.
        pick_fields(
            &mut lights[2].light,
            &camera(),
            &cascades,
            sun_config.cascades.blend,
        )?;
        let rgba = host.shade(&device, &queue, enc, &lights)?;
        // Every frame shows the same scene: static maps kept, the sun's filtered anew.
        match &first {
            None => first = Some(rgba),
            Some(f) if *f != rgba => {
                let differ = f.iter().zip(&rgba).filter(|(a, b)| a != b).count();
                anyhow::bail!("frame {frame}: {differ} bytes differ from the first frame's");
            }
            Some(_) => {}
        }
    }
    anyhow::ensure!(
        spot_stage.dispatch_count() == spot_dispatches,
        "the static spot lights were filtered again ({} dispatches after the first frame's {})",
        spot_stage.dispatch_count(),
        spot_dispatches
    );
    let rgba = first.unwrap_or_default();
    image::save_buffer(&out, &rgba, IMAGE.0, IMAGE.1, image::ColorType::Rgba8)
        .with_context(|| format!("writing {out}"))?;
    println!(
        "wrote {out} ({}x{}: two MSM spot lights and a soft vssm sun in three cascades, {} + {} \
         {}² maps from two stages, layers of one depth array; {} pipelines, {} textures; {FRAMES} \
         identical frames, the spots filtered once, timing {}) in {:.2} s",
        IMAGE.0,
        IMAGE.1,
        spot_stage.light_count(),
        sun_stage.light_count(),
        SHADOW_MAP,
        spot_stage.pipeline_count() + sun_stage.pipeline_count(),
        spot_stage.texture_count() + sun_stage.texture_count(),
        if timed {
            "on, never read"
        } else {
            "unavailable"
        },
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The array passed whole names no layer: the stage must refuse it (`StageError::DepthArray`)
/// rather than filter a light from layer 0. Nothing is recorded; the encoder is dropped.
fn refuse_whole_array(
    device: &wgpu::Device,
    stage: &mut Prefilter,
    shadows: &wgpu::Texture,
    light: &LightParams,
) -> anyhow::Result<()> {
    let mut enc = device.create_command_encoder(&Default::default());
    match stage.record_light(1, device, &mut enc, shadows, light) {
        Err(shadowgraph::Error::Stage(StageError::DepthArray { .. })) => Ok(()),
        Err(e) => anyhow::bail!("an array passed whole: expected the DepthLayer error, got {e}"),
        Ok(_) => anyhow::bail!("an array passed whole was filtered"),
    }
}

/// Both techniques' functions once, then one block per map at its bindings of group 1, and
/// the maps' layout.
fn host_wgsl(
    device: &wgpu::Device,
    spot_stage: &Prefilter,
    sun_stage: &Prefilter,
    sun: shadowgraph::Technique,
) -> anyhow::Result<(String, wgpu::BindGroupLayout)> {
    let techniques = [spot_stage.config().technique, sun];
    let mut wgsl = shadowgraph::wgsl::functions_for(&techniques)?;
    let mut maps_entries = Vec::new();
    for (k, name) in MAPS.iter().enumerate() {
        let stage = if k < 2 { spot_stage } else { sun_stage };
        let first = maps_entries.len() as u32;
        // The spots' blocks one by one; the sun's three cascades in one call, with the
        // function that picks and blends them.
        match k {
            0 | 1 => wgsl.push_str(&stage.wgsl_light(name, 1, first)?),
            2 => wgsl.push_str(&stage.wgsl_cascades("sun", 1, first)?),
            _ => {}
        }
        maps_entries.extend(stage.layout_entries(first, wgpu::ShaderStages::FRAGMENT)?);
    }
    let maps_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("host.maps"),
        entries: &maps_entries,
    });
    Ok((wgsl, maps_layout))
}

/// The host's pipelines, layouts and geometry.
struct Host {
    shade: wgpu::RenderPipeline,
    depth_pipeline: wgpu::RenderPipeline,
    frame_layout: wgpu::BindGroupLayout,
    maps_layout: wgpu::BindGroupLayout,
    vertices: wgpu::Buffer,
    count: u32,
}

impl Host {
    /// Shades the frame recorded so far in `enc` with `lights`' maps (this frame's views: a
    /// stage's pooled textures may swap) and `sg_Light`s, submits it and reads it back.
    fn shade(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mut enc: wgpu::CommandEncoder,
        lights: &[PrefilterOutput],
    ) -> anyhow::Result<Vec<u8>> {
        let views: Vec<&wgpu::TextureView> = lights
            .iter()
            .flat_map(|o| o.maps.iter().map(|m| &m.view))
            .collect();
        let maps = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host.maps"),
            layout: &self.maps_layout,
            entries: &views
                .iter()
                .enumerate()
                .map(|(b, v)| wgpu::BindGroupEntry {
                    binding: b as u32,
                    resource: wgpu::BindingResource::TextureView(v),
                })
                .collect::<Vec<_>>(),
        });
        let frame = self.frame_bind_group(device, lights);
        let color = target(device, IMAGE, wgpu::TextureFormat::Rgba8UnormSrgb);
        let depth = target(device, IMAGE, wgpu::TextureFormat::Depth32Float);
        {
            let (cv, dv) = (
                color.create_view(&Default::default()),
                depth.create_view(&Default::default()),
            );
            let mut pass = begin_shade_pass(&mut enc, &cv, &dv);
            pass.set_pipeline(&self.shade);
            pass.set_bind_group(0, &frame, &[]);
            pass.set_bind_group(1, &maps, &[]);
            pass.set_vertex_buffer(0, self.vertices.slice(..));
            pass.draw(0..self.count, 0..1);
        }
        let readback = copy_color(device, &mut enc, &color);
        queue.submit([enc.finish()]);
        read(device, &readback)
    }

    /// The camera, the lights' colours and their `sg_Light`s, one after another.
    fn frame_bind_group(
        &self,
        device: &wgpu::Device,
        lights: &[PrefilterOutput],
    ) -> wgpu::BindGroup {
        let cam = camera();
        let view_proj = Mat4::perspective_rh(cam.fov_y, cam.aspect, 0.1, 100.0) * cam.view;
        let uniforms: Vec<Vec<u8>> = vec![
            bytemuck::cast_slice(&view_proj.to_cols_array()).to_vec(),
            COLORS
                .iter()
                .flat_map(|c| bytemuck::cast_slice(&[c[0], c[1], c[2], 0.0]).to_vec())
                .collect(),
            lights
                .iter()
                .flat_map(|o| bytemuck::bytes_of(&o.light).to_vec())
                .collect(),
        ];
        let buffers: Vec<wgpu::Buffer> = uniforms
            .iter()
            .map(|u| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("host.uniform"),
                    contents: u,
                    usage: wgpu::BufferUsages::UNIFORM,
                })
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host.frame"),
            layout: &self.frame_layout,
            entries: &buffers
                .iter()
                .enumerate()
                .map(|(b, buf)| wgpu::BindGroupEntry {
                    binding: b as u32,
                    resource: buf.as_entire_binding(),
                })
                .collect::<Vec<_>>(),
        })
    }
}

/// The host's shadow maps: one layer per light.
fn shadow_array(device: &wgpu::Device, layers: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.shadows"),
        size: wgpu::Extent3d {
            width: SHADOW_MAP,
            height: SHADOW_MAP,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        // Read by the stage: TEXTURE_BINDING.
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}
