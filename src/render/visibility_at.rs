//! [`visibility_at`]: the real shading kernel evaluated at given points on given maps.

use bytemuck::Zeroable;
use glam::Vec3;

use crate::error::{Error, Result};
use crate::gpu::{read_buffer, submit_and_wait, write_texture};
use crate::gpu_objects;
use crate::graph::Graph;
use crate::model::Light;
use crate::technique;

use super::FrameGpu;
use super::renderer::{Renderer, ShadeInputs, record_shade};

/// A map handed to [`visibility_at`]: what the light's technique reads (linear depth as R32Float,
/// moments as Rg32Float, …), never the raw depth of hardware PCF. Two moments of a light that
/// stores them in f16 are given as Rg32Float too; `visibility_at` packs them as the stage does.
pub struct MapData<'a> {
    /// Side length of level 0.
    pub size: u32,
    /// Texel format of `data`: a 32-bit float format, or `Rgba32Uint` for a fixed-point
    /// summed-area table, whose words `data` carries bit for bit (`f32::from_bits`).
    pub format: wgpu::TextureFormat,
    /// Mip levels in `data` (1 for a plain map).
    pub mips: u32,
    /// Every level's texels, row-major, level 0 first (level `m` is `max(1, size >> m)` wide).
    pub data: &'a [f32],
}

impl<'a> MapData<'a> {
    /// A linear depth map.
    pub fn linear(size: u32, data: &'a [f32]) -> Self {
        Self::new(size, wgpu::TextureFormat::R32Float, data)
    }

    /// A one-level map of `format`.
    pub fn new(size: u32, format: wgpu::TextureFormat, data: &'a [f32]) -> Self {
        Self {
            size,
            format,
            mips: 1,
            data,
        }
    }
}

