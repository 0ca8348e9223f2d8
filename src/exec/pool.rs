//! What a plan's run holds: textures (and the storage buffers of intermediates kept in buffers)
//! pooled by shape across runs, the texture or buffer of every planned resource, and the
//! per-step counters a kernel may increment.

use std::collections::HashMap;

use crate::error::{ExecError, Result};
use crate::gpu::read_buffer;
use crate::gpu_objects;
use crate::graph::{Plan, Slot};

/// Textures (and buffers) kept across runs, keyed by shape; a plan takes the ones it needs in
/// order.
#[derive(Default)]
pub struct TexturePool {
    pub(super) free: HashMap<Slot, Vec<wgpu::Texture>>,
    pub(super) free_buffers: HashMap<Slot, Vec<wgpu::Buffer>>,
}

/// What holds a slot's resources: a texture, or a row-major storage buffer
/// ([`super::buffer_slots`]).
#[derive(Clone)]
pub(super) enum Held {
    Texture(wgpu::Texture),
    Buffer(wgpu::Buffer),
}

/// A resource held in a row-major storage buffer ([`crate::graph::Resource::unfiltered`]):
/// texel `(x, y)` at element `y · width + x`, each the bytes of its texture format's texel.
#[derive(Clone, Debug, PartialEq)]
pub struct BufferMap {
    /// The buffer.
    pub buffer: wgpu::Buffer,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The resource's format ([`crate::graph::texture_format`] gives its texels' bytes).
    pub format: wgpu::TextureFormat,
}

impl TexturePool {
    /// A buffer for `slot` ([`super::buffer_slots`]): a free one of its shape, or a new one.
    pub(super) fn take_buffer(&mut self, device: &wgpu::Device, slot: &Slot) -> wgpu::Buffer {
        if let Some(b) = self.free_buffers.get_mut(slot).and_then(Vec::pop) {
            return b;
        }
        let format = crate::graph::texture_format(slot.format);
        let bytes =
            u64::from(slot.width) * u64::from(slot.height) * crate::graph::texel_bytes(format);
        gpu_objects::buffer(
            device,
            &wgpu::BufferDescriptor {
                label: Some("shadowgraph.pool.buffer"),
                size: bytes.max(4),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            },
        )
    }

    /// Returns `held` of `slot` to the free lists.
    pub(super) fn give_back(&mut self, slot: Slot, held: Held) {
        match held {
            Held::Texture(t) => self.free.entry(slot).or_default().push(t),
            Held::Buffer(b) => self.free_buffers.entry(slot).or_default().push(b),
        }
    }

