//! Ground truth for the shadow techniques.
//!
//! - [`area_light_truth`] (GPU): the light's emitter ([`emitter`]) sampled at K points on a
//!   stratified jittered grid, one hard shadow map per sample at high resolution, visibility
//!   per camera pixel = the fraction of samples that see it, accumulated on the GPU (one raster
//!   pass and one compute pass per sample, one readback at the end).
//! - [`raycast::ray_cast_truth`] (CPU, f64): the same emitter samples seen by shadow rays
//!   through a BVH of the scene's triangles, from first hits of primary camera rays; the
//!   independent check of the GPU truth.
//! - [`pcf::pcf_box`] (CPU, f64): brute-force PCF with a box of any width over a linear depth
//!   map, edges exact to the sub-texel — the filtered hard shadow that VSM, EVSM, ESM, MSM and
//!   CSM approximate.
//!
//! **Relevant pixels** ([`relevant`]): covered by geometry, facing the light (`N·L > 0` toward
//! the light's centre), inside the light's frustum and depth range, and for a spot light inside
//! its cone. Errors are measured there only.
//!
//! **Bias policy**: each sample's hard shadow map uses the light's own settings — the
//! rasterizer's slope-scaled bias, the constant `bias` (linear depth units, the same for every
//! sample since all samples share the light's near/far along its axis) and the normal offset of
//! `normal_bias` texels *of the truth map* (so it shrinks as the truth's resolution grows). The
//! truth therefore shares the scene's bias: a technique is not charged for the bias the scene
//! chose, and the CPU ray cast (no bias, only its own triangle skipped) measures what the bias
//! costs.

pub mod bvh;
pub mod emitter;
pub mod pcf;
pub mod peel;
pub mod raycast;

use glam::DVec3;
use wgpu::util::DeviceExt;

use crate::error::{Error, Result};
use crate::gpu::{read_buffer, submit_and_wait, write_texture};
use crate::render::{RenderOptions, Renderer, ShadowRaster};
use crate::wgsl_mirrors::LightGpu;
use crate::{
    model::{Light, LightKind, Technique},
    scene::Scene,
};

/// Samples recorded per submission (bounds the per-sample buffers alive at once).
const BATCH: usize = 16;

/// Largest default truth resolution (a 8192² depth map is 256 MiB).
const MAX_DEFAULT_RESOLUTION: u32 = 8192;

/// Most emitter samples the truth takes: it rasterizes a shadow map a sample and keeps a record
/// of about half a KiB a sample, so `--k 100000000` asked for 50 GB at once and aborted (and
/// would render for hours on any GPU). 65 536 is 256 times the default K.
pub const MAX_EMITTER_SAMPLES: usize = 65_536;

/// Where the emitter is sampled.
#[derive(Clone, Debug, PartialEq)]
pub enum Emitter {
    /// `k` points on a stratified jittered grid ([`emitter::stratified_offsets`]).
    Stratified {
        /// Number of samples K.
        k: u32,
        /// Seed of the jitter.
        seed: u64,
    },
    /// Explicit offsets in units of the light's size, each in `[−½, ½]²`.
    Offsets(Vec<[f64; 2]>),
}

impl Emitter {
    /// How many samples it takes (before any are made).
    pub fn count(&self) -> usize {
        match self {
            Emitter::Stratified { k, .. } => *k as usize,
            Emitter::Offsets(o) => o.len(),
        }
    }

    /// The offsets (units of the light's size).
    pub fn offsets(&self) -> Vec<[f64; 2]> {
        match self {
            Emitter::Stratified { k, seed } => emitter::stratified_offsets(*k, *seed),
            Emitter::Offsets(o) => o.clone(),
        }
    }
}

/// How [`area_light_truth`] samples and rasterizes.
#[derive(Clone, Debug, PartialEq)]
pub struct TruthOptions {
    /// Emitter samples.
    pub emitter: Emitter,
    /// Side of each sample's shadow map; `None`: `max(2048, 2 × the light's shadow_map)`,
    /// at most 8192 and the device's limit.
    pub resolution: Option<u32>,
}

impl Default for TruthOptions {
    /// K = 256 stratified samples (seed 1) at the default resolution.
    fn default() -> Self {
        Self {
            emitter: Emitter::Stratified { k: 256, seed: 1 },
            resolution: None,
        }
    }
}

/// Ground-truth visibility per pixel and light.
#[derive(Clone, Debug)]
pub struct Truth {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Number of lights.
    pub lights: usize,
    /// Visibility in [0, 1]: `visibility[px * lights + l]` (1 on the background and where no
    /// sample's map covers the point; meaningful where `mask` is set).
    pub visibility: Vec<f32>,
    /// Relevant receivers ([`relevant`]), same indexing.
    pub mask: Vec<bool>,
    /// Emitter samples per light.
    pub samples: usize,
    /// Shadow-map side used per light.
    pub resolution: Vec<u32>,
}