/// Evaluates each light's visibility at `points` (position, unit normal) on the given maps
/// with the real shading kernel. `maps` lists every light's maps in binding order (one per
/// light; CSM: one per two terms), summed-area tables that the light's shading reads
/// interleaved in one texture (`technique::map_tables`) one by one: `visibility_at` interleaves
/// them. Returns `vis[point * lights + light]`.
pub fn visibility_at(
    renderer: &mut Renderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    lights: &[Light],
    maps: &[MapData],
    points: &[(Vec3, Vec3)],
) -> Result<Vec<f32>> {
    // Per binding, the tables it holds (1 for a map).
    let held: Vec<usize> = lights
        .iter()
        .flat_map(|l| technique::map_tables(l).into_iter().map(|t| t.len()))
        .collect();
    let needed: usize = held.iter().sum();
    if maps.len() != needed || points.is_empty() {
        return Err(Error::Invalid(format!(
            "visibility_at needs {needed} map(s) for these lights and at least one point"
        )));
    }
    let w = (points.len() as u32).min(256);
    let h = (points.len() as u32).div_ceil(w);
    let mut pos = vec![[0.0f32; 4]; (w * h) as usize];
    let mut nor = vec![[0.0f32; 4]; (w * h) as usize];
    for (i, (p, n)) in points.iter().enumerate() {
        pos[i] = p.extend(1.0).to_array();
        nor[i] = n.extend(0.0).to_array();
    }
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    let points_texture = |label| {
        super::targets::texture(
            device,
            label,
            (w, h),
            wgpu::TextureFormat::Rgba32Float,
            usage,
        )
    };
    let gpos = points_texture("shadowgraph.visibility_at.position");
    let gnorm = points_texture("shadowgraph.visibility_at.normal");
    write_texture(queue, &gpos, bytemuck::cast_slice(&pos));
    write_texture(queue, &gnorm, bytemuck::cast_slice(&nor));
    // A light whose shading reads packed f16 moments (`technique::maps_packed`) gets its
    // two-channel maps packed here (exact for values read back from an f16 map).
    let packed: Vec<bool> = lights
        .iter()
        .enumerate()
        .flat_map(|(i, l)| {
            let n = technique::add_light_nodes(&mut Graph::default(), i, l)
                .maps
                .len();
            std::iter::repeat_n(technique::maps_packed(l), n)
        })
        .collect();
    let mut views = Vec::new();
    let mut rest = maps;
    for (&n, packed) in held.iter().zip(packed) {
        let (tables, after) = rest.split_at(n);
        rest = after;
        // Several tables of one binding: one texture n times as wide.
        let interleaved = interleave(tables)?;
        let m = match &interleaved {
            Some(i) => MapData::new(i.size, i.format, &i.data),
            None => MapData { ..tables[0] },
        };
        let channels = crate::gpu::float_channels(m.format).unwrap_or(0);
        let packed = packed && channels == 2;
        let side = |l: u32| (m.size >> l).max(1) as usize;
        let texels: usize = (0..m.mips).map(|l| side(l) * side(l)).sum();
        let is_f32 = crate::graph::texel_bytes(m.format) == 4 * channels as u64;
        if !is_f32 || channels == 0 || m.mips == 0 || m.data.len() != texels * channels * n {
            return Err(Error::Invalid(format!(
                "a {0}x{0} {1:?} map of {3} level(s) needs {2} f32 values",
                m.size,
                m.format,
                texels * channels.max(1),
                m.mips
            )));
        }
        let t = gpu_objects::texture(
            device,
            &wgpu::TextureDescriptor {
                label: Some("shadowgraph.visibility_at.map"),
                size: wgpu::Extent3d {
                    width: m.size * n as u32,
                    height: m.size,
                    depth_or_array_layers: 1,
                },
                mip_level_count: m.mips,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: if packed {
                    crate::graph::texture_format(crate::graph::PACKED_F16X2)
                } else {
                    m.format
                },
                usage,
                view_formats: &[],
            },
        );
        let mut at = 0;
        for level in 0..m.mips {
            let count = side(level) * side(level) * channels * n;
            let values = &m.data[at..at + count];
            let bytes: Vec<u8> = if packed {
                bytemuck::cast_slice(&crate::gpu::pack_f16x2(values)).to_vec()
            } else {
                bytemuck::cast_slice(values).to_vec()
            };
            crate::gpu::write_texture_level(queue, &t, level, &bytes);
            at += count;
        }
        views.push(gpu_objects::view(&t, &Default::default()));
    }
    let frame = FrameGpu {
        size: [w, h],
        light_count: lights.len() as u32,
        ..FrameGpu::zeroed()
    };
    let at = ShadePoints {
        maps: &views,
        frame: &frame,
        gpos: &gpos,
        gnorm: &gnorm,
    };
    let visibility = renderer.shade_points(device, queue, lights, &at)?;
    let readback = gpu_objects::buffer(
        device,
        &wgpu::BufferDescriptor {
            label: Some("shadowgraph.visibility.readback"),
            size: visibility.size(),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        },
    );
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(&visibility, 0, &readback, 0, visibility.size());
    submit_and_wait(device, queue, enc, "visibility_at readback")?;
    let mut vis: Vec<f32> = bytemuck::cast_slice(&read_buffer(device, &readback)?).to_vec();
    vis.truncate(points.len() * lights.len());
    Ok(vis)
}

/// Several fixed-point tables of one binding, interleaved along x as the graph stores them
/// (`crate::graph::Graph::interleaved`).
struct Interleaved {
    /// One table's side (the texture is as many times as wide as there are tables).
    size: u32,
    /// The widest table's format.
    format: wgpu::TextureFormat,
    /// Row-major, every table's texel in turn, padded with zeros to the widest's channels.
    data: Vec<f32>,
}

