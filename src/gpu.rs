//! GPU context: adapter selection, device creation with the adapter's own limits, readback.

use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

use crate::error::{Error, Result};

mod half;
pub use half::{f16_to_f32, f32_to_f16, pack_f16x2, unpack_f16x2};

/// A device and queue chosen by shadowgraph (the CLI's way in). Library entry points that run
/// work take `&wgpu::Device`/`&wgpu::Queue` instead, so a host renderer can pass its own.
pub struct Gpu {
    /// The adapter the device came from.
    pub adapter: wgpu::Adapter,
    /// The logical device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
}

/// Features shadowgraph uses when offered; none is required.
const WANTED_FEATURES: wgpu::Features = crate::timer::TIMER_FEATURES
    .union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES)
    .union(wgpu::Features::FLOAT32_FILTERABLE)
    .union(wgpu::Features::SHADER_F64)
    .union(wgpu::Features::SHADER_INT64)
    .union(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM)
    .union(wgpu::Features::SUBGROUP);

impl Gpu {
    /// Picks an adapter and creates a device with the adapter's own limits.
    ///
    /// Honours wgpu's environment overrides: `WGPU_BACKEND`, `WGPU_ADAPTER_NAME` (a substring of
    /// the adapter name), `WGPU_POWER_PREF`.
    pub fn new() -> Result<Self> {
        pollster::block_on(Self::new_async(|_| {}))
    }

    /// As [`Gpu::new`], with the adapter's limits changed by `adjust` before the device is
    /// requested: a host mirrors a smaller device it targets, and tests pin a limit to
    /// WebGPU's default so that they refuse the same scenes on every adapter. Limits above the
    /// adapter's fail with [`Error::RequestDevice`].
    pub fn with_limits(adjust: impl FnOnce(&mut wgpu::Limits)) -> Result<Self> {
        pollster::block_on(Self::new_async(adjust))
    }

    async fn new_async(adjust: impl FnOnce(&mut wgpu::Limits)) -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pick_adapter(&instance).await?;
        let info = adapter.get_info();
        let features = adapter.features() & WANTED_FEATURES;
        let mut limits = adapter.limits();
        adjust(&mut limits);
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("shadowgraph"),
                required_features: features,
                required_limits: limits,
                ..Default::default()
            })
            .await
            .map_err(|e| Error::RequestDevice {
                adapter: info.name.clone(),
                message: e.to_string(),
            })?;
        watch_uncaptured(&device);
        Ok(Self {
            adapter,
            device,
            queue,
        })
    }

    /// One-line description of the adapter: name, backend, device type, driver.
    pub fn describe(&self) -> String {
        let i = self.adapter.get_info();
        format!(
            "{} ({:?}, {:?}, driver {} {})",
            i.name, i.backend, i.device_type, i.driver, i.driver_info
        )
    }

    /// Whether GPU timestamps can be written between passes ([`crate::timer::GpuTimer`]).
    pub fn can_time(&self) -> bool {
        self.device
            .features()
            .contains(crate::timer::TIMER_FEATURES)
    }

    /// The facts `shadowgraph info` prints: adapter, backend, features and limits that matter.
    pub fn info_report(&self) -> String {
        let i = self.adapter.get_info();
        let f = self.device.features();
        let l = self.device.limits();
        let mut s = String::new();
        let mut line = |k: &str, v: String| s.push_str(&format!("{k:<40} {v}\n"));
        line("adapter", i.name.clone());
        line("backend", format!("{:?}", i.backend));
        line("device type", format!("{:?}", i.device_type));
        line("driver", format!("{} {}", i.driver, i.driver_info));
        for (name, feat) in [
            ("TIMESTAMP_QUERY", wgpu::Features::TIMESTAMP_QUERY),
            (
                "TIMESTAMP_QUERY_INSIDE_ENCODERS",
                wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS,
            ),
            (
                "TIMESTAMP_QUERY_INSIDE_PASSES",
                wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES,
            ),
            ("FLOAT32_FILTERABLE", wgpu::Features::FLOAT32_FILTERABLE),
            ("SHADER_F64", wgpu::Features::SHADER_F64),
            ("SHADER_INT64", wgpu::Features::SHADER_INT64),
            ("SUBGROUP", wgpu::Features::SUBGROUP),
        ] {
            line(&format!("feature {name}"), yes_no(f.contains(feat)));
        }
        line(
            "max_texture_dimension_2d",
            l.max_texture_dimension_2d.to_string(),
        );
        line(
            "max_storage_textures_per_shader_stage",
            l.max_storage_textures_per_shader_stage.to_string(),
        );
        line(
            "max_sampled_textures_per_shader_stage",
            l.max_sampled_textures_per_shader_stage.to_string(),
        );
        line(
            "max_storage_buffer_binding_size",
            l.max_storage_buffer_binding_size.to_string(),
        );
        line("max_buffer_size", l.max_buffer_size.to_string());
        line(
            "max_compute_workgroup_storage_size",
            l.max_compute_workgroup_storage_size.to_string(),
        );
        line(
            "max_compute_invocations_per_workgroup",
            l.max_compute_invocations_per_workgroup.to_string(),
        );
        line(
            "max_compute_workgroups_per_dimension",
            l.max_compute_workgroups_per_dimension.to_string(),
        );
        line("max_bind_groups", l.max_bind_groups.to_string());
        line(
            "timestamp period (ns/tick)",
            format!("{}", self.queue.get_timestamp_period()),
        );
        let layout = match crate::exec::KernelLayout::for_device(&self.device) {
            Ok(layout) => layout.name().to_string(),
            Err(e) => e.to_string(),
        };
        line("kernel layout", layout);
        s
    }
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_string()
}

