//! What a plan's run holds: textures pooled by shape across runs, the texture of every planned
//! resource, and the per-step counters a kernel may increment.

use std::collections::HashMap;

use crate::error::{ExecError, Result};
use crate::gpu::read_buffer;
use crate::gpu_objects;
use crate::graph::{Plan, Slot};

/// Textures kept across runs, keyed by shape; a plan takes the ones it needs in order.
#[derive(Default)]
pub struct TexturePool {
    pub(super) free: HashMap<Slot, Vec<wgpu::Texture>>,
}

impl TexturePool {
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

    /// Textures held (in use by the last run or free).
    pub fn texture_count(&self) -> usize {
        self.free.values().map(Vec::len).sum()
    }
}

/// The textures a run produced, by resource name.
#[derive(Clone)]
pub struct Outputs {
    /// Texture of every planned resource, imports included.
    pub textures: HashMap<String, wgpu::Texture>,
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
        textures: HashMap<String, wgpu::Texture>,
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
            layers,
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

/// The texture of every planned resource: its slot's, or the caller's for an import; sizes
/// checked against the plan.
pub(super) fn plan_textures(
    plan: &Plan,
    slot_textures: &[wgpu::Texture],
    imports: &HashMap<String, wgpu::Texture>,
) -> Result<HashMap<String, wgpu::Texture>> {
    let mut textures = HashMap::new();
    for r in &plan.resources {
        let name = &r.resource.name;
        let t = match r.slot.and_then(|s| slot_textures.get(s)) {
            Some(t) => t.clone(),
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
    Ok(textures)
}