/// `tables` interleaved; `None` for a binding of one table or map.
fn interleave(tables: &[MapData<'_>]) -> Result<Option<Interleaved>> {
    let [first, _, ..] = tables else {
        return Ok(None);
    };
    let channels = |m: &MapData| crate::gpu::float_channels(m.format).unwrap_or(0);
    let texels = (first.size * first.size) as usize;
    if tables.iter().any(|m| {
        m.size != first.size
            || m.mips != 1
            || channels(m) == 0
            || m.data.len() != texels * channels(m)
    }) {
        return Err(Error::Invalid(format!(
            "{} tables of one binding need one level each of {1}x{1} texels",
            tables.len(),
            first.size
        )));
    }
    let widest = tables.iter().max_by_key(|m| channels(m)).unwrap_or(first);
    let c = channels(widest);
    let mut data = Vec::with_capacity(texels * c * tables.len());
    for t in 0..texels {
        for m in tables {
            let k = channels(m);
            data.extend_from_slice(&m.data[t * k..(t + 1) * k]);
            data.extend(std::iter::repeat_n(0.0, c - k));
        }
    }
    Ok(Some(Interleaved {
        size: first.size,
        format: widest.format,
        data,
    }))
}

/// What [`Renderer::shade_points`] evaluates at.
pub(super) struct ShadePoints<'a> {
    /// Light by light, the maps in binding order.
    pub maps: &'a [wgpu::TextureView],
    pub frame: &'a FrameGpu,
    pub gpos: &'a wgpu::Texture,
    pub gnorm: &'a wgpu::Texture,
}

impl Renderer {
    /// Runs the shading kernel for `lights` once over positions and normals in `at` (for
    /// `visibility_at`: no camera, the frame's own buffers), returning its visibility buffer.
    pub(super) fn shade_points(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        lights: &[Light],
        at: &ShadePoints,
    ) -> Result<wgpu::Buffer> {
        use wgpu::BufferUsages as B;
        let kernel = self.shade_kernel(device, lights)?;
        let init = |label, bytes: &[u8], usage| {
            gpu_objects::buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage,
                },
            )
        };
        let gpu_lights: Vec<crate::wgsl_mirrors::LightGpu> = lights
            .iter()
            .map(crate::wgsl_mirrors::LightGpu::new)
            .collect();
        let (w, h) = (at.frame.size[0], at.frame.size[1]);
        let color = super::targets::color_target(device, (w, h));
        let vis_bytes = (u64::from(w) * u64::from(h) * lights.len().max(1) as u64 * 4).max(4);
        let visibility = gpu_objects::buffer(
            device,
            &wgpu::BufferDescriptor {
                label: Some("shadowgraph.visibility"),
                size: vis_bytes,
                usage: B::STORAGE | B::COPY_SRC,
                mapped_at_creation: false,
            },
        );
        let views = [
            gpu_objects::view(at.gpos, &Default::default()),
            gpu_objects::view(at.gnorm, &Default::default()),
            gpu_objects::view(&color, &Default::default()),
        ];
        let inputs = ShadeInputs {
            gpos: &views[0],
            gnorm: &views[1],
            materials: &init(
                "shadowgraph.materials",
                bytemuck::cast_slice(&[[1.0f32; 4]]),
                B::STORAGE,
            ),
            lights: &init(
                "shadowgraph.lights",
                bytemuck::cast_slice(&gpu_lights),
                B::STORAGE,
            ),
            frame: &init(
                "shadowgraph.frame",
                bytemuck::bytes_of(at.frame),
                B::UNIFORM,
            ),
            color: &views[2],
            visibility: &visibility,
        };
        let maps: Vec<wgpu::BindingResource> = at
            .maps
            .iter()
            .map(wgpu::BindingResource::TextureView)
            .collect();
        let groups = self.shade_bind_groups(device, &kernel, &inputs, &maps)?;
        let mut enc = device.create_command_encoder(&Default::default());
        record_shade(&mut enc, &kernel, &groups, (w, h), None);
        submit_and_wait(device, queue, enc, "visibility_at")?;
        Ok(visibility)
    }
}