/// Whether a receiver at `p` with unit normal `n` is one the light `light` lights: facing its
/// centre (`N·L > 0`), inside its frustum and depth range, and for a spot inside its cone.
pub fn relevant(light: &Light, p: DVec3, n: DVec3) -> bool {
    let g = LightGpu::new(light);
    let s = crate::cpu::light::sample(&g, p, DVec3::ZERO);
    let faces = n.dot(crate::cpu::light::to_light(&g, p)) > 0.0;
    let in_cone = match light.kind {
        LightKind::Directional { .. } | LightKind::Point => true,
        LightKind::Spot { fov_degrees } => {
            let axis = (light.target - light.position).as_dvec3().normalize();
            (p - light.position.as_dvec3()).normalize().dot(axis)
                >= (0.5 * f64::from(fov_degrees).to_radians()).cos()
        }
    };
    s.inside && faces && in_cone
}

/// Distance of `p` along `light`'s axis from its position (a point light's: along the axis of
/// the face that sees `p`).
pub fn axis_distance(light: &Light, p: DVec3) -> f64 {
    if light.kind == LightKind::Point {
        return (p - light.position.as_dvec3()).abs().max_element();
    }
    let (_, _, axis) = emitter::frame(light);
    (p - light.position.as_dvec3()).dot(axis)
}

/// The default truth resolution for `light` on a device allowing `max` texels a side.
pub fn default_resolution(light: &Light, max: u32) -> u32 {
    let (w, _) = light.map_dims();
    // A point light's atlas is three faces wide.
    let across = w / light.shadow_map.max(1);
    (2 * light.shadow_map)
        .clamp(2048, MAX_DEFAULT_RESOLUTION / across)
        .min(max / across)
}

/// The area-light ground truth of every light of `scene` at the scene's output size, on the
/// GPU (see the module docs for the emitter, the bias policy and the relevant pixels).
pub fn area_light_truth(
    renderer: &mut Renderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    opts: &TruthOptions,
) -> Result<Truth> {
    if opts.emitter.count() > MAX_EMITTER_SAMPLES {
        return Err(Error::Limit {
            what: "truth emitter samples (K)".into(),
            requested: opts.emitter.count() as u64,
            limit: MAX_EMITTER_SAMPLES as u64,
        });
    }
    let offsets = opts.emitter.offsets();
    if offsets.is_empty()
        || offsets
            .iter()
            .flatten()
            .any(|v| v.is_nan() || v.abs() > 0.5)
    {
        return Err(Error::Invalid(
            "truth: emitter offsets must be non-empty and inside [−½, ½]²".into(),
        ));
    }
    let max = device.limits().max_texture_dimension_2d;
    if let Some(r) = opts.resolution {
        if r == 0 || r > max {
            return Err(Error::Limit {
                what: "truth resolution".into(),
                requested: u64::from(r),
                limit: u64::from(max),
            });
        }
    }
    // The G-buffer, from a render whose lights use the cheapest technique.
    let mut hard = scene.clone();
    for l in &mut hard.lights {
        l.shadow.technique = Technique::Hard;
    }
    let frame = renderer.render(
        device,
        queue,
        &hard,
        RenderOptions {
            aux: true,
            repeat: 1,
            dump: false,
        },
    )?;
    let (w, h) = (frame.width, frame.height);
    let pixels = (w * h) as usize;
    let lights = scene.lights.len();
    let geometry = Geometry::upload(device, queue, scene, &frame.position, &frame.normal, (w, h));
    let mut truth = Truth {
        width: w,
        height: h,
        lights,
        visibility: vec![1.0; pixels * lights],
        mask: vec![false; pixels * lights],
        samples: offsets.len(),
        resolution: Vec::new(),
    };
    for (li, light) in scene.lights.iter().enumerate() {
        let mut z_min = f64::INFINITY;
        for px in 0..pixels {
            let (p, n) = gbuffer_point(&frame.position, &frame.normal, px);
            if frame.position[4 * px + 3] != 0.0 && relevant(light, p, n) {
                truth.mask[px * lights + li] = true;
                z_min = z_min.min(axis_distance(light, p));
            }
        }
        let res = opts
            .resolution
            .unwrap_or_else(|| default_resolution(light, max));
        let samples = emitter::samples(light, &offsets, res, z_min);
        let dims = samples.first().map_or((res, res), |s| {
            (s.light.map_size[0] as u32, s.light.map_size[1] as u32)
        });
        check_memory(li, dims, (w, h), opts.resolution.is_some())?;
        let counts = accumulate(renderer, device, queue, &geometry, light, &samples, dims)?;
        for (px, &c) in counts.iter().enumerate() {
            // Background stays 1, as the renderer reports it.
            if frame.position[4 * px + 3] != 0.0 {
                truth.visibility[px * lights + li] = c as f32 / samples.len() as f32;
            }
        }
        truth.resolution.push(res);
    }
    Ok(truth)
}

