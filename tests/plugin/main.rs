//! The plug-in stage inside a host: from a depth texture the host rasterized itself, the
//! stage's maps equal the renderer's, and the exported WGSL with `PrefilterOutput::light`
//! gives the renderer's visibility; recording every frame keeps memory constant; a size
//! change reallocates; per-kernel timings.

#[path = "../common/mod.rs"]
mod common;
use common::host::{host_depth, host_depth_views};
use shadowgraph::low_level::exec::ComputeKernel;
use shadowgraph::low_level::gpu::{
    Gpu, read_float_texture, read_resource_texture, submit_and_wait,
};
use shadowgraph::low_level::render::{Frame, RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique::depth_name;
use shadowgraph::{LightParams, Prefilter, PrefilterConfig, StageError};
use std::path::{Path, PathBuf};
use wgpu::util::DeviceExt;

mod cascades;
mod stage;

/// Per pixel of `frame`, the surface's world-space differentials along x and y (two vec4s),
/// as the renderer computes them for its footprints.
fn differentials(frame: &Frame, scene: &Scene) -> Vec<f32> {
    let rays =
        shadowgraph::low_level::model::CameraRays::new(&scene.camera, frame.width, frame.height);
    let eye = scene.camera.position.as_dvec3();
    let mut diffs = Vec::with_capacity(8 * (frame.width * frame.height) as usize);
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = 4 * (y * frame.width + x) as usize;
            let p = glam::Vec3::from_slice(&frame.position[i..i + 3]).as_dvec3();
            let n = glam::Vec3::from_slice(&frame.normal[i..i + 3]).as_dvec3();
            let n = if n.length() > 0.0 {
                n.normalize()
            } else {
                glam::DVec3::Y
            };
            let (dx, dy) =
                shadowgraph::low_level::cpu::shade::pixel_differentials(eye, &rays, x, y, p, n);
            for v in [dx, dy] {
                diffs.extend([v.x as f32, v.y as f32, v.z as f32, 0.0]);
            }
        }
    }
    diffs
}

/// A host probe's last steps: its maps' bind group from `entries`, one invocation a pixel,
/// `vis` read back.
fn run_probe(
    g: &Gpu,
    kernel: &ComputeKernel,
    mut enc: wgpu::CommandEncoder,
    bg0: &wgpu::BindGroup,
    entries: &[wgpu::BindGroupEntry],
    vis: &wgpu::Buffer,
    n: usize,
) -> Vec<f32> {
    let d = &g.device;
    let bg1 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host.probe.maps"),
        layout: &kernel.layouts[1],
        entries,
    });
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, bg0, &[]);
        pass.set_bind_group(1, &bg1, &[]);
        pass.dispatch_workgroups((n as u32).div_ceil(64), 1, 1);
    }
    let readback = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("host.probe.readback"),
        size: vis.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_buffer_to_buffer(vis, 0, &readback, 0, vis.size());
    submit_and_wait(d, &g.queue, enc, "host probe").expect("submit");
    let raw = shadowgraph::low_level::gpu::read_buffer(d, &readback).expect("readback");
    bytemuck::cast_slice(&raw).to_vec()
}

fn scenes() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut v: Vec<PathBuf> = [root.clone(), root.join("techniques")]
        .iter()
        .flat_map(|d| {
            std::fs::read_dir(d)
                .expect("scenes/")
                .map(|e| e.expect("entry").path())
        })
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    v
}

/// A soft light's f64 inputs from the renderer's shade map (`None` for other techniques).
fn soft_inputs(
    g: &Gpu,
    frame: &Frame,
    light: &shadowgraph::Light,
    li: usize,
) -> Option<common::soft::SoftInputs> {
    light.shadow.technique.soft()?;
    let sm = &frame.shade_maps[li];
    let level0 = shadowgraph::low_level::cpu::Texels::from_f32(
        sm.width as usize,
        sm.height as usize,
        sm.channels,
        &sm.data,
    );
    common::soft::SoftInputs::new(light, &level0, common::soft_maps::trig_error(g))
}

/// How far two runs of a soft light may differ at pixel `px`: 1e-5 or twice the propagated
/// tolerance of the f64 reference, `None` where it jumps or the blocker threshold could flip.
fn soft_allowance(
    soft: &common::soft::SoftInputs,
    light: &shadowgraph::Light,
    frame: &Frame,
    px: usize,
) -> Option<f64> {
    let lg = shadowgraph::LightGpu::new(light);
    let p = &frame.position[4 * px..4 * px + 3];
    let n = &frame.normal[4 * px..4 * px + 3];
    let s = shadowgraph::low_level::cpu::light::sample(
        &lg,
        glam::DVec3::new(p[0].into(), p[1].into(), p[2].into()),
        glam::DVec3::new(n[0].into(), n[1].into(), n[2].into()).normalize(),
    );
    let v = common::robust(&s, light.shadow_map as usize, |t| soft.reference(&lg, t))?;
    soft.tolerance(&lg, &s, v).map(|t| (2.0 * t).max(1e-5))
}
