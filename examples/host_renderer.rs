//! A small renderer of its own — its own device, geometry, depth pass, pipelines and shading,
//! in plain wgpu — that uses shadowgraph only as a plug-in preprocess stage: each frame it
//! hands its shadow depth texture to one `Prefilter` per moment technique and shades with the
//! WGSL the stage exports. Writes a 2×2 panel PNG (VSM, EVSM4 / MSM, CSM).
//!
//!     cargo run --release --example host_renderer [-- out.png]     (default target/host_renderer.png)

mod common;

use anyhow::Context;
use common::{
    begin_shade_pass, copy_color, depth_pass, depth_pipeline, device, read, scene, shade_pipeline,
    target, uniform_entry,
};
use glam::{Mat4, Vec3};
use shadowgraph::{LightParams, Prefilter, PrefilterConfig, TIMER_FEATURES};
use wgpu::util::DeviceExt;

const PANEL: (u32, u32) = (384, 288);
const SHADOW_MAP: u32 = 1024;
const FRAMES: u32 = 3;

/// The host's shading: Lambert and ambient, with shadowgraph's visibility per fragment.
const SHADE: &str = "
@group(0) @binding(0) var<uniform> camera: mat4x4<f32>;
@group(0) @binding(1) var<uniform> light: sg_Light;

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

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    let lit = max(dot(n, -light.direction), 0.0) * shadowgraph_visibility(light, in.world, n);
    return vec4<f32>(in.color * (0.15 + 0.85 * lit), 1.0);
}
";

