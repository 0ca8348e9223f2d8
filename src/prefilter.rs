//! The plug-in preprocess stage: a host with its own wgpu renderer hands over its device, an
//! encoder and a depth texture it rasterized from a light, and gets back the filtered maps of a
//! technique and the WGSL that samples them. Nothing of the host's is kept: every call borrows
//! the device and records into the host's encoder; the stage never submits, reads back or
//! polls (only [`Prefilter::timings`], which the host calls after its submission, waits).
//!
//! ```no_run
//! # fn frame(device: &wgpu::Device, depth: &wgpu::Texture, view: glam::Mat4)
//! #     -> shadowgraph::Result<()> {
//! use shadowgraph::prefilter::{LightParams, Prefilter, PrefilterConfig};
//! let mut stage = Prefilter::new(device, &PrefilterConfig::vsm(1024))?;   // pipelines, once
//! let host_wgsl = stage.wgsl(1, 0)?;         // prepend to the host's shader: group 1, binding 0…
//! let mut encoder = device.create_command_encoder(&Default::default());
//! // … the host's depth pass into `depth` …
//! let light = LightParams::orthographic(view, 5.0, 2.0, 20.0);
//! let out = stage.record(device, &mut encoder, depth, &light)?;
//! // bind out.maps[k].view at binding k of group 1, upload bytemuck::bytes_of(&out.light)
//! // as the `Light` the host passes to `shadowgraph_visibility(l, p, n)`, then submit.
//! # Ok(()) }
//! ```

mod config;
mod limits;
pub mod wgsl;

use std::collections::HashMap;

use glam::Mat4;

pub use crate::error::StageError;
/// The light's GPU description the exported WGSL's `Light` mirrors (what
/// [`LightParams::light_gpu`] returns), where a host looks for it.
pub use crate::gpu_data::LightGpu;
pub use config::{LightParams, PrefilterConfig};

use crate::error::{Error, Result};
use crate::exec::Executor;
use crate::graph::{Graph, Plan, plan};
use crate::scene::Light;
use crate::technique;
use crate::timer::{GpuTimer, TIMER_FEATURES};

/// Depth formats the `linearize` kernel reads (as unfilterable float, depth aspect only).
pub const DEPTH_FORMATS: [wgpu::TextureFormat; 5] = [
    wgpu::TextureFormat::Depth32Float,
    wgpu::TextureFormat::Depth32FloatStencil8,
    wgpu::TextureFormat::Depth24Plus,
    wgpu::TextureFormat::Depth24PlusStencil8,
    wgpu::TextureFormat::Depth16Unorm,
];

/// One map the visibility function reads.
#[derive(Clone, Debug)]
pub struct OutputMap {
    /// The graph resource (e.g. `light0.vsm.blur_v`).
    pub resource: String,
    /// Its WGSL binding type (e.g. `texture_2d<f32>`).
    pub wgsl_type: &'static str,
    /// The texture: pooled by the stage, valid until the next [`Prefilter::record`]. Textures
    /// of one shape are handed out in any order, so rebuild bind groups from each call's
    /// output (or compare textures, which implement `Eq`).
    pub texture: wgpu::Texture,
    /// A view of it to bind (depth aspect only for a depth texture).
    pub view: wgpu::TextureView,
}

/// What [`Prefilter::record`] recorded.
#[derive(Clone, Debug)]
pub struct PrefilterOutput {
    /// The maps, in binding order: map `k` goes to `@binding(first_binding + k)` of
    /// [`Prefilter::wgsl`].
    pub maps: Vec<OutputMap>,
    /// The WGSL `struct Light` to upload (bytemuck) for this frame's matrices.
    pub light: LightGpu,
}

/// A plan for one depth size and depth mapping.
struct Planned {
    key: PlanKey,
    plan: Plan,
    maps: Vec<MapInput>,
}

/// What a plan depends on besides the technique: the map size and the linearization.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct PlanKey {
    size: u32,
    perspective: bool,
    near: u32,
    far: u32,
}

impl PlanKey {
    fn new(light: &LightParams, size: u32) -> Self {
        Self {
            size,
            perspective: light.perspective,
            near: light.near.to_bits(),
            far: light.far.to_bits(),
        }
    }
}

/// The stage: pipelines made once for a configuration, textures pooled across frames.
pub struct Prefilter {
    config: PrefilterConfig,
    warnings: Vec<String>,
    executor: Executor,
    planned: Planned,
    timer: Option<GpuTimer>,
    /// The last record's maps (with their views), handed out again while the textures stay.
    maps: Vec<OutputMap>,
}

impl Prefilter {
    /// Validates `config` (the scene file's rules; EVSM exponents past the storage's limit are
    /// clamped and reported by [`Prefilter::warnings`]), checks the device's limits against the
    /// map size and the kernels, and creates the pipelines.
    pub fn new(device: &wgpu::Device, config: &PrefilterConfig) -> Result<Self> {
        let (config, warnings) = config.validated()?;
        let planned = plan_for(&config, &planning_params(), config.size)?;
        limits::check(device, &planned.plan, config.size)?;
        // Features the technique's storage needs (e.g. unorm16 MSM moments).
        crate::limits::check_features(
            device,
            &[planning_params().scene_light(&config, config.size)],
        )?;
        let mut executor = Executor::new();
        executor.prepare(device, &planned.plan)?;
        Ok(Self {
            config,
            warnings,
            executor,
            planned,
            timer: None,
            maps: Vec::new(),
        })
    }

