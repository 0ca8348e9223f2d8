//! The yardsticks: `kernels/copy.wgsl` copying a storage buffer, and two copies of a texture of
//! each format a benchmarked kernel reads or writes in the map kernels' 16×16 workgroups:
//! `kernels/copy_texture.wgsl` (`copy_texture_u32.wgsl`) one texel an invocation, as the map
//! kernels read, and `copy_texture_x4.wgsl` (`copy_texture_u32_x4.wgsl`) four, every load
//! issued before the first store ([`TextureCopy`]).

use std::sync::Arc;

use super::BenchGraph;
use super::harness::{Timed, median_time, random_depths, timer};
use crate::error::{Error, Result};
use crate::gpu::scoped;
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;
use crate::{
    exec::{ComputeKernel, KernelCache, wgsl_storage_format},
    timer::GpuTimer,
};

/// Bytes one invocation of the buffer copy kernel copies (one `vec4<u32>`).
const COPY_BYTES_PER_INVOCATION: u64 = 16;

/// Name of the buffer copy kernel (`kernels/copy.wgsl`).
pub const COPY: &str = "copy";

/// The formats benchmarked kernels read or write, each with a texture copy row: the
/// rasterized depth (copied to `r32float`, as `linearize` reads it), linear depth and ESM
/// (`r32float`), VSM and the blur (`rg32float`), 16-bit moments (`rgba16float`), EVSM4, MSM,
/// CSM and mips (`rgba32float`), summed-area tables (`rgba32uint`).
pub const COPY_FORMATS: &[wgpu::TextureFormat] = &[
    wgpu::TextureFormat::Depth32Float,
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::Rg32Float,
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::Rgba32Float,
    wgpu::TextureFormat::R32Uint,
    wgpu::TextureFormat::Rg32Uint,
    wgpu::TextureFormat::Rgba32Uint,
];

/// The name of a format in the report (WGSL's storage-format names; `depth32float`).
pub fn format_name(format: wgpu::TextureFormat) -> String {
    match format {
        wgpu::TextureFormat::Depth32Float => "depth32float".into(),
        f => wgsl_storage_format(f).map_or_else(|_| format!("{f:?}"), str::to_string),
    }
}

/// A texture copy kernel: texels an invocation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureCopy {
    /// One texel an invocation, one load in flight (`kernels/copy_texture.wgsl`): the map
    /// kernels' shape, each kernel row's `x` yardstick.
    X1,
    /// Four texels an invocation, 16 apart along x, every load issued before the first store
    /// (`kernels/copy_texture_x4.wgsl`): what a texture copy reaches with loads in flight.
    X4,
}

impl TextureCopy {
    /// Both, in the report's order.
    pub const ALL: [TextureCopy; 2] = [TextureCopy::X1, TextureCopy::X4];

    /// The row's kernel name: `copy texture x1`, `copy texture x4`.
    pub fn name(self) -> &'static str {
        match self {
            TextureCopy::X1 => "copy texture x1",
            TextureCopy::X4 => "copy texture x4",
        }
    }

    /// The kernel copying textures of `format` (float or unsigned integer texels).
    fn kernel(self, format: wgpu::TextureFormat) -> KernelId {
        let uint = matches!(
            format,
            wgpu::TextureFormat::R32Uint
                | wgpu::TextureFormat::Rg32Uint
                | wgpu::TextureFormat::Rgba32Uint
        );
        match (self, uint) {
            (TextureCopy::X1, false) => KernelId::CopyTexture,
            (TextureCopy::X1, true) => KernelId::CopyTextureU32,
            (TextureCopy::X4, false) => KernelId::CopyTextureX4,
            (TextureCopy::X4, true) => KernelId::CopyTextureU32X4,
        }
    }
}

/// A graph of one node copying an imported `n`² texture of `format` into a texture of the same
/// format (a depth texture into `r32float`) with the kernel `copy`: the texture roofline of that
/// format.
pub fn copy_texture_graph(n: u32, format: wgpu::TextureFormat, copy: TextureCopy) -> BenchGraph {
    let kernel = copy.kernel(format);
    let out = match format {
        wgpu::TextureFormat::Depth32Float => wgpu::TextureFormat::R32Float,
        f => f,
    };
    let mut graph = Graph::default();
    let src = graph.import("copy.src", format, n, n, None);
    let size = SizeRule::Fixed {
        width: n,
        height: n,
    };
    let dst = graph.resource("copy.dst", out, size, None);
    graph.node(Node {
        name: format!("{} {}", copy.name(), format_name(format)),
        kernel,
        inputs: vec![("src".into(), src)],
        outputs: vec![("dst".into(), dst.clone())],
        params: Vec::new(),
        dispatch: Dispatch::Texels(dst.clone()),
        light: None,
    });
    BenchGraph {
        graph,
        outputs: vec![dst],
    }
}