/// The truth of light `li` against the memory budget (`SHADOWGRAPH_MEMORY_BUDGET`, as every
/// frame is): its depth map of `dims` texels, which every emitter sample rasterizes in turn,
/// and the per-pixel counts of the `image` and their read-back. `asked`: the resolution came
/// from `--truth-resolution` (else the default, which the message names).
fn check_memory(li: usize, dims: (u32, u32), image: (u32, u32), asked: bool) -> Result<()> {
    let budget = crate::limits::memory_budget()?;
    let depth = u64::from(dims.0) * u64::from(dims.1) * 4;
    let counts = 2 * u64::from(image.0) * u64::from(image.1) * 4;
    if depth + counts <= budget {
        return Ok(());
    }
    let fix = if asked {
        "lower --truth-resolution"
    } else {
        "set a lower --truth-resolution (the default is twice the light's shadow_map, 2048 to 8192 texels a side)"
    };
    let b = crate::graph::print::human_bytes;
    Err(Error::Invalid(format!(
        "the truth of light[{li}] needs {} (a {}×{} depth map: {}; the image's counts: {}), more \
         than the memory budget of {} ({}): {fix} or raise the budget",
        b(depth + counts),
        dims.0,
        dims.1,
        b(depth),
        b(counts),
        b(budget),
        crate::limits::MEMORY_BUDGET_ENV
    )))
}

/// World position and unit normal of G-buffer pixel `px`.
fn gbuffer_point(position: &[f32], normal: &[f32], px: usize) -> (DVec3, DVec3) {
    let v = |d: &[f32]| DVec3::new(d[4 * px].into(), d[4 * px + 1].into(), d[4 * px + 2].into());
    (v(position), v(normal).normalize_or_zero())
}

/// The scene's vertices and the camera G-buffer on the GPU.
struct Geometry {
    vertices: wgpu::Buffer,
    count: u32,
    position: wgpu::TextureView,
    normal: wgpu::TextureView,
    size: (u32, u32),
}

impl Geometry {
    fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        position: &[f32],
        normal: &[f32],
        size: (u32, u32),
    ) -> Self {
        let verts = scene.vertices();
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadowgraph.truth.vertices"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let tex = |label, data: &[f32]| {
            let t = texture(
                device,
                label,
                size,
                wgpu::TextureFormat::Rgba32Float,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            );
            write_texture(queue, &t, bytemuck::cast_slice(data));
            t.create_view(&Default::default())
        };
        Self {
            vertices,
            count: verts.len() as u32,
            position: tex("shadowgraph.truth.position", position),
            normal: tex("shadowgraph.truth.normal", normal),
            size,
        }
    }
}

fn texture(
    device: &wgpu::Device,
    label: &str,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Per pixel, how many of `samples` see it: one raster pass and one `truth_accumulate` pass
/// per sample into one count buffer, read back once.
fn accumulate(
    renderer: &mut Renderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    geo: &Geometry,
    light: &Light,
    samples: &[emitter::EmitterSample],
    dims: (u32, u32),
) -> Result<Vec<u32>> {
    let kernel = renderer.executor.kernels.get(device, "truth_accumulate")?;
    let (w, h) = geo.size;
    let bytes = u64::from(w) * u64::from(h) * 4;
    let counts = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("shadowgraph.truth.counts"),
        contents: &vec![0u8; bytes as usize],
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    });
    let depth = texture(
        device,
        "shadowgraph.truth.depth",
        dims,
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let depth_view = depth.create_view(&Default::default());
    let groups = kernel.groups_for(w, h);
    for batch in samples.chunks(BATCH) {
        let mut enc = device.create_command_encoder(&Default::default());
        for s in batch {
            let raster = ShadowRaster {
                label: "truth.shadow_raster",
                views: &s.views,
                slope_bias: light.shadow.slope_bias,
            };
            renderer.shadow_raster(
                device,
                &mut enc,
                &raster,
                &geo.vertices,
                geo.count,
                &depth,
                None,
            )?;
            let light_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadowgraph.truth.light"),
                contents: bytemuck::bytes_of(&s.light),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let entries = [
                (0, wgpu::BindingResource::TextureView(&geo.position)),
                (1, wgpu::BindingResource::TextureView(&geo.normal)),
                (2, wgpu::BindingResource::TextureView(&depth_view)),
                (3, light_buf.as_entire_binding()),
                (4, counts.as_entire_binding()),
            ]
            .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource });
            let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadowgraph.truth_accumulate"),
                layout: &kernel.layouts[0],
                entries: &entries,
            });
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("truth_accumulate"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&kernel.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(groups[0], groups[1], 1);
        }
        submit_and_wait(device, queue, enc, "truth")?;
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("shadowgraph.truth.readback"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(&counts, 0, &staging, 0, bytes);
    submit_and_wait(device, queue, enc, "truth readback")?;
    Ok(bytemuck::cast_slice(&read_buffer(device, &staging)?).to_vec())
}
