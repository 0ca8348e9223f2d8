//! What a frame renders into, binds and reads back, made once for a scene's shape and kept
//! across frames and [`super::Renderer::render`] calls: the G-buffer, the shadow maps, the
//! shading pass's outputs and inputs, every uniform and storage buffer (rewritten with
//! `queue.write_buffer` when a call starts), the raster passes' bind groups and the read-back
//! buffers.

use std::collections::HashMap;

use crate::gpu::read_buffer;
use crate::gpu_objects;
use crate::{scene::Scene, wgsl_mirrors::Vertex};
use crate::{technique, wgsl_mirrors::LightGpu};

use super::FrameGpu;
use super::cascade::DrawnLights;

/// Usage of textures the renderer writes and later reads back or samples.
pub(super) const TARGET: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);

/// What the kept resources depend on: a scene of the same shape reuses them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct TargetKey {
    /// Image size.
    pub size: (u32, u32),
    /// Per drawn light: shadow-map width and height (a point light's atlas) and slope-scaled
    /// bias (its raster pipeline's key).
    pub lights: Vec<((u32, u32), u32)>,
    /// Per light: whether it rasterizes a second, peeled depth ([`technique::peels`]).
    pub peels: Vec<bool>,
    /// The scene's lights: the visibility channels.
    pub visible: usize,
    /// Vertex buffer bytes.
    pub vertex_bytes: u64,
    /// Materials.
    pub materials: usize,
}

impl TargetKey {
    /// The key of `scene` drawing `drawn` with `vertices`.
    pub fn new(scene: &Scene, drawn: &DrawnLights, vertices: usize) -> Self {
        Self {
            size: (scene.width, scene.height),
            lights: drawn
                .lights
                .iter()
                .map(|l| (l.map_dims(), l.shadow.slope_bias.to_bits()))
                .collect(),
            peels: drawn
                .lights
                .iter()
                .map(|l| technique::peels(&l.shadow.technique))
                .collect(),
            visible: drawn.visible,
            vertex_bytes: (vertices * std::mem::size_of::<Vertex>()) as u64,
            materials: scene.objects.len(),
        }
    }
}

/// One light's shadow map and its raster pass's uniform and bind group.
pub(super) struct LightTarget {
    /// The raster pass's label (and timer span), `light<i>.shadow_raster`.
    pub label: String,
    /// The view of its depth map (Depth32Float, kept in [`Targets::imports`]) as the raster
    /// pass's attachment.
    pub view: wgpu::TextureView,
    /// World → light clip (the raster pass's uniform).
    pub view_proj: wgpu::Buffer,
    /// Binds `view_proj` for the light's raster pipeline.
    pub bind_group: wgpu::BindGroup,
    /// Each view's viewport in the map, draw `k` with matrix `k` of `view_proj`: the whole map,
    /// or a point light's six faces (set with the matrices by [`Targets::upload`]).
    pub viewports: Vec<[u32; 4]>,
    /// Its peel pass, where its technique reads a second depth.
    pub peel: Option<PeelTarget>,
}

/// A light's second depth map and its peel pass's bind group.
pub(super) struct PeelTarget {
    /// The pass's label (and timer span), `light<i>.shadow_peel`.
    pub label: String,
    /// The view of its second depth map (Depth32Float, kept in [`Targets::imports`] as
    /// [`technique::second_depth_name`]) as the pass's attachment.
    pub view: wgpu::TextureView,
    /// Binds the light's `view_proj` and its first depth map for the peel pipeline.
    pub bind_group: wgpu::BindGroup,
}

/// The kept resources of a frame.
pub(super) struct Targets {
    pub key: TargetKey,
    pub vertices: wgpu::Buffer,
    pub vertex_count: u32,
    pub gpos: wgpu::Texture,
    pub gnorm: wgpu::Texture,
    pub gpos_view: wgpu::TextureView,
    pub gnorm_view: wgpu::TextureView,
    pub depth_view: wgpu::TextureView,
    /// The camera's view·projection (the G-buffer pass's uniform) and its bind group.
    pub camera: wgpu::Buffer,
    pub gbuffer_bind_group: wgpu::BindGroup,
    pub lights: Vec<LightTarget>,
    /// The shadow maps by the graph's import names.
    pub imports: HashMap<String, wgpu::Texture>,
    pub materials: wgpu::Buffer,
    pub light_data: wgpu::Buffer,
    pub frame: wgpu::Buffer,
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    pub visibility: wgpu::Buffer,
    color_readback: wgpu::Buffer,
    visibility_readback: wgpu::Buffer,
}