async fn pick_adapter(instance: &wgpu::Instance) -> Result<wgpu::Adapter> {
    if let Ok(wanted) = std::env::var("WGPU_ADAPTER_NAME") {
        let wanted = wanted.to_lowercase();
        let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
        return adapters
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&wanted))
            .ok_or_else(|| Error::NoAdapter {
                detail: format!(
                    " matching WGPU_ADAPTER_NAME={wanted:?} (adapters present: {names:?})"
                ),
            });
    }
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env().unwrap_or_default(),
            ..Default::default()
        })
        .await
        .map_err(|e| Error::NoAdapter {
            detail: format!(" ({e})"),
        })
}

thread_local! {
    /// wgpu errors raised outside any error scope (an allocation that ran out of memory, a lost
    /// device), per watched device, until [`take_uncaptured`] hands them to the caller. wgpu
    /// reports an error in the thread whose call failed, so each thread keeps its own: tests
    /// and workers sharing a process never see each other's (device ids repeat across
    /// instances in one process, so the key alone could not tell them apart).
    static UNCAPTURED: RefCell<HashMap<u64, Vec<String>>> = RefCell::new(HashMap::new());
}

fn device_key(device: &wgpu::Device) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    device.hash(&mut h);
    h.finish()
}

fn push_uncaptured(key: u64, message: String) {
    UNCAPTURED.with(|u| u.borrow_mut().entry(key).or_default().push(message));
}

/// Collects `device`'s uncaptured errors and its loss for [`take_uncaptured`], which
/// [`scoped`], [`submit_and_wait`] and [`read_buffer`] call: an error wgpu raises outside a
/// scope fails the next of those calls in the same thread instead of being logged while the
/// work "succeeds". [`Gpu::new`] does this for its device; a host may call it for its own.
pub fn watch_uncaptured(device: &wgpu::Device) {
    let key = device_key(device);
    UNCAPTURED.with(|u| u.borrow_mut().insert(key, Vec::new()));
    device.on_uncaptured_error(Arc::new(move |e| {
        push_uncaptured(key, one_line(&e.to_string()))
    }));
    device.set_device_lost_callback(move |reason, message| {
        push_uncaptured(
            key,
            format!("device lost ({reason:?}): {}", one_line(&message)),
        );
    });
}

/// The errors `device` raised outside any scope since the last call, as one error.
pub fn take_uncaptured(device: &wgpu::Device) -> Result<()> {
    let key = device_key(device);
    let errors = UNCAPTURED.with(|u| u.borrow_mut().remove(&key).unwrap_or_default());
    match errors.as_slice() {
        [] => Ok(()),
        [first, rest @ ..] => Err(Error::Gpu {
            stage: "device".into(),
            message: if rest.is_empty() {
                first.clone()
            } else {
                format!("{first} (and {} more)", rest.len())
            },
        }),
    }
}