    /// Records the technique's kernels over `depth` into `encoder` and returns the maps the
    /// visibility function reads. Nothing is submitted.
    ///
    /// `depth` is a texture, not a view: the executor imports whole textures (it plans from
    /// their size, picks the depth aspect and makes its own views), so a view of one layer or
    /// aspect could not be honoured. It must be square, single-sampled, one layer, in one of
    /// [`DEPTH_FORMATS`], with `TEXTURE_BINDING`. A size other than the last one's replans and
    /// reallocates the pooled textures; pipelines are kept.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::Texture,
        light: &LightParams,
    ) -> Result<PrefilterOutput> {
        light.validate()?;
        let size = check_depth(depth)?;
        let key = PlanKey::new(light, size);
        if key != self.planned.key {
            let planned = plan_for(&self.config, light, size)?;
            if size != self.planned.key.size {
                limits::check(device, &planned.plan, size)?;
                // Textures of the old size go back to the device; pipelines stay.
                let kernels = std::mem::take(&mut self.executor.kernels);
                self.executor = Executor::new();
                self.executor.kernels = kernels;
            }
            self.planned = planned;
        }
        let imports = HashMap::from([(technique::depth_name(0), depth.clone())]);
        if let Some(t) = self.timer.as_mut() {
            t.reset();
        }
        let outputs = self.executor.record(
            device,
            encoder,
            &self.planned.plan,
            &imports,
            self.timer.as_mut(),
        )?;
        if let Some(t) = self.timer.as_mut() {
            t.resolve(encoder);
        }
        let maps = self.output_maps(&outputs.textures)?;
        Ok(PrefilterOutput {
            maps,
            light: light.light_gpu(&self.config, size),
        })
    }

    /// The maps of a record whose plan produced `textures`: the last record's (views
    /// included) while the textures are the same, else made anew.
    fn output_maps(&mut self, textures: &HashMap<String, wgpu::Texture>) -> Result<Vec<OutputMap>> {
        let texture = |m: &MapInput| {
            textures
                .get(&m.resource)
                .cloned()
                .ok_or_else(|| Error::Invalid(format!("the plan produced no `{}`", m.resource)))
        };
        let same = self.maps.len() == self.planned.maps.len()
            && self.maps.iter().zip(&self.planned.maps).all(|(o, m)| {
                o.resource == m.resource && textures.get(&m.resource) == Some(&o.texture)
            });
        if !same {
            self.maps = self
                .planned
                .maps
                .iter()
                .map(|m| {
                    let texture = texture(m)?;
                    Ok(OutputMap {
                        resource: m.resource.clone(),
                        wgsl_type: m.wgsl_type,
                        view: depth_aspect_view(&texture),
                        texture,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
        }
        Ok(self.maps.clone())
    }

    /// The host's WGSL: the technique's visibility function, its maps bound at
    /// `@group(group) @binding(first_binding + k)` (then a comparison sampler where
    /// [`Prefilter::needs_comparison_sampler`]) and
    /// `fn shadowgraph_visibility(l: Light, p: vec3<f32>, n: vec3<f32>) -> f32`.
    pub fn wgsl(&self, group: u32, first_binding: u32) -> Result<String> {
        wgsl::host_block(&self.config.technique, group, first_binding)
    }

    /// The host's bind group layout entries for [`Prefilter::wgsl`]'s bindings (maps, then
    /// the comparison sampler where needed), visible to `visibility`.
    pub fn layout_entries(
        &self,
        first_binding: u32,
        visibility: wgpu::ShaderStages,
    ) -> Result<Vec<wgpu::BindGroupLayoutEntry>> {
        wgsl::layout_entries(&self.config.technique, first_binding, visibility)
    }

    /// Whether the technique reads the raw depth through a comparison sampler (hardware PCF):
    /// the host binds one (linear filtering, compare less-equal) after the maps.
    pub fn needs_comparison_sampler(&self) -> Result<bool> {
        wgsl::needs_comparison_sampler(&self.config.technique)
    }

    /// Times each kernel from now on with GPU timestamps written between the stage's passes
    /// ([`GpuTimer`]); an error when the device was created without `TIMESTAMP_QUERY` and
    /// `TIMESTAMP_QUERY_INSIDE_ENCODERS`.
    pub fn enable_timing(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<()> {
        let spans = self.planned.plan.steps.len().max(1) as u32;
        let timer = GpuTimer::new(device, queue, spans).ok_or(StageError::MissingFeature {
            feature: TIMER_FEATURES.difference(device.features()),
            needed_for: "per-kernel GPU timing",
        })?;
        self.timer = Some(timer);
        Ok(())
    }

    /// `(node, milliseconds)` per kernel of the last [`Prefilter::record`], e.g.
    /// `("vsm.blur_h", 0.21)`. Call after the host's submission of that encoder; it waits for
    /// the queries' readback (see [`Prefilter::poll_timings`] for a read that never waits).
    /// Empty before timing is enabled.
    pub fn timings(&mut self, device: &wgpu::Device) -> Result<Vec<(String, f64)>> {
        let Some(timer) = &mut self.timer else {
            return Ok(Vec::new());
        };
        Ok(strip_light(timer.read(device)?))
    }

    /// The timings of the newest recorded frame whose timestamps have arrived, without
    /// waiting: call after submitting each encoder [`Prefilter::record`] recorded into; the
    /// times of a frame arrive once the device has finished it, typically a frame later
    /// (`None` until then, and before timing is enabled). Older unread frames are dropped.
    pub fn poll_timings(&mut self, device: &wgpu::Device) -> Result<Option<Vec<(String, f64)>>> {
        let Some(timer) = &mut self.timer else {
            return Ok(None);
        };
        Ok(timer.collect(device)?.pop().map(strip_light))
    }

    /// The configuration in use (validated, exponents clamped).
    pub fn config(&self) -> &PrefilterConfig {
        &self.config
    }

    /// Values validation changed, one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The map side of the current plan (the last depth texture's, or the configuration's).
    pub fn size(&self) -> u32 {
        self.planned.key.size
    }

    /// Names of the planned kernels' nodes, in execution order.
    pub fn kernels(&self) -> Vec<String> {
        self.planned
            .plan
            .steps
            .iter()
            .map(|s| s.node.name.clone())
            .collect()
    }

    /// Textures the stage's pool holds (constant while the size stays the same).
    pub fn texture_count(&self) -> usize {
        self.executor.texture_count()
    }

    /// Pipelines created so far.
    pub fn pipeline_count(&self) -> usize {
        self.executor.kernels.len()
    }
}

/// Node names are `light0.<node>`, like the resource names (`technique::depth_name`): the
/// light's prefix is dropped.
fn strip_light(spans: Vec<(String, f64)>) -> Vec<(String, f64)> {
    spans
        .into_iter()
        .map(|(name, ms)| match name.strip_prefix("light0.") {
            Some(n) => (n.to_string(), ms),
            None => (name, ms),
        })
        .collect()
}

/// Parameters to plan with before the first frame: pipelines do not depend on them.
fn planning_params() -> LightParams {
    LightParams::orthographic(Mat4::IDENTITY, 1.0, 0.1, 1.0)
}

/// The graph of light 0 with `config`'s technique, planned for the maps the shading reads.
fn plan_for(config: &PrefilterConfig, light: &LightParams, size: u32) -> Result<Planned> {
    let scene_light = light.scene_light(config, size);
    let mut graph = Graph::default();
    let maps = light_maps(&mut graph, &scene_light);
    let outputs: Vec<&str> = maps.iter().map(|m| m.resource.as_str()).collect();
    let plan = plan(&graph, &outputs)?;
    Ok(Planned {
        key: PlanKey::new(light, size),
        plan,
        maps,
    })
}

/// The maps light 0's technique reads, in binding order. `add_light_nodes` returns one per
/// light today; when it returns a list, this is the one line to change.
fn light_maps(graph: &mut Graph, light: &Light) -> Vec<MapInput> {
    let input = technique::add_light_nodes(graph, 0, light);
    input
        .maps
        .into_iter()
        .map(|resource| MapInput {
            resource,
            wgsl_type: input.wgsl_type,
        })
        .collect()
}

/// One map the technique's visibility function reads.
#[derive(Clone, Debug)]
struct MapInput {
    /// Graph resource.
    resource: String,
    /// WGSL type of its binding.
    wgsl_type: &'static str,
}

/// The side of `depth`, or what makes it unusable.
fn check_depth(depth: &wgpu::Texture) -> Result<u32, StageError> {
    if !DEPTH_FORMATS.contains(&depth.format()) {
        let accepted: Vec<String> = DEPTH_FORMATS.iter().map(|f| format!("{f:?}")).collect();
        return Err(StageError::DepthFormat {
            format: depth.format(),
            accepted: accepted.join(", "),
        });
    }
    if !depth.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(StageError::DepthUsage {
            usage: depth.usage(),
        });
    }
    let (dimension, layers, samples) = (
        depth.dimension(),
        depth.depth_or_array_layers(),
        depth.sample_count(),
    );
    if dimension != wgpu::TextureDimension::D2 || layers != 1 || samples != 1 {
        return Err(StageError::DepthLayout {
            dimension,
            layers,
            samples,
        });
    }
    if depth.width() != depth.height() {
        return Err(StageError::DepthNotSquare {
            width: depth.width(),
            height: depth.height(),
        });
    }
    Ok(depth.width())
}

fn depth_aspect_view(t: &wgpu::Texture) -> wgpu::TextureView {
    crate::created::view(
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