/// A 2-D texture of one level.
pub(super) fn texture(
    device: &wgpu::Device,
    label: &str,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu_objects::texture(
        device,
        &wgpu::TextureDescriptor {
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
        },
    )
}

/// A buffer of `size` bytes (at least 16).
fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    gpu_objects::buffer(
        device,
        &wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16).div_ceil(4) * 4,
            usage,
            mapped_at_creation: false,
        },
    )
}

/// The shading pass's image (RGBA8, sRGB-encoded values).
pub(super) fn color_target(device: &wgpu::Device, size: (u32, u32)) -> wgpu::Texture {
    texture(
        device,
        "shadowgraph.color",
        size,
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
    )
}

/// Bytes per row of the colour read-back: RGBA8 rows padded to wgpu's copy alignment.
fn color_row(width: u32) -> u32 {
    (4 * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

/// A bind group of one uniform buffer at binding 0.
pub(super) fn uniform_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffer: &wgpu::Buffer,
) -> wgpu::BindGroup {
    gpu_objects::bind_group(
        device,
        &wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            }],
        },
    )
}

/// Light `i`'s second depth map (`side`², imported as [`technique::second_depth_name`]) and
/// its peel pass's bind group over `view_proj` and the first depth map `first`.
fn peel_target(
    device: &wgpu::Device,
    i: usize,
    side: u32,
    layout: &wgpu::BindGroupLayout,
    view_proj: &wgpu::Buffer,
    first: &wgpu::Texture,
    imports: &mut HashMap<String, wgpu::Texture>,
) -> PeelTarget {
    let second = texture(
        device,
        "shadowgraph.second_depth",
        (side, side),
        wgpu::TextureFormat::Depth32Float,
        TARGET,
    );
    let first_view = super::renderer::depth_only_view(first);
    let bind_group = gpu_objects::bind_group(
        device,
        &wgpu::BindGroupDescriptor {
            label: Some("shadowgraph.shadow_peel"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: view_proj.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&first_view),
                },
            ],
        },
    );
    let view = gpu_objects::view(&second, &Default::default());
    imports.insert(technique::second_depth_name(i), second);
    PeelTarget {
        label: format!("light{i}.shadow_peel"),
        view,
        bind_group,
    }
}

impl Targets {
    /// Makes the resources of `key`; `gbuffer_layout` and `raster_layouts` (one per light)
    /// are the layouts of the G-buffer and each light's raster pipeline (and its peel
    /// pipeline's, where it peels).
    pub fn new(
        device: &wgpu::Device,
        key: TargetKey,
        gbuffer_layout: &wgpu::BindGroupLayout,
        raster_layouts: &[(wgpu::BindGroupLayout, Option<wgpu::BindGroupLayout>)],
    ) -> Self {
        use wgpu::BufferUsages as B;
        use wgpu::TextureFormat as F;
        let size = key.size;
        let gpos = texture(
            device,
            "shadowgraph.g_position",
            size,
            F::Rgba32Float,
            TARGET,
        );
        let gnorm = texture(device, "shadowgraph.g_normal", size, F::Rgba32Float, TARGET);
        let cam_depth = texture(
            device,
            "shadowgraph.camera_depth",
            size,
            F::Depth32Float,
            TARGET,
        );
        let camera = buffer(device, "shadowgraph.camera", 64, B::UNIFORM | B::COPY_DST);
        let gbuffer_bind_group =
            uniform_group(device, "shadowgraph.gbuffer", gbuffer_layout, &camera);
        let mut lights = Vec::new();
        let mut imports = HashMap::new();
        for (i, (&(dims, _), (layout, peel_layout))) in
            key.lights.iter().zip(raster_layouts).enumerate()
        {
            let depth = texture(
                device,
                "shadowgraph.shadow_map",
                dims,
                F::Depth32Float,
                TARGET,
            );
            let view_proj = buffer(
                device,
                "shadowgraph.light_view",
                super::renderer::VIEW_BYTES,
                B::UNIFORM | B::COPY_DST,
            );
            let peel = peel_layout
                .as_ref()
                .map(|l| peel_target(device, i, dims.0, l, &view_proj, &depth, &mut imports));
            imports.insert(technique::depth_name(i), depth.clone());
            lights.push(LightTarget {
                label: format!("light{i}.shadow_raster"),
                view: gpu_objects::view(&depth, &Default::default()),
                bind_group: uniform_group(device, "shadowgraph.shadow_depth", layout, &view_proj),
                view_proj,
                viewports: Vec::new(),
                peel,
            });
        }
        let color = color_target(device, size);
        let pixels = u64::from(size.0) * u64::from(size.1);
        let vis_bytes = pixels * key.visible.max(1) as u64 * 4;
        let light_bytes = (key.lights.len() * std::mem::size_of::<LightGpu>()) as u64;
        let frame_bytes = std::mem::size_of::<FrameGpu>() as u64;
        Self {
            vertices: buffer(
                device,
                "shadowgraph.vertices",
                key.vertex_bytes,
                B::VERTEX | B::COPY_DST,
            ),
            vertex_count: 0,
            gpos_view: gpu_objects::view(&gpos, &Default::default()),
            gnorm_view: gpu_objects::view(&gnorm, &Default::default()),
            depth_view: gpu_objects::view(&cam_depth, &Default::default()),
            gpos,
            gnorm,
            camera,
            gbuffer_bind_group,
            lights,
            imports,
            materials: buffer(
                device,
                "shadowgraph.materials",
                16 * key.materials as u64,
                B::STORAGE | B::COPY_DST,
            ),
            light_data: buffer(
                device,
                "shadowgraph.lights",
                light_bytes,
                B::STORAGE | B::COPY_DST,
            ),
            frame: buffer(
                device,
                "shadowgraph.frame",
                frame_bytes,
                B::UNIFORM | B::COPY_DST,
            ),
            color_view: gpu_objects::view(&color, &Default::default()),
            color,
            visibility: buffer(
                device,
                "shadowgraph.visibility",
                vis_bytes,
                B::STORAGE | B::COPY_SRC,
            ),
            color_readback: buffer(
                device,
                "shadowgraph.color.readback",
                u64::from(color_row(size.0)) * u64::from(size.1),
                B::COPY_DST | B::MAP_READ,
            ),
            visibility_readback: buffer(
                device,
                "shadowgraph.visibility.readback",
                vis_bytes,
                B::COPY_DST | B::MAP_READ,
            ),
            key,
        }
    }

