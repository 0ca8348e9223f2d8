//! Counts of the GPU objects shadowgraph creates, per thread.
//!
//! The renderer, the executor, the timer and the plug-in stage create every buffer, texture,
//! view, bind group, layout, shader module, pipeline, sampler and query set through the
//! functions here, which count what they create on the calling thread (wgpu creates on the
//! caller's thread; a count per thread keeps tests running side by side apart). wgpu's own
//! counters (`Device::get_internal_counters`, feature `counters`) count live objects, which a
//! frame that creates and drops its objects leaves unchanged; these count creations, so a test
//! can check that a frame after the first creates nothing (`tests/reuse.rs`, which also checks
//! that those files create nothing around these functions).

use std::cell::Cell;

/// GPU objects created on this thread so far, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Created {
    /// Buffers (uniform, storage, staging, readback).
    pub buffers: u64,
    /// Textures.
    pub textures: u64,
    /// Texture views.
    pub views: u64,
    /// Bind groups.
    pub bind_groups: u64,
    /// Bind group and pipeline layouts.
    pub layouts: u64,
    /// Shader modules.
    pub shader_modules: u64,
    /// Compute and render pipelines.
    pub pipelines: u64,
    /// Samplers.
    pub samplers: u64,
    /// Query sets.
    pub query_sets: u64,
}

thread_local! {
    static CREATED: Cell<Created> = Cell::new(Created::default());
}

/// What this thread has created so far.
pub fn created() -> Created {
    CREATED.with(Cell::get)
}

fn count(f: impl FnOnce(&mut Created)) {
    CREATED.with(|c| {
        let mut v = c.get();
        f(&mut v);
        c.set(v);
    });
}

/// `Device::create_buffer`, counted.
pub(crate) fn buffer(device: &wgpu::Device, desc: &wgpu::BufferDescriptor) -> wgpu::Buffer {
    count(|c| c.buffers += 1);
    device.create_buffer(desc)
}

/// `DeviceExt::create_buffer_init`, counted.
pub(crate) fn buffer_init(
    device: &wgpu::Device,
    desc: &wgpu::util::BufferInitDescriptor,
) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    count(|c| c.buffers += 1);
    device.create_buffer_init(desc)
}

/// `Device::create_texture`, counted.
pub(crate) fn texture(device: &wgpu::Device, desc: &wgpu::TextureDescriptor) -> wgpu::Texture {
    count(|c| c.textures += 1);
    device.create_texture(desc)
}

/// `Texture::create_view`, counted.
pub(crate) fn view(
    texture: &wgpu::Texture,
    desc: &wgpu::TextureViewDescriptor,
) -> wgpu::TextureView {
    count(|c| c.views += 1);
    texture.create_view(desc)
}

/// `Device::create_bind_group`, counted.
pub(crate) fn bind_group(
    device: &wgpu::Device,
    desc: &wgpu::BindGroupDescriptor,
) -> wgpu::BindGroup {
    count(|c| c.bind_groups += 1);
    device.create_bind_group(desc)
}

/// `Device::create_bind_group_layout`, counted.
pub(crate) fn bind_group_layout(
    device: &wgpu::Device,
    desc: &wgpu::BindGroupLayoutDescriptor,
) -> wgpu::BindGroupLayout {
    count(|c| c.layouts += 1);
    device.create_bind_group_layout(desc)
}

/// `Device::create_pipeline_layout`, counted.
pub(crate) fn pipeline_layout(
    device: &wgpu::Device,
    desc: &wgpu::PipelineLayoutDescriptor,
) -> wgpu::PipelineLayout {
    count(|c| c.layouts += 1);
    device.create_pipeline_layout(desc)
}

/// `Device::create_shader_module`, counted.
pub(crate) fn shader_module(
    device: &wgpu::Device,
    desc: wgpu::ShaderModuleDescriptor,
) -> wgpu::ShaderModule {
    count(|c| c.shader_modules += 1);
    device.create_shader_module(desc)
}

/// `Device::create_shader_module_trusted` with every runtime check off
/// (`wgpu::ShaderRuntimeChecks::unchecked()`), counted: a kernel of `kernels/` compiled without
/// naga's bounds on its indices and loops, for the A/B of `exec::ShaderChecks::Off` only (never
/// a default).
///
/// Sound for the kernels of `kernels/` (not for any WGSL): every one indexes within bounds,
/// loads textures at coordinates tested against or clamped to `textureDimensions`, indexes
/// private and workgroup arrays by counters below their constant lengths and storage buffers
/// below the sizes the host allocates for its dispatch (`arrayLength` in `copy`, `materials`
/// clamped in `shade`), bounds every loop by a count, and divides integers only by constants or
/// sizes of at least 1; the suite runs them checked, so a change that broke this would not
/// show there, which is why the mode stays an opt-in measurement.
pub(crate) fn shader_module_unchecked(
    device: &wgpu::Device,
    desc: wgpu::ShaderModuleDescriptor,
) -> wgpu::ShaderModule {
    count(|c| c.shader_modules += 1);
    // SAFETY: the kernels passed here index within bounds, bound their loops and never
    // divide an integer by zero (the function's documentation gives the reasons).
    unsafe { device.create_shader_module_trusted(desc, wgpu::ShaderRuntimeChecks::unchecked()) }
}

/// `Device::create_compute_pipeline`, counted.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    desc: &wgpu::ComputePipelineDescriptor,
) -> wgpu::ComputePipeline {
    count(|c| c.pipelines += 1);
    device.create_compute_pipeline(desc)
}

/// `Device::create_render_pipeline`, counted.
#[cfg(feature = "cli")]
pub(crate) fn render_pipeline(
    device: &wgpu::Device,
    desc: &wgpu::RenderPipelineDescriptor,
) -> wgpu::RenderPipeline {
    count(|c| c.pipelines += 1);
    device.create_render_pipeline(desc)
}

/// `Device::create_sampler`, counted.
#[cfg(feature = "cli")]
pub(crate) fn sampler(device: &wgpu::Device, desc: &wgpu::SamplerDescriptor) -> wgpu::Sampler {
    count(|c| c.samplers += 1);
    device.create_sampler(desc)
}

/// `Device::create_query_set`, counted.
pub(crate) fn query_set(device: &wgpu::Device, desc: &wgpu::QuerySetDescriptor) -> wgpu::QuerySet {
    count(|c| c.query_sets += 1);
    device.create_query_set(desc)
}