/// wgpu's multi-line error text as one line: its lines trimmed and joined with `: `.
pub fn one_line(message: &str) -> String {
    let parts: Vec<&str> = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    parts.join(": ")
}

/// Runs `f` inside a validation error scope and turns a captured error into `make_err` (one
/// line); an earlier uncaptured error on the device comes first.
pub fn scoped<T>(
    device: &wgpu::Device,
    f: impl FnOnce() -> T,
    make_err: impl FnOnce(String) -> Error,
) -> Result<T> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let out = f();
    let popped = pollster::block_on(scope.pop());
    take_uncaptured(device)?;
    match popped {
        None => Ok(out),
        Some(e) => Err(make_err(one_line(&e.to_string()))),
    }
}

/// Submits `encoder`, waits for completion, and reports any validation error (or any error the
/// device raised outside a scope since the last check) as `stage`.
pub fn submit_and_wait(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    encoder: wgpu::CommandEncoder,
    stage: &str,
) -> Result<()> {
    let gpu_err = |m: String| Error::Gpu {
        stage: stage.to_string(),
        message: m,
    };
    scoped(device, || queue.submit([encoder.finish()]), gpu_err)?;
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| gpu_err(one_line(&e.to_string())))?;
    take_uncaptured(device)
}

/// Records a copy of `buffer` (which needs `COPY_SRC`) into a staging buffer at the end of
/// `encoder`, submits it as [`submit_and_wait`] does and returns the buffer's bytes: the
/// one-off readback of a probe or test kernel's storage output.
pub fn submit_and_read(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mut encoder: wgpu::CommandEncoder,
    buffer: &wgpu::Buffer,
    stage: &str,
) -> Result<Vec<u8>> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("shadowgraph.readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    submit_and_wait(device, queue, encoder, stage)?;
    read_buffer(device, &staging)
}

/// Reads a whole buffer back (it must have `MAP_READ`); waits for the device.
pub fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::Gpu {
            stage: "readback".into(),
            message: e.to_string(),
        })?;
    let mapped = rx.recv().map_err(|e| Error::Gpu {
        stage: "readback".into(),
        message: e.to_string(),
    })?;
    mapped.map_err(|e| Error::Gpu {
        stage: "readback".into(),
        message: e.to_string(),
    })?;
    take_uncaptured(device)?;
    let data = buffer
        .get_mapped_range(..)
        .map_err(|e| Error::Gpu {
            stage: "readback".into(),
            message: e.to_string(),
        })?
        .to_vec();
    buffer.unmap();
    Ok(data)
}

/// Copies mip level `mip` of a 2-D texture to the CPU, tightly packed (rows without padding).
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    mip: u32,
) -> Result<Vec<u8>> {
    let format = texture.format();
    let bpp = format
        .block_copy_size(Some(wgpu::TextureAspect::All))
        .or_else(|| format.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)))
        .ok_or_else(|| Error::Invalid(format!("cannot read back {format:?}")))?;
    let w = (texture.width() >> mip).max(1);
    let h = (texture.height() >> mip).max(1);
    let row = w * bpp;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("shadowgraph.readback"),
        size: u64::from(padded) * u64::from(h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    let aspect = if format.is_depth_stencil_format() {
        wgpu::TextureAspect::DepthOnly
    } else {
        wgpu::TextureAspect::All
    };
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d::ZERO,
            aspect,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    submit_and_wait(device, queue, enc, "readback")?;
    let raw = read_buffer(device, &buffer)?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for y in 0..h as usize {
        let start = y * padded as usize;
        out.extend_from_slice(&raw[start..start + row as usize]);
    }
    Ok(out)
}

/// Uploads tightly packed texel data into mip 0 of a 2-D texture.
pub fn write_texture(queue: &wgpu::Queue, texture: &wgpu::Texture, data: &[u8]) {
    write_texture_level(queue, texture, 0, data);
}