    pub(super) fn take(&mut self, device: &wgpu::Device, slot: &Slot) -> wgpu::Texture {
        if let Some(t) = self.free.get_mut(slot).and_then(Vec::pop) {
            return t;
        }
        gpu_objects::texture(
            device,
            &wgpu::TextureDescriptor {
                label: Some("shadowgraph.pool"),
                size: wgpu::Extent3d {
                    width: slot.width,
                    height: slot.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: slot.mips,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: crate::graph::texture_format(slot.format),
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
        )
    }

    /// Textures and buffers held (free).
    pub fn texture_count(&self) -> usize {
        self.free.values().map(Vec::len).sum::<usize>()
            + self.free_buffers.values().map(Vec::len).sum::<usize>()
    }
}

/// The textures a run produced, by resource name.
#[derive(Clone)]
pub struct Outputs {
    /// Texture of every planned resource held in a texture, imports included.
    pub textures: HashMap<String, wgpu::Texture>,
    /// Buffer of every planned resource held in a storage buffer ([`super::buffer_slots`];
    /// none outside [`super::KernelLayout::Redesign`]).
    pub buffers: HashMap<String, BufferMap>,
    /// The array layer each imported resource is read from, where it is one layer of an array
    /// texture (absent: the whole texture).
    pub layers: HashMap<String, u32>,
    /// One counter per step that a kernel may increment (e.g. non-finite texels replaced).
    pub stats: wgpu::Buffer,
    pub(super) stats_readback: wgpu::Buffer,
    /// Step names, in the order of the counters.
    pub steps: Vec<String>,
}

/// Stride between per-step counters: storage binding offsets must be 256-byte aligned.
pub(super) const STATS_STRIDE: u64 = 256;

impl Outputs {
    /// The outputs of a run of `plan` over `textures`, with zeroed counters.
    pub(super) fn new(
        device: &wgpu::Device,
        plan: &Plan,
        (textures, buffers): (HashMap<String, wgpu::Texture>, HashMap<String, BufferMap>),
        layers: HashMap<String, u32>,
    ) -> Self {
        let steps = plan.steps.len().max(1) as u64;
        let counters = |label, usage| {
            gpu_objects::buffer(
                device,
                &wgpu::BufferDescriptor {
                    label: Some(label),
                    size: steps * STATS_STRIDE,
                    usage,
                    mapped_at_creation: false,
                },
            )
        };
        Outputs {
            stats: counters(
                "shadowgraph.stats",
                wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
            ),
            stats_readback: counters(
                "shadowgraph.stats.readback",
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            ),
            steps: plan.steps.iter().map(|s| s.node.name.clone()).collect(),
            textures,
            buffers,
            layers,
        }
    }

    /// Mip levels of resource `name` (1 for one held in a buffer; 0 for none).
    pub fn levels(&self, name: &str) -> u32 {
        match self.textures.get(name) {
            Some(t) => t.mip_level_count(),
            None => u32::from(self.buffers.contains_key(name)),
        }
    }

    /// Level `level` of resource `name` (of `format`, its planned format) as f32 values,
    /// wherever it is held: `(width, height, channels, values)`
    /// ([`crate::gpu::read_resource_texture`], [`crate::gpu::read_resource_buffer`]).
    pub fn read_level(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        name: &str,
        level: u32,
        format: wgpu::TextureFormat,
    ) -> Result<(u32, u32, usize, Vec<f32>)> {
        if let Some(t) = self.textures.get(name) {
            let (c, v) = crate::gpu::read_resource_texture(device, queue, t, level, format)?;
            let (w, h) = ((t.width() >> level).max(1), (t.height() >> level).max(1));
            return Ok((w, h, c, v));
        }
        match self.buffers.get(name) {
            Some(b) if level == 0 => {
                let (c, v) = crate::gpu::read_resource_buffer(device, queue, b)?;
                Ok((b.width, b.height, c, v))
            }
            _ => Err(ExecError::NoResource(name.to_string()).into()),
        }
    }

    /// `(width, height)` of resource `name`, in a texture (level 0) or a buffer.
    pub fn size(&self, name: &str) -> Option<(u32, u32)> {
        match self.textures.get(name) {
            Some(t) => Some((t.width(), t.height())),
            None => self.buffers.get(name).map(|b| (b.width, b.height)),
        }
    }

    /// A default view of resource `name`.
    pub fn view(&self, name: &str) -> Result<wgpu::TextureView> {
        self.textures
            .get(name)
            .map(|t| gpu_objects::view(t, &Default::default()))
            .ok_or_else(|| ExecError::NoResource(name.to_string()).into())
    }

    /// Records the copy of the counters for [`Outputs::read_stats`].
    pub fn copy_stats(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(&self.stats, 0, &self.stats_readback, 0, self.stats.size());
    }

    /// `(step, count)` for every step whose counter is non-zero; after the submission completed.
    pub fn read_stats(&self, device: &wgpu::Device) -> Result<Vec<(String, u32)>> {
        let raw = read_buffer(device, &self.stats_readback)?;
        Ok(self
            .steps
            .iter()
            .enumerate()
            .filter_map(|(i, s)| {
                let at = i * STATS_STRIDE as usize;
                let v = u32::from_le_bytes(raw[at..at + 4].try_into().ok()?);
                (v > 0).then(|| (s.clone(), v))
            })
            .collect())
    }
}

/// The texture or buffer of every planned resource: its slot's, or the caller's texture for an
/// import; sizes checked against the plan.
pub(super) fn plan_textures(
    plan: &Plan,
    held: &[Held],
    imports: &HashMap<String, wgpu::Texture>,
) -> Result<(HashMap<String, wgpu::Texture>, HashMap<String, BufferMap>)> {
    let mut textures = HashMap::new();
    let mut buffers = HashMap::new();
    for r in &plan.resources {
        let name = &r.resource.name;
        let t = match r.slot.and_then(|s| held.get(s)) {
            Some(Held::Texture(t)) => t.clone(),
            Some(Held::Buffer(b)) => {
                let map = BufferMap {
                    buffer: b.clone(),
                    width: r.width,
                    height: r.height,
                    format: r.resource.format,
                };
                buffers.insert(name.clone(), map);
                continue;
            }
            None => imports
                .get(name)
                .cloned()
                .ok_or_else(|| ExecError::MissingImport(name.clone()))?,
        };
        if (t.width(), t.height()) != (r.width, r.height) {
            return Err(ExecError::Size {
                resource: name.clone(),
                width: t.width(),
                height: t.height(),
                plan_width: r.width,
                plan_height: r.height,
            }
            .into());
        }
        textures.insert(name.clone(), t);
    }
    Ok((textures, buffers))
}