    /// Writes `scene`'s data into the kept buffers (staged by the queue before the next
    /// submission): vertices, materials, lights, the frame constants and every view·projection.
    pub fn upload(
        &mut self,
        queue: &wgpu::Queue,
        scene: &Scene,
        drawn: &DrawnLights,
        vertices: &[Vertex],
    ) {
        queue.write_buffer(&self.vertices, 0, bytemuck::cast_slice(vertices));
        self.vertex_count = vertices.len() as u32;
        let materials: Vec<[f32; 4]> = scene
            .objects
            .iter()
            .map(|o| o.color.extend(1.0).to_array())
            .collect();
        queue.write_buffer(&self.materials, 0, bytemuck::cast_slice(&materials));
        queue.write_buffer(&self.light_data, 0, bytemuck::cast_slice(&drawn.gpu));
        let frame = FrameGpu::new(scene, scene.width, scene.height);
        queue.write_buffer(&self.frame, 0, bytemuck::bytes_of(&frame));
        let camera = scene
            .camera
            .view_proj(scene.width as f32 / scene.height as f32)
            .to_cols_array();
        queue.write_buffer(&self.camera, 0, bytemuck::cast_slice(&camera));
        for (t, l) in self.lights.iter_mut().zip(&drawn.lights) {
            let views = l.raster_views();
            let vp: Vec<f32> = views.iter().flat_map(|(m, _)| *m).collect();
            queue.write_buffer(&t.view_proj, 0, bytemuck::cast_slice(&vp));
            t.viewports = views.iter().map(|(_, v)| *v).collect();
        }
    }

    /// Copies the image and the visibility into the read-back buffers and reads them: the
    /// image tightly packed (RGBA8 rows), the visibility per pixel per light.
    pub fn read_back(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> crate::error::Result<(Vec<u8>, Vec<f32>)> {
        let (w, h) = self.key.size;
        let row = color_row(w);
        let mut enc = device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            self.color.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.color_readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        let vis_bytes = self.visibility.size();
        enc.copy_buffer_to_buffer(&self.visibility, 0, &self.visibility_readback, 0, vis_bytes);
        crate::gpu::submit_and_wait(device, queue, enc, "read back")?;
        let raw = read_buffer(device, &self.color_readback)?;
        let rgba = raw
            .chunks(row as usize)
            .flat_map(|r| &r[..4 * w as usize])
            .copied()
            .collect();
        let pixels = (u64::from(w) * u64::from(h)) as usize * self.key.visible;
        let mut vis: Vec<f32> =
            bytemuck::cast_slice(&read_buffer(device, &self.visibility_readback)?).to_vec();
        vis.truncate(pixels);
        Ok((rgba, vis))
    }
}