/// Writes tightly packed texels into mip `level` of `texture`.
pub fn write_texture_level(queue: &wgpu::Queue, texture: &wgpu::Texture, level: u32, data: &[u8]) {
    let bpp = texture
        .format()
        .block_copy_size(Some(wgpu::TextureAspect::All))
        .unwrap_or(4);
    let (w, h) = (
        (texture.width() >> level).max(1),
        (texture.height() >> level).max(1),
    );
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        data,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(w * bpp),
            rows_per_image: Some(h),
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
}

/// Channels of a float texel format shadowgraph reads back, or `None` for other formats.
pub fn float_channels(format: wgpu::TextureFormat) -> Option<usize> {
    use wgpu::TextureFormat as T;
    match format {
        T::R32Float | T::Depth32Float => Some(1),
        T::Rg32Float => Some(2),
        T::Rg16Unorm => Some(2),
        T::Rgba32Float | T::Rgba16Float | T::Rgba16Unorm => Some(4),
        // Summed-area tables and their intermediates: raw words read as i32 (dumps only).
        T::R32Uint => Some(1),
        T::Rg32Uint => Some(2),
        T::Rgba32Uint => Some(4),
        _ => None,
    }
}

/// Reads mip `mip` of the texture of a graph resource of `format` as f32 values (`channels`
/// per texel, row-major): a [`crate::graph::PACKED_F16X2`] resource's `r32uint` words are
/// unpacked into its two f16 values, any other as [`read_float_texture`] reads it.
pub fn read_resource_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    mip: u32,
    format: wgpu::TextureFormat,
) -> Result<(usize, Vec<f32>)> {
    if !crate::graph::is_packed(format) {
        return read_float_texture(device, queue, texture, mip);
    }
    let raw = read_texture(device, queue, texture, mip)?;
    let words: Vec<u32> = raw
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    Ok((2, unpack_f16x2(&words)))
}

/// Reads mip `mip` of a float texture as f32 values (`channels` per texel, row-major).
pub fn read_float_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    mip: u32,
) -> Result<(usize, Vec<f32>)> {
    let format = texture.format();
    let channels = float_channels(format)
        .ok_or_else(|| Error::Invalid(format!("cannot read {format:?} as float")))?;
    let raw = read_texture(device, queue, texture, mip)?;
    Ok((channels, float_texels(format, &raw)))
}

/// A graph resource held in a storage buffer (`exec::BufferMap`: row-major texels of its
/// texture format) as f32 values, as [`read_resource_texture`] reads the same resource's
/// texture.
pub fn read_resource_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    map: &crate::exec::BufferMap,
) -> Result<(usize, Vec<f32>)> {
    let format = crate::graph::texture_format(map.format);
    let encoder = device.create_command_encoder(&Default::default());
    let raw = submit_and_read(device, queue, encoder, &map.buffer, "read back")?;
    let len = (map.width * map.height) as usize * crate::graph::texel_bytes(format) as usize;
    let raw = raw.get(..len).unwrap_or(&raw);
    if crate::graph::is_packed(map.format) {
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(raw);
        return Ok((2, unpack_f16x2(&words)));
    }
    let channels = float_channels(format)
        .ok_or_else(|| Error::Invalid(format!("cannot read {format:?} as float")))?;
    Ok((channels, float_texels(format, raw)))
}

/// The texels `raw` (tightly packed, of `format`) as f32 values, as [`read_float_texture`]
/// gives them.
fn float_texels(format: wgpu::TextureFormat, raw: &[u8]) -> Vec<f32> {
    if format == wgpu::TextureFormat::Rgba16Float {
        raw.chunks_exact(2)
            .map(|b| f16_to_f32(u16::from_le_bytes([b[0], b[1]])))
            .collect()
    } else if matches!(
        format,
        wgpu::TextureFormat::Rg16Unorm | wgpu::TextureFormat::Rgba16Unorm
    ) {
        raw.chunks_exact(2)
            .map(|b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0)
            .collect()
    } else if matches!(
        format,
        wgpu::TextureFormat::R32Uint
            | wgpu::TextureFormat::Rg32Uint
            | wgpu::TextureFormat::Rgba32Uint
    ) {
        raw.chunks_exact(4)
            .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32)
            .collect()
    } else {
        bytemuck::pod_collect_to_vec(raw)
    }
}