/// The median times of copying a `buffer_bytes` buffer with `kernels/copy.wgsl` (moving twice
/// that).
pub(super) fn time_buffer_copy(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    kernels: &mut KernelCache,
    buffer_bytes: u64,
    repeat: u32,
) -> Result<Timed> {
    let max_x = device
        .limits()
        .max_compute_workgroups_per_dimension
        .min(65535);
    let copy = CopyBench::new(device, queue, kernels, buffer_bytes, max_x)?;
    let mut timer = timer(device, queue, 1)?;
    median_time(device, queue, &mut timer, repeat, |enc, t| {
        copy.record(enc, Some(t));
        Ok(())
    })
}

/// Workgroups for copying `bytes` with `wg`-wide groups: a 2-D grid with `x ≤ max_x` and
/// `y ≤ max_y`, as `kernels/copy.wgsl` indexes it (`i = id.x + id.y · groups.x · WG_SIZE`).
fn copy_groups(bytes: u64, wg: u32, max_x: u32, max_y: u32) -> Result<[u32; 3]> {
    let invocations = bytes.div_ceil(COPY_BYTES_PER_INVOCATION);
    let groups = invocations.div_ceil(u64::from(wg.max(1))).max(1);
    let x = groups.min(u64::from(max_x.max(1)));
    let y = groups.div_ceil(x);
    if y > u64::from(max_y) {
        return Err(Error::Limit {
            what: "copy benchmark workgroups".into(),
            requested: groups,
            limit: u64::from(max_x) * u64::from(max_y),
        });
    }
    Ok([x as u32, y as u32, 1])
}

/// Whether a storage buffer of `bytes` can be created and bound whole.
fn check_copy_bytes(limits: &wgpu::Limits, bytes: u64) -> Result<()> {
    let limit = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    if bytes > limit {
        return Err(Error::Limit {
            what: "copy benchmark buffer (bytes)".into(),
            requested: bytes,
            limit,
        });
    }
    Ok(())
}

/// The copy kernel bound to a source and a destination buffer of the same size.
struct CopyBench {
    kernel: Arc<ComputeKernel>,
    /// The destination (the bind group keeps both buffers alive; the tests read this one).
    #[cfg_attr(not(test), allow(dead_code, reason = "read back by the tests only"))]
    dst: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    groups: [u32; 3],
}

impl CopyBench {
    /// Buffers of `bytes` (a multiple of 16), the source random, bound by reflected names.
    fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernels: &mut KernelCache,
        bytes: u64,
        max_x: u32,
    ) -> Result<Self> {
        let limits = device.limits();
        check_copy_bytes(&limits, bytes)?;
        let kernel = kernels.get(device, COPY)?;
        let wg = kernel.reflection.workgroup_size.unwrap_or([1, 1, 1]);
        let max_y = limits.max_compute_workgroups_per_dimension;
        let groups = copy_groups(bytes, wg[0] * wg[1] * wg[2], max_x, max_y)?;
        let gpu_err = |m: String| Error::Gpu {
            stage: "creating the copy benchmark".into(),
            message: m,
        };
        let buffer = |label: &str, usage: wgpu::BufferUsages| {
            scoped(
                device,
                || {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size: bytes,
                        usage,
                        mapped_at_creation: false,
                    })
                },
                gpu_err,
            )
        };
        let src = buffer(
            "shadowgraph.bench.copy.src",
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        )?;
        let dst = buffer(
            "shadowgraph.bench.copy.dst",
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        )?;
        let data = random_depths((bytes / 4) as usize, 0xC0FF);
        queue.write_buffer(&src, 0, bytemuck::cast_slice(&data));
        let bind_group = copy_bind_group(device, &kernel, &src, &dst)?;
        Ok(Self {
            kernel,
            dst,
            bind_group,
            groups,
        })
    }

    /// Records one copy pass, timed when `timer` is given.
    fn record(&self, enc: &mut wgpu::CommandEncoder, timer: Option<&mut GpuTimer>) {
        if let Some(t) = timer {
            t.begin(enc, COPY);
        }
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("shadowgraph.bench.copy"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.kernel.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.groups[0], self.groups[1], self.groups[2]);
    }
}

