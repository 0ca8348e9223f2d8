//! What the example hosts share: their geometry, device, render-target and pipeline-state
//! helpers and readback — plain wgpu, nothing of shadowgraph's beyond the timer features.
#![allow(dead_code, reason = "each example uses a subset")]

use anyhow::{Context, Result};
use glam::Vec3;
use shadowgraph::{LightParams, TIMER_FEATURES};
use wgpu::util::DeviceExt;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub color: [f32; 3],
}

pub async fn device() -> Result<(wgpu::Device, wgpu::Queue)> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = instance
        .request_adapter(&Default::default())
        .await
        .context("no GPU adapter (without a GPU: apt-get install mesa-vulkan-drivers)")?;
    // Per-kernel timing writes timestamps between passes: both timer features or none.
    let features = adapter.features() & TIMER_FEATURES;
    Ok(adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("host"),
            required_features: features,
            ..Default::default()
        })
        .await?)
}

pub fn target(
    device: &wgpu::Device,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.target"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        // The shadow map is also read by the stage: TEXTURE_BINDING.
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

pub fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

const ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];

pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ATTRIBUTES,
    }
}

pub fn depth_state(slope_scale: f32) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: wgpu::TextureFormat::Depth32Float,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: wgpu::DepthBiasState {
            constant: 0,
            slope_scale,
            clamp: 0.0,
        },
    }
}

pub fn clear_depth(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

pub fn read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    buffer.map_async(wgpu::MapMode::Read, .., |r| {
        if let Err(e) = r {
            eprintln!("readback failed: {e}");
        }
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let data = buffer.get_mapped_range(..)?.to_vec();
    buffer.unmap();
    Ok(data)
}

/// A ground slab, three boxes and a thin pillar.
pub fn scene() -> Vec<Vertex> {
    let mut v = Vec::new();
    cuboid(
        &mut v,
        Vec3::new(0.0, -0.05, 0.0),
        Vec3::new(12.0, 0.1, 12.0),
        [0.75, 0.74, 0.7],
    );
    cuboid(
        &mut v,
        Vec3::new(-1.2, 0.6, 0.4),
        Vec3::new(1.2, 1.2, 1.2),
        [0.8, 0.35, 0.3],
    );
    cuboid(
        &mut v,
        Vec3::new(1.4, 0.35, -0.6),
        Vec3::new(0.9, 0.7, 1.8),
        [0.3, 0.5, 0.8],
    );
    cuboid(
        &mut v,
        Vec3::new(0.5, 1.6, 1.8),
        Vec3::new(0.8, 0.2, 0.8),
        [0.4, 0.7, 0.4],
    );
    cuboid(
        &mut v,
        Vec3::new(0.5, 0.75, 1.8),
        Vec3::new(0.12, 1.5, 0.12),
        [0.6, 0.6, 0.6],
    );
    v
}

pub fn cuboid(out: &mut Vec<Vertex>, center: Vec3, size: Vec3, color: [f32; 3]) {
    let half = 0.5 * size;
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let n = Vec3::AXES[axis] * sign;
            let (u, w) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
            let (hu, hw) = (u * half[(axis + 1) % 3], w * half[(axis + 2) % 3]);
            let c = center + n * half[axis];
            let corners = [c - hu - hw, c + hu - hw, c + hu + hw, c - hu + hw];
            for i in [0, 1, 2, 0, 2, 3] {
                out.push(Vertex {
                    position: corners[i].to_array(),
                    normal: n.to_array(),
                    color,
                });
            }
        }
    }
}

/// The hosts' depth pass from a light.
const DEPTH: &str = "
@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;
@vertex
fn vs_main(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view_proj * vec4<f32>(p, 1.0);
}
";

/// The depth-only pipeline of the hosts' shadow pass (slope-scaled bias 1.5).
pub fn depth_pipeline(device: &wgpu::Device) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host.depth"),
        source: wgpu::ShaderSource::Wgsl(DEPTH.into()),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host.depth"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(vertex_layout())],
        },
        primitive: Default::default(),
        depth_stencil: Some(depth_state(1.5)),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

/// The scene's depth from `light` into `view` (a depth texture, or one layer of an array).
pub fn depth_pass(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    (vertices, count): (&wgpu::Buffer, u32),
    view: &wgpu::TextureView,
    light: &LightParams,
) {
    let vp = (light.projection * light.view).to_cols_array();
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host.light_view_proj"),
        contents: bytemuck::cast_slice(&vp),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host.depth"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host.depth"),
        color_attachments: &[],
        depth_stencil_attachment: Some(clear_depth(view)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &bg, &[]);
    pass.set_vertex_buffer(0, vertices.slice(..));
    pass.draw(0..count, 0..1);
}

/// A shading pipeline from `wgsl` (`vs_main`, `fs_main`) over the scene's vertices, writing
/// `Rgba8UnormSrgb` with a depth test, bind groups laid out by `layouts`.
pub fn shade_pipeline(
    device: &wgpu::Device,
    wgsl: &str,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host.shade"),
        source: wgpu::ShaderSource::Wgsl(wgsl.into()),
    });
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().copied().map(Some).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("host.shade"),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host.shade"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(vertex_layout())],
        },
        primitive: Default::default(),
        depth_stencil: Some(depth_state(0.0)),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::TextureFormat::Rgba8UnormSrgb.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The shading pass into `color` and `depth`, both cleared (sky colour, far).
pub fn begin_shade_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host.shade"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: 0.3,
                    g: 0.38,
                    b: 0.5,
                    a: 1.0,
                }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(clear_depth(depth)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
    .forget_lifetime()
}

/// A readback buffer and the copy of `color` (RGBA8, rows a multiple of 256 bytes) into it.
pub fn copy_color(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    color: &wgpu::Texture,
) -> wgpu::Buffer {
    let (w, h) = (color.width(), color.height());
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("host.readback"),
        size: u64::from(w * h * 4),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_texture_to_buffer(
        color.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 4),
                rows_per_image: Some(h),
            },
        },
        color.size(),
    );
    buffer
}
