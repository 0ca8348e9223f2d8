//! Every mistake a host can make with the plug-in stage is a typed error naming what is wrong,
//! never a panic or a wgpu validation error.

#[path = "../common/mod.rs"]
mod common;

use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::{Error, LightParams, Prefilter, PrefilterConfig, StageError};

mod creation;
mod record;

fn texture(
    g: &Gpu,
    format: wgpu::TextureFormat,
    (w, h, layers): (u32, u32, u32),
    samples: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.depth"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

const READABLE: wgpu::TextureUsages =
    wgpu::TextureUsages::RENDER_ATTACHMENT.union(wgpu::TextureUsages::TEXTURE_BINDING);

fn light() -> LightParams {
    LightParams::orthographic(
        glam::Mat4::look_at_rh(
            glam::Vec3::new(0.0, 5.0, 1.0),
            glam::Vec3::ZERO,
            glam::Vec3::Y,
        ),
        2.0,
        1.0,
        10.0,
    )
}

/// `record` over `depth`, expecting a stage error.
fn record_err<'a>(
    g: &Gpu,
    depth: impl Into<shadowgraph::DepthLayer<'a>>,
    light: &LightParams,
) -> StageError {
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(64)).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    match stage.record(&g.device, &mut enc, depth, light) {
        Err(Error::Stage(e)) => e,
        Err(e) => panic!("expected a stage error, got {e}"),
        Ok(_) => panic!("expected a stage error, got maps"),
    }
}

/// A device (and queue) of the same adapter with `limits` and no optional features.
fn device_with(g: &Gpu, limits: wgpu::Limits) -> (wgpu::Device, wgpu::Queue) {
    pollster::block_on(g.adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("limited"),
        required_limits: limits,
        ..Default::default()
    }))
    .expect("a device with lower limits")
}

fn limit_error(device: &wgpu::Device, config: &PrefilterConfig) -> String {
    match Prefilter::new(device, config) {
        Err(e @ Error::Limit { .. }) => e.to_string(),
        Err(e) => panic!("expected a limit error, got {e}"),
        Ok(_) => panic!("expected a limit error"),
    }
}