/// Errors as one line, causes joined (`{:#}`), status 1.
fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/host_renderer.png".into());
    let start = std::time::Instant::now();
    let (device, queue) = pollster::block_on(device())?;
    let host = Host::new(&device);
    let configs = [
        PrefilterConfig::vsm(SHADOW_MAP),
        PrefilterConfig::evsm4(SHADOW_MAP),
        PrefilterConfig::msm(SHADOW_MAP),
        PrefilterConfig::csm(SHADOW_MAP, 8),
    ];
    let mut panels = Vec::new();
    for config in &configs {
        // The stage: pipelines once; its WGSL and layout go into the host's own pipeline.
        let mut stage = Prefilter::new(&device, config)?;
        if device.features().contains(TIMER_FEATURES) {
            stage.enable_timing(&device, &queue)?;
        }
        let maps_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host.maps"),
            entries: &stage.layout_entries(0, wgpu::ShaderStages::FRAGMENT)?,
        });
        let pipeline = host.shade_pipeline(&device, &stage.wgsl(1, 0)?, &maps_layout);
        panels.push((stage, maps_layout, pipeline));
    }
    let mut rgba = Vec::new();
    for frame in 0..FRAMES {
        // The light moves a little each frame: new matrices, same stages and textures.
        let angle = 3.9 + 0.05 * frame as f32;
        let eye = Vec3::new(8.0 * angle.cos(), 6.0, 8.0 * angle.sin());
        let view = Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y);
        let light = LightParams::orthographic(view, 5.0, 4.0, 20.0);
        let mut enc = device.create_command_encoder(&Default::default());
        host.depth_pass(&device, &mut enc, &light);
        let mut shaded = Vec::new();
        for (stage, maps_layout, pipeline) in &mut panels {
            let out = stage.record(&device, &mut enc, &host.shadow, &light)?;
            // Pooled textures may swap between frames: bind this frame's views.
            let entries: Vec<wgpu::BindGroupEntry> = out
                .maps
                .iter()
                .enumerate()
                .map(|(k, m)| wgpu::BindGroupEntry {
                    binding: k as u32,
                    resource: wgpu::BindingResource::TextureView(&m.view),
                })
                .collect();
            let maps = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("host.maps"),
                layout: maps_layout,
                entries: &entries,
            });
            let frame_bg = host.frame_bind_group(&device, bytemuck::bytes_of(&out.light));
            shaded.push((pipeline.clone(), frame_bg, maps));
        }
        host.shade_pass(&mut enc, &shaded);
        let readback = host.copy_color(&device, &mut enc);
        queue.submit([enc.finish()]);
        rgba = read(&device, &readback)?;
    }
    image::save_buffer(
        &out,
        &rgba,
        2 * PANEL.0,
        2 * PANEL.1,
        image::ColorType::Rgba8,
    )
    .with_context(|| format!("writing {out}"))?;
    for (stage, _, _) in &mut panels {
        let name = stage.config().technique.name();
        let times: Vec<String> = stage
            .timings(&device)?
            .iter()
            .map(|(k, ms)| format!("{k} {ms:.2} ms"))
            .collect();
        println!(
            "{name:>6}: {} textures; {}",
            stage.texture_count(),
            times.join(", ")
        );
    }
    println!(
        "wrote {out} ({}x{}: vsm, evsm4 / msm, csm), {FRAMES} frames in {:.2} s",
        2 * PANEL.0,
        2 * PANEL.1,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Everything the host owns: geometry, its shadow depth texture, colour and depth targets,
/// the depth pipeline and the shading pipelines' shared layout.
struct Host {
    vertices: wgpu::Buffer,
    count: u32,
    shadow: wgpu::Texture,
    color: wgpu::Texture,
    depth: wgpu::Texture,
    depth_pipeline: wgpu::RenderPipeline,
    frame_layout: wgpu::BindGroupLayout,
    camera: Mat4,
}

impl Host {
    fn new(device: &wgpu::Device) -> Self {
        let verts = scene();
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host.vertices"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let depth_pipeline = depth_pipeline(device);
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host.frame"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::VERTEX),
                uniform_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let aspect = PANEL.0 as f32 / PANEL.1 as f32;
        let camera = Mat4::perspective_rh(0.75, aspect, 0.1, 100.0)
            * Mat4::look_at_rh(Vec3::new(3.0, 4.0, 6.5), Vec3::new(0.2, 0.5, 0.5), Vec3::Y);
        let size = (2 * PANEL.0, 2 * PANEL.1);
        Self {
            count: verts.len() as u32,
            vertices,
            shadow: target(
                device,
                (SHADOW_MAP, SHADOW_MAP),
                wgpu::TextureFormat::Depth32Float,
            ),
            color: target(device, size, wgpu::TextureFormat::Rgba8UnormSrgb),
            depth: target(device, size, wgpu::TextureFormat::Depth32Float),
            depth_pipeline,
            frame_layout,
            camera,
        }
    }

    fn shade_pipeline(
        &self,
        device: &wgpu::Device,
        stage_wgsl: &str,
        maps_layout: &wgpu::BindGroupLayout,
    ) -> wgpu::RenderPipeline {
        let wgsl = format!("{stage_wgsl}{SHADE}");
        shade_pipeline(device, &wgsl, &[&self.frame_layout, maps_layout])
    }

    fn depth_pass(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        light: &LightParams,
    ) {
        let view = self.shadow.create_view(&Default::default());
        let geometry = (&self.vertices, self.count);
        depth_pass(device, enc, &self.depth_pipeline, geometry, &view, light);
    }

    /// Camera and light uniforms of one panel (`light` is the stage's `struct Light` bytes).
    fn frame_bind_group(&self, device: &wgpu::Device, light: &[u8]) -> wgpu::BindGroup {
        let uniform = |contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("host.uniform"),
                contents,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let camera = uniform(bytemuck::cast_slice(&self.camera.to_cols_array()));
        let light = uniform(light);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host.frame"),
            layout: &self.frame_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: camera.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: light.as_entire_binding(),
                },
            ],
        })
    }

    /// One draw of the scene per panel, each in its quarter of the image.
    fn shade_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        panels: &[(wgpu::RenderPipeline, wgpu::BindGroup, wgpu::BindGroup)],
    ) {
        let (cv, dv) = (
            self.color.create_view(&Default::default()),
            self.depth.create_view(&Default::default()),
        );
        let mut pass = begin_shade_pass(enc, &cv, &dv);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        for (k, (pipeline, frame, maps)) in panels.iter().enumerate() {
            let (x, y) = ((k as u32 % 2) * PANEL.0, (k as u32 / 2) * PANEL.1);
            pass.set_viewport(x as f32, y as f32, PANEL.0 as f32, PANEL.1 as f32, 0.0, 1.0);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, frame, &[]);
            pass.set_bind_group(1, maps, &[]);
            pass.draw(0..self.count, 0..1);
        }
    }

    fn copy_color(&self, device: &wgpu::Device, enc: &mut wgpu::CommandEncoder) -> wgpu::Buffer {
        // 2 · 384 · 4 bytes per row: a multiple of COPY_BYTES_PER_ROW_ALIGNMENT (256).
        copy_color(device, enc, &self.color)
    }
}
