//! The renderer's raster passes: the light's depth-only pass (also the truth's emitter
//! samples, [`Renderer::shadow_raster`]) and the camera's G-buffer, with their pipelines.

use crate::error::{Error, Result};
use crate::gpu::scoped;
use crate::gpu_objects;
use crate::kernels;
use crate::timer::GpuTimer;

use super::super::targets::uniform_group;
use super::Renderer;

const VERTEX_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32];

fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<crate::wgsl_mirrors::Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRS,
    }
}

/// A depth attachment cleared to the far plane and kept.
pub(super) fn clear_depth(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// A view of all of `t` (its depth aspect for a depth texture).
pub(in crate::render) fn depth_only_view(t: &wgpu::Texture) -> wgpu::TextureView {
    gpu_objects::view(
        t,
        &wgpu::TextureViewDescriptor {
            aspect: if t.format().is_depth_stencil_format() {
                wgpu::TextureAspect::DepthOnly
            } else {
                wgpu::TextureAspect::All
            },
            ..Default::default()
        },
    )
}

/// Bytes of a raster pass's uniform: one world → clip matrix per view it may draw
/// (`VIEWS` in `kernels/shadow_depth.wgsl`).
pub(in crate::render) const VIEW_BYTES: u64 = 64 * crate::model::point::FACES as u64;

/// Records a depth-only raster pass: `count` vertices of `vertices` into `depth`, once per
/// viewport of `viewports` (x, y, width, height in texels), draw `k` with instance `k` (the
/// matrix the vertex stage picks).
#[expect(clippy::too_many_arguments, reason = "one raster pass's inputs")]
pub(super) fn raster_pass(
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    bind_group: &wgpu::BindGroup,
    depth: &wgpu::TextureView,
    vertices: &wgpu::Buffer,
    count: u32,
    viewports: &[[u32; 4]],
    timer: Option<&mut GpuTimer>,
) {
    if let Some(t) = timer {
        t.begin(enc, label);
    }
    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[],
        depth_stencil_attachment: Some(clear_depth(depth)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind_group, &[]);
    pass.set_vertex_buffer(0, vertices.slice(..));
    for (k, &[x, y, w, h]) in (0u32..).zip(viewports) {
        pass.set_viewport(x as f32, y as f32, w as f32, h as f32, 0.0, 1.0);
        pass.set_scissor_rect(x, y, w, h);
        pass.draw(0..count, k..k + 1);
    }
}

impl Renderer {
    fn raster_pipeline(
        device: &wgpu::Device,
        name: &str,
        fragment: Option<&[Option<wgpu::ColorTargetState>]>,
        bias: wgpu::DepthBiasState,
    ) -> Result<(wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
        let wgsl = kernels::resolve(name, None)?;
        let (_, refl) = kernels::reflect(name, &wgsl)?;
        let label = format!("shadowgraph.{name}");
        scoped(
            device,
            || {
                let module = gpu_objects::shader_module(
                    device,
                    wgpu::ShaderModuleDescriptor {
                        label: Some(&label),
                        source: wgpu::ShaderSource::Wgsl(wgsl.as_str().into()),
                    },
                );
                let bgl = gpu_objects::bind_group_layout(
                    device,
                    &wgpu::BindGroupLayoutDescriptor {
                        label: Some(&label),
                        entries: &refl.layout_entries(0),
                    },
                );
                let layout = gpu_objects::pipeline_layout(
                    device,
                    &wgpu::PipelineLayoutDescriptor {
                        label: Some(&label),
                        bind_group_layouts: &[Some(&bgl)],
                        immediate_size: 0,
                    },
                );
                let pipeline = gpu_objects::render_pipeline(
                    device,
                    &wgpu::RenderPipelineDescriptor {
                        label: Some(&label),
                        layout: Some(&layout),
                        vertex: wgpu::VertexState {
                            module: &module,
                            entry_point: Some("vs_main"),
                            compilation_options: Default::default(),
                            buffers: &[Some(vertex_layout())],
                        },
                        // Two-sided: planes and open meshes cast and receive from both sides.
                        primitive: wgpu::PrimitiveState::default(),
                        depth_stencil: Some(wgpu::DepthStencilState {
                            format: wgpu::TextureFormat::Depth32Float,
                            depth_write_enabled: Some(true),
                            depth_compare: Some(wgpu::CompareFunction::Less),
                            stencil: Default::default(),
                            bias,
                        }),
                        multisample: Default::default(),
                        fragment: fragment.map(|targets| wgpu::FragmentState {
                            module: &module,
                            entry_point: Some("fs_main"),
                            compilation_options: Default::default(),
                            targets,
                        }),
                        multiview_mask: None,
                        cache: None,
                    },
                );
                (pipeline, bgl)
            },
            |message| Error::Pipeline {
                kernel: name.to_string(),
                message,
            },
        )
    }

    /// The raster pipeline for slope-scaled bias `slope` (pipeline state: one per distinct
    /// value, made once) and its bind group layout.
    pub(super) fn shadow_pipeline(
        &mut self,
        device: &wgpu::Device,
        slope: f32,
    ) -> Result<&(wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
        depth_pipeline(&mut self.shadow, device, "shadow_depth", None, slope)
    }

    /// The peel pass's pipeline (`shadow_peel`: the second-nearest surface, after the first
    /// depth map) for slope-scaled bias `slope`, the same raster state as
    /// [`Renderer::shadow_pipeline`]'s, and its bind group layout.
    pub(super) fn peel_pipeline(
        &mut self,
        device: &wgpu::Device,
        slope: f32,
    ) -> Result<&(wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
        depth_pipeline(&mut self.peel, device, "shadow_peel", Some(&[]), slope)
    }

    /// The G-buffer pipeline and its layout, made once.
    pub(super) fn gbuffer_pipeline(
        &mut self,
        device: &wgpu::Device,
    ) -> Result<&(wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
        if self.gbuffer.is_none() {
            let t = Some(wgpu::ColorTargetState {
                format: wgpu::TextureFormat::Rgba32Float,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            });
            self.gbuffer = Some(Self::raster_pipeline(
                device,
                "gbuffer",
                Some(&[t.clone(), t]),
                Default::default(),
            )?);
        }
        self.gbuffer
            .as_ref()
            .ok_or_else(|| Error::Invalid("G-buffer pipeline missing".into()))
    }

    /// Records a depth-only raster pass of the scene's vertices `vbuf` (`count` vertices) into
    /// `depth` (Depth32Float) with explicit world → clip matrices and viewports: the pipeline and bias the
    /// renderer's own shadow maps use (`truth` rasterizes its emitter samples with it). Each
    /// call makes its own uniform, so that many passes can share one encoder.
    #[expect(clippy::too_many_arguments, reason = "one raster pass's inputs")]
    pub fn shadow_raster(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        raster: &ShadowRaster,
        vbuf: &wgpu::Buffer,
        count: u32,
        depth: &wgpu::Texture,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let (pipeline, layout) = self.shadow_pipeline(device, raster.slope_bias)?;
        let mut matrices = vec![0.0f32; (VIEW_BYTES / 4) as usize];
        for (m, (vp, _)) in matrices.chunks_mut(16).zip(raster.views) {
            m.copy_from_slice(vp);
        }
        let viewports: Vec<[u32; 4]> = raster.views.iter().map(|(_, v)| *v).collect();
        let ubuf = gpu_objects::buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("shadowgraph.light_view"),
                contents: bytemuck::cast_slice(&matrices),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let bg = uniform_group(device, "shadowgraph.shadow_depth", layout, &ubuf);
        let view = gpu_objects::view(depth, &Default::default());
        raster_pass(
            enc,
            raster.label,
            pipeline,
            &bg,
            &view,
            vbuf,
            count,
            &viewports,
            timer,
        );
        Ok(())
    }
}

/// Depth raster pipeline `name` (with `fragment` targets) for slope-scaled bias `slope`, from
/// `cache` (one per distinct value, made once) with its bind group layout.
fn depth_pipeline<'a>(
    cache: &'a mut std::collections::HashMap<u32, (wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    device: &wgpu::Device,
    name: &str,
    fragment: Option<&[Option<wgpu::ColorTargetState>]>,
    slope: f32,
) -> Result<&'a (wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
    match cache.entry(slope.to_bits()) {
        std::collections::hash_map::Entry::Occupied(e) => Ok(e.into_mut()),
        std::collections::hash_map::Entry::Vacant(e) => {
            let bias = wgpu::DepthBiasState {
                constant: 0,
                slope_scale: slope,
                clamp: 0.0,
            };
            Ok(e.insert(Renderer::raster_pipeline(device, name, fragment, bias)?))
        }
    }
}

/// One depth-only raster pass for [`Renderer::shadow_raster`].
#[derive(Clone, Copy, Debug)]
pub struct ShadowRaster<'a> {
    /// Pass label (and timer label).
    pub label: &'a str,
    /// Each view: world → clip, column-major (wgpu depth convention: 0 at near, 1 at far),
    /// and its viewport in the map (x, y, width, height in texels): one for a one-map light,
    /// six for a point light's faces ([`crate::model::Light::raster_views`]).
    pub views: &'a [([f32; 16], [u32; 4])],
    /// Slope-scaled depth bias (`DepthBiasState::slope_scale`).
    pub slope_bias: f32,
}