/// Binds `src` and `dst` to the copy kernel's bindings of those names.
fn copy_bind_group(
    device: &wgpu::Device,
    kernel: &ComputeKernel,
    src: &wgpu::Buffer,
    dst: &wgpu::Buffer,
) -> Result<wgpu::BindGroup> {
    let mut entries = Vec::new();
    for (name, buffer) in [("src", src), ("dst", dst)] {
        let b = kernel
            .reflection
            .binding(name)
            .ok_or_else(|| Error::Pipeline {
                kernel: COPY.into(),
                message: format!("the copy kernel has no binding `{name}`"),
            })?;
        entries.push(wgpu::BindGroupEntry {
            binding: b.binding,
            resource: buffer.as_entire_binding(),
        });
    }
    scoped(
        device,
        || {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadowgraph.bench.copy"),
                layout: &kernel.layouts[0],
                entries: &entries,
            })
        },
        |message| Error::Pipeline {
            kernel: COPY.into(),
            message: format!("binding the copy benchmark: {message}"),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{Gpu, read_buffer, submit_and_wait};

    /// The format the copy of `format` writes.
    fn built_format(format: wgpu::TextureFormat) -> wgpu::TextureFormat {
        match format {
            wgpu::TextureFormat::Depth32Float => wgpu::TextureFormat::R32Float,
            f => f,
        }
    }

    fn gpu() -> Gpu {
        match Gpu::new() {
            Ok(g) => g,
            Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
        }
    }

    #[test]
    fn copy_groups_cover_every_invocation_once_in_a_2d_grid() {
        for (bytes, max_x) in [
            (16, 65535),
            (40_000, 3),
            (256 * 16 * 70_000, 65535),
            (64, 1),
        ] {
            let [x, y, z] = copy_groups(bytes, 256, max_x, 65535).unwrap();
            let invocations = bytes / 16;
            let cover = u64::from(x) * u64::from(y) * 256;
            assert!(x <= max_x && z == 1, "{bytes}: {x}x{y}x{z}");
            assert!(cover >= invocations, "{bytes}: {x}x{y} covers {cover}");
            assert!(
                cover - invocations < u64::from(x) * 256,
                "{bytes}: a whole spare row"
            );
        }
        assert!(copy_groups(16 * 256 * 10, 256, 3, 3).is_err());
    }

    /// The yardstick must really copy, including through the 2-D grid (forced by `max_x`).
    #[test]
    fn copy_kernel_copies_through_a_2d_grid() {
        let gpu = gpu();
        let (device, queue) = (&gpu.device, &gpu.queue);
        let mut kernels = KernelCache::default();
        let bytes = 40_000;
        let copy = CopyBench::new(device, queue, &mut kernels, bytes, 3).unwrap();
        assert_eq!(copy.groups, [3, 4, 1]);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = device.create_command_encoder(&Default::default());
        copy.record(&mut enc, None);
        enc.copy_buffer_to_buffer(&copy.dst, 0, &readback, 0, bytes);
        submit_and_wait(device, queue, enc, "test").unwrap();
        let got = read_buffer(device, &readback).unwrap();
        let want = random_depths((bytes / 4) as usize, 0xC0FF);
        assert_eq!(got, bytemuck::cast_slice::<f32, u8>(&want));
    }

    /// Every texture yardstick, one texel an invocation or four, copies its format bit for bit
    /// (a depth texture, cleared to ½, into `r32float`), at sizes that are multiples neither of
    /// 4 nor of the workgroup (16) nor of the four-texel copy's 64 columns a workgroup: 37
    /// (one workgroup, most lanes' texels past the edge) and 150 (two and a part); the
    /// four-texel copy at 150² also with its module unchecked (`exec::ShaderChecks::Off`, the
    /// A/B of wgpu's runtime checks), the same bits.
    #[test]
    fn texture_copies_copy_every_format() {
        use crate::exec::ShaderChecks;
        let gpu = gpu();
        let (device, queue) = (&gpu.device, &gpu.queue);
        let mut cases = Vec::new();
        for n in [37, 150] {
            for copy in TextureCopy::ALL {
                cases.extend(COPY_FORMATS.iter().map(|&f| (n, copy, f, ShaderChecks::On)));
            }
        }
        let unchecked = COPY_FORMATS
            .iter()
            .map(|&f| (150, TextureCopy::X4, f, ShaderChecks::Off));
        cases.extend(unchecked);
        for (n, copy, format, checks) in cases {
            let built = copy_texture_graph(n, format, copy);
            let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
            let plan = crate::graph::plan(&built.graph, &outputs).unwrap();
            let mut executor = crate::exec::Executor::new();
            executor.kernels.set_shader_checks(checks);
            let imports = super::super::harness::random_imports(device, queue, &plan).unwrap();
            let src = &imports["copy.src"];
            let mut enc = device.create_command_encoder(&Default::default());
            let out = executor
                .record(device, &mut enc, &plan, &imports, None)
                .unwrap();
            submit_and_wait(device, queue, enc, "test").unwrap();
            let got = crate::gpu::read_texture(device, queue, &out.textures["copy.dst"], 0);
            let got = got.unwrap();
            let want = match format {
                wgpu::TextureFormat::Depth32Float => {
                    bytemuck::cast_slice(&vec![0.5f32; (n * n) as usize]).to_vec()
                }
                _ => crate::gpu::read_texture(device, queue, src, 0).unwrap(),
            };
            let what = format!("{} {} at {n}² {checks:?}", copy.name(), format_name(format));
            assert_eq!(got.len(), want.len(), "{what}");
            if let Some(i) = (0..got.len()).find(|&i| got[i] != want[i]) {
                let texel = i / crate::graph::texel_bytes(built_format(format)) as usize;
                panic!(
                    "{what}: texel ({}, {}) differs",
                    texel % n as usize,
                    texel / n as usize
                );
            }
            assert!(got.iter().any(|&b| b != 0), "{what}");
        }
    }

    /// The smooth inputs reach the GPU as the formula gives them, in each format's coding:
    /// f32 as is, u32 as 24-bit fixed point, halves ordered in [⅛, 1) (checked in f64 on the
    /// texture read back; tolerances: f32 sines, fixed point's truncation of an f32).
    #[test]
    fn smooth_imports_hold_the_field_in_each_format() {
        use super::super::harness::{Inputs, fill_imports};
        let gpu = gpu();
        let (device, queue) = (&gpu.device, &gpu.queue);
        let n = 45u32;
        let want = |x: u32, y: u32, c: u32| {
            let tau = std::f64::consts::TAU;
            0.5 + 0.2 * (tau * (x as f64 / 97.0 + c as f64 / 7.0)).sin()
                + 0.2 * (tau * (y as f64 / 61.0 + c as f64 / 5.0)).cos()
        };
        for format in [
            wgpu::TextureFormat::Rg32Float,
            wgpu::TextureFormat::Rgba32Uint,
            wgpu::TextureFormat::Rgba16Float,
        ] {
            let built = copy_texture_graph(n, format, TextureCopy::X1);
            let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
            let plan = crate::graph::plan(&built.graph, &outputs).unwrap();
            let imports = fill_imports(device, queue, &plan, Inputs::Smooth).unwrap();
            let bytes = crate::gpu::read_texture(device, queue, &imports["copy.src"], 0).unwrap();
            let channels = match format {
                wgpu::TextureFormat::Rg32Float => 2,
                _ => 4,
            };
            let mut previous = None;
            for y in 0..n {
                for x in 0..n {
                    for c in 0..channels {
                        let i = ((y * n + x) * channels + c) as usize;
                        let v = want(x, y, c);
                        match format {
                            wgpu::TextureFormat::Rg32Float => {
                                let got: f32 = bytemuck::pod_read_unaligned(&bytes[4 * i..][..4]);
                                assert!((got as f64 - v).abs() < 1e-5, "{x} {y} {c}: {got} {v}");
                            }
                            wgpu::TextureFormat::Rgba32Uint => {
                                let got: u32 = bytemuck::pod_read_unaligned(&bytes[4 * i..][..4]);
                                let fixed = v * (1u64 << 24) as f64;
                                assert!((got as f64 - fixed).abs() < 200.0, "{got} {fixed}");
                            }
                            _ => {
                                let got: u16 = bytemuck::pod_read_unaligned(&bytes[2 * i..][..2]);
                                assert!((0x3000..0x3C00).contains(&got), "{got:#x}");
                                // Ordered as the field along a row of channel 0.
                                if c == 0 && x > 0 {
                                    let (pv, pg): (f64, u16) = previous.unwrap();
                                    if v > pv + 1e-3 {
                                        assert!(got >= pg, "{x} {y}");
                                    }
                                }
                                if c == 0 {
                                    previous = Some((v, got));
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
