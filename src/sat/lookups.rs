//! The shading side's table lookups run by a kernel of their own ([`lookup_means`]), one
//! rectangle per invocation, so a test or the numerical-stability suite can hold each lookup
//! against an exact reference without a scene around it.

use wgpu::util::DeviceExt;

use super::SatCoding;
use crate::error::Result;
use crate::exec::ComputeKernel;
use crate::gpu::{Gpu, submit_and_read};

/// Which of `shared/sat`'s lookups the kernel runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// `sat_mean_fixed`: the exact integral from a fixed-point (u32) table, sixteen loads.
    Fixed,
    /// `sat_mean_float`: the same from an f32 table.
    Float,
    /// `sat_mean_linear`: four bilinear-filtered fetches of an f32 table (corners on the
    /// 2⁻⁸-texel grid), through [`super::SAT_SAMPLER_DESCRIPTOR`].
    Linear,
}

impl Lookup {
    /// The WGSL function, the table's sample type, and the sampler argument if any.
    fn parts(self) -> (&'static str, &'static str, &'static str) {
        match self {
            Lookup::Fixed => ("sat_mean_fixed", "u32", ""),
            Lookup::Float => ("sat_mean_float", "f32", ""),
            Lookup::Linear => ("sat_mean_linear", "f32", "smp, "),
        }
    }

    /// The kernel's source (before `// #import` resolution).
    fn source(self) -> String {
        let (f, ty, smp) = self.parts();
        let sampler = if smp.is_empty() {
            ""
        } else {
            "@group(0) @binding(4) var smp: sampler;\n"
        };
        format!(
            "// #import shared/sat
struct Coding {{ offset: vec4<f32>, scale: vec4<f32> }}
@group(0) @binding(0) var table: texture_2d<{ty}>;
@group(0) @binding(1) var<storage, read> rects: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> means: array<vec4<f32>>;
@group(0) @binding(3) var<uniform> coding: Coding;
{sampler}@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if id.x < arrayLength(&rects) {{
        means[id.x] = {f}(table, {smp}rects[id.x], coding.offset, coding.scale);
    }}
}}
"
        )
    }
}

/// The means over `rects` (x0, y0, x1, y1 in texels) that `lookup` reads from `table`, a table
/// coded by `coding`, one dispatch, read back. Compiles its kernel each call: for tests and the
/// stability suite, not for a frame.
pub fn lookup_means(
    gpu: &Gpu,
    table: &wgpu::Texture,
    lookup: Lookup,
    coding: &SatCoding,
    rects: &[[f32; 4]],
) -> Result<Vec<[f32; 4]>> {
    let d = &gpu.device;
    let name = "sat_lookup";
    let wgsl = crate::kernels::resolve_source(name, &lookup.source())?;
    let kernel = ComputeKernel::new(d, name, &wgsl)?;
    let init = |label, contents: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    };
    let rects_buf = init(
        "sat_lookup.rects",
        bytemuck::cast_slice(rects),
        wgpu::BufferUsages::STORAGE,
    );
    let coding_buf = init(
        "sat_lookup.coding",
        bytemuck::cast_slice(&[coding.offset, coding.scale]),
        wgpu::BufferUsages::UNIFORM,
    );
    // A zero-sized storage binding is invalid: one unused rectangle's room at least.
    let bytes = (rects.len().max(1) * 16) as u64;
    let means = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sat_lookup.means"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let view = table.create_view(&Default::default());
    let sampler = d.create_sampler(&super::SAT_SAMPLER_DESCRIPTOR);
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&view),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: rects_buf.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: means.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 3,
            resource: coding_buf.as_entire_binding(),
        },
    ];
    if lookup == Lookup::Linear {
        entries.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: wgpu::BindingResource::Sampler(&sampler),
        });
    }
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(name),
        layout: &kernel.layouts[0],
        entries: &entries,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((rects.len() as u32).div_ceil(64), 1, 1);
    }
    let raw = submit_and_read(d, &gpu.queue, enc, &means, name)?;
    let all: &[[f32; 4]] = bytemuck::cast_slice(&raw);
    Ok(all[..rects.len()].to_vec())
}
