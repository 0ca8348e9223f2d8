//! What the example hosts share: their geometry, device, render-target and pipeline-state
//! helpers and readback — plain wgpu, nothing of shadowgraph's beyond the timer features.
#![allow(dead_code, reason = "each example uses a subset")]

use anyhow::{Context, Result};
use glam::Vec3;
use shadowgraph::timer::TIMER_FEATURES;

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
