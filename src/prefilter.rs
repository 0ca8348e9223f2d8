//! The plug-in preprocess stage: a host with its own wgpu renderer hands over its device, an
//! encoder and a depth texture it rasterized from a light, and gets back the filtered maps of a
//! technique and the WGSL that samples them. Nothing of the host's is kept: every call borrows
//! the device and records into the host's encoder; the stage never submits, reads back or
//! polls (only [`Prefilter::timings`], which the host calls after its submission, waits).
//!
//! ```no_run
//! # fn frame(device: &wgpu::Device, depth: &wgpu::Texture, view: glam::Mat4)
//! #     -> shadowgraph::Result<()> {
//! use shadowgraph::{LightParams, Prefilter, PrefilterConfig};
//! let mut stage = Prefilter::new(device, &PrefilterConfig::vsm(1024))?;   // pipelines, once
//! let host_wgsl = stage.wgsl(1, 0)?;         // prepend to the host's shader: group 1, binding 0…
//! let mut encoder = device.create_command_encoder(&Default::default());
//! // … the host's depth pass into `depth` …
//! let light = LightParams::orthographic(view, 5.0, 2.0, 20.0);
//! let out = stage.record(device, &mut encoder, depth, &light)?;
//! // bind out.maps[k].view at binding k of group 1, upload bytemuck::bytes_of(&out.light)
//! // as the `sg_Light` the host passes to `shadowgraph_visibility(l, p, n)`, then submit.
//! # Ok(()) }
//! ```
//!
//! Many lights: one stage, `record_light(k, …, DepthLayer::new(&array, k), …)` per light (or
//! cascade, [`cascades`]), the functions once ([`Prefilter::wgsl_functions`]) and one
//! [`Prefilter::wgsl_light`] block per light in the host's shader.

pub mod cascades;
mod config;
mod depth;
mod light_params;
mod limits;
mod planning;
pub mod wgsl;

use std::collections::HashMap;

use glam::{Mat4, Vec3};

pub use crate::error::StageError;
/// The light's GPU description the exported WGSL's `Light` mirrors (what
/// [`LightParams::light_gpu`] returns), where a host looks for it.
pub use crate::wgsl_mirrors::LightGpu;
pub use config::PrefilterConfig;
pub use depth::{DEPTH_FORMATS, DepthLayer};
pub use light_params::LightParams;

use crate::error::{Error, Result};
use crate::exec::{Executor, KernelCache};
use crate::graph::Plan;
use crate::technique;
use crate::timer::{GpuTimer, TIMER_FEATURES};
use planning::{MapInput, plan_for, planning_params, strip_light};

/// One map the visibility function reads.
#[derive(Clone, Debug)]
pub struct OutputMap {
    /// The graph resource (e.g. `light0.vsm.blur_v`).
    pub resource: String,
    /// Its WGSL binding type (e.g. `texture_2d<f32>`; `texture_2d<u32>` for packed f16
    /// moments and fixed-point tables).
    pub wgsl_type: &'static str,
    /// The resource's format in the graph: [`crate::graph::PACKED_F16X2`] where the texture
    /// (`r32uint`) holds two f16 moments a texel as `pack2x16float` words (read them back with
    /// [`crate::gpu::read_resource_texture`]), else the texture's own format.
    pub format: wgpu::TextureFormat,
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
    /// The WGSL `struct sg_Light` to upload (bytemuck) for this frame's matrices.
    pub light: LightGpu,
}

/// A plan for one depth size and depth mapping.
struct Planned {
    key: PlanKey,
    plan: Plan,
    maps: Vec<MapInput>,
}

/// One face of a point light's depth pass ([`Prefilter::point_views`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointView {
    /// World → clip of the face (wgpu's depth convention: 0 at near, 1 at far).
    pub view_proj: Mat4,
    /// The face's tile in the atlas: x, y, width, height in texels.
    pub viewport: [u32; 4],
}

/// What a plan depends on besides the technique: the map size and the linearization.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct PlanKey {
    size: u32,
    perspective: bool,
    point: bool,
    near: u32,
    far: u32,
    /// A cascade's own `max_search` (it codes a fixed-point table's window).
    max_search: Option<u32>,
}

impl PlanKey {
    fn new(light: &LightParams, size: u32) -> Self {
        Self {
            size,
            perspective: light.perspective,
            point: light.point,
            near: light.near.to_bits(),
            far: light.far.to_bits(),
            max_search: light.max_search.map(f32::to_bits),
        }
    }
}

/// The sampler a host binds after the maps where [`Prefilter::needs_filtering_sampler`]
/// (defined beside the tables it reads, [`crate::sat::SAT_SAMPLER_DESCRIPTOR`]).
pub use crate::sat::SAT_SAMPLER_DESCRIPTOR;

/// Lights one stage serves at most ([`Prefilter::record_light`]'s `slot`).
pub const MAX_LIGHTS: usize = 256;

/// The stage: pipelines made once for a configuration and shared by every light it serves,
/// textures pooled across frames per light.
pub struct Prefilter {
    config: PrefilterConfig,
    warnings: Vec<String>,
    /// The pipelines, shared by the lights' executors (each borrows them while it records).
    kernels: KernelCache,
    /// Per light slot: its plan, pooled textures and last maps (`None`: never recorded; slot
    /// 0 is made by [`Prefilter::new`]).
    lights: Vec<Option<LightSlot>>,
    timer: Option<GpuTimer>,
    /// Compute dispatches recorded so far, every light slot together.
    dispatches: u64,
}

/// What one light of a stage keeps between frames.
struct LightSlot {
    /// Its textures (its pipelines are the stage's, lent while it records).
    executor: Executor,
    planned: Planned,
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
        limits::check(device, &planned.plan, config.size, 0)?;
        // Features the technique's storage needs (e.g. unorm16 MSM moments).
        crate::limits::check_features(
            device,
            &[planning_params().scene_light(&config, config.size)],
        )?;
        let mut executor = Executor::new();
        executor.prepare(device, &planned.plan)?;
        let kernels = std::mem::take(&mut executor.kernels);
        Ok(Self {
            config,
            warnings,
            kernels,
            lights: vec![Some(LightSlot {
                executor,
                planned,
                maps: Vec::new(),
            })],
            timer: None,
            dispatches: 0,
        })
    }

    /// Records the technique's kernels over `depth` into `encoder` and returns the maps the
    /// visibility function reads: light slot 0 of [`Prefilter::record_light`]. Nothing is
    /// submitted.
    pub fn record<'a>(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: impl Into<DepthLayer<'a>>,
        light: &LightParams,
    ) -> Result<PrefilterOutput> {
        self.record_light(0, device, encoder, depth, light)
    }

    /// Records the kernels of light `slot` (below [`MAX_LIGHTS`]) over `depth` into
    /// `encoder`: one stage serves many lights with one set of pipelines, and each slot keeps
    /// its own textures, so its maps stay valid until the next record of the same slot (or a
    /// new map size). Nothing is submitted.
    ///
    /// `depth` is a texture of one layer (`&wgpu::Texture`) or [`DepthLayer`]: one layer of a
    /// 2-D array, read through a view of it (no copy); an array passed whole is refused
    /// ([`StageError::DepthArray`]). It must be square, single-sampled, in one of
    /// [`DEPTH_FORMATS`], with `TEXTURE_BINDING`. A size other than the slot's last one replans
    /// and reallocates its pooled textures; pipelines are kept. With timing enabled, slot 0's
    /// kernels are timed.
    pub fn record_light<'a>(
        &mut self,
        slot: usize,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: impl Into<DepthLayer<'a>>,
        light: &LightParams,
    ) -> Result<PrefilterOutput> {
        let depth = depth.into();
        light.validate()?;
        if light.max_search.is_some() && self.config.technique.max_search().is_none() {
            return Err(StageError::LightParams {
                field: "max_search",
                message: format!(
                    "technique \"{}\" has no search to cap (PCSS and the soft techniques do)",
                    self.config.technique.name()
                ),
            }
            .into());
        }
        if slot >= MAX_LIGHTS {
            return Err(StageError::LightSlot {
                slot,
                max: MAX_LIGHTS,
            }
            .into());
        }
        let size = depth::check_depth(depth, light)?;
        let key = PlanKey::new(light, size);
        self.replan(device, slot, key, light)?;
        let config = &self.config;
        let one = self.lights[slot]
            .as_mut()
            .ok_or_else(|| Error::Invalid(format!("light slot {slot} was not planned")))?;
        let name = technique::depth_name(0);
        let imports = HashMap::from([(name.clone(), depth.texture().clone())]);
        let mut layers = HashMap::new();
        if depth.texture().depth_or_array_layers() > 1 {
            layers.insert(name, depth.layer());
        }
        let mut timer = self.timer.as_mut().filter(|_| slot == 0);
        if let Some(t) = timer.as_mut() {
            t.reset();
        }
        // The slot's executor records with the stage's pipelines, then gives them back.
        one.executor.kernels = std::mem::take(&mut self.kernels);
        let before = one.executor.dispatch_count();
        let recorded = one.executor.record_layers(
            device,
            encoder,
            &one.planned.plan,
            &imports,
            &layers,
            timer.as_deref_mut(),
        );
        self.kernels = std::mem::take(&mut one.executor.kernels);
        self.dispatches += one.executor.dispatch_count() - before;
        let outputs = recorded?;
        if let Some(t) = timer {
            t.resolve(encoder);
        }
        let maps = one.output_maps(&outputs.textures)?;
        Ok(PrefilterOutput {
            maps,
            light: light.light_gpu(config, size),
        })
    }

    /// The cascades of a directional light shining along `direction` for `camera`, laid out
    /// by the config's `cascades` (count and split; see [`PrefilterConfig::with_cascades`]) on
    /// `size`² maps, casters kept `caster_margin` world units toward the light: record cascade
    /// `k` in light slot `k` with `cascades[k].light`, and give cascade 0's `sg_Light` the pick
    /// fields ([`cascades::pick_fields`] with the config's blend band). Each cascade has its
    /// own depth range, so PCSS and the soft techniques are refused here: their cascades share
    /// the light's depth axis ([`Prefilter::fit_light_cascades`]).
    pub fn fit_cascades(
        &self,
        camera: &cascades::CascadeCamera,
        direction: Vec3,
        caster_margin: f32,
    ) -> Result<Vec<cascades::Cascade>> {
        if self.config.technique.max_search().is_some() {
            return Err(StageError::Config {
                field: "technique".into(),
                message: format!(
                    "\"{}\" sizes its penumbra from depths along the light's axis, which fit_cascades gives each cascade anew: fit its cascades with fit_light_cascades(&camera, &light), which keeps the light's plane and widens each map by the technique's reach",
                    self.config.technique.name()
                ),
            }
            .into());
        }
        let c = self.config.cascades;
        let layout = cascades::CascadeLayout {
            count: c.count,
            lambda: c.lambda,
            map_size: self.config.size,
            caster_margin,
        };
        Ok(cascades::fit_cascades(camera, direction, &layout)?)
    }

    /// The cascades of the host's directional `light` (its one orthographic map: view, planes,
    /// half-width) for `camera`, for every technique the stage runs in cascades, PCSS and the
    /// soft techniques included ([`cascades::fit_light_cascades`]: `light` moved across its
    /// direction onto each slice, the same planes, each map widened by the technique's reach
    /// and capped at it by its own [`LightParams::max_search`]). Record cascade `k` in light
    /// slot `k` with `cascades[k].light` and fill cascade 0's pick fields as for
    /// [`Prefilter::fit_cascades`]; `light`'s near and far planes must hold every caster.
    pub fn fit_light_cascades(
        &self,
        camera: &cascades::CascadeCamera,
        light: &LightParams,
    ) -> Result<Vec<cascades::Cascade>> {
        Ok(cascades::fit_light_cascades(camera, light, &self.config)?)
    }

    /// A point light's faces for the host's depth pass into a `3·face × 2·face` depth
    /// texture: per face (+X, −X, +Y, −Y, +Z, −Z) its world → clip matrix (wgpu's depth
    /// convention, each frustum widened by the guard band of the stage's technique) and its
    /// viewport `[x, y, width, height]` in texels; draw the scene once per face with that
    /// viewport (and scissor), then [`Prefilter::record`] the texture with the same `light`.
    /// Refused where the technique's reach cannot be bounded to a face (e.g. `smrt`) or the
    /// guard band leaves less than half the face.
    pub fn point_views(&self, light: &LightParams, face: u32) -> Result<Vec<PointView>> {
        if !light.point {
            return Err(StageError::LightParams {
                field: "point",
                message: "point_views needs a point light (`LightParams::point`)".into(),
            }
            .into());
        }
        light.validate()?;
        self.point_layout(face)?;
        Ok(light
            .scene_light(&self.config, face)
            .raster_views()
            .into_iter()
            .map(|(m, viewport)| PointView {
                view_proj: Mat4::from_cols_array(&m),
                viewport,
            })
            .collect())
    }

    /// The face layout of the stage's technique on `face`-texel faces, or why there is none.
    fn point_layout(&self, face: u32) -> Result<crate::model::point::PointLayout> {
        crate::technique::reach(&self.config.technique, face)
            .and_then(|r| crate::model::point::PointLayout::new(face, r))
            .map_err(|message| {
                StageError::Config {
                    field: "technique".into(),
                    message,
                }
                .into()
            })
    }

    /// The host's WGSL: the technique's visibility function, its maps bound at
    /// `@group(group) @binding(first_binding + k)` (then a comparison sampler where
    /// [`Prefilter::needs_comparison_sampler`], a filtering one where
    /// [`Prefilter::needs_filtering_sampler`]) and
    /// `fn shadowgraph_visibility(l: sg_Light, p: vec3<f32>, n: vec3<f32>) -> f32` (upload
    /// [`PrefilterOutput::light`] as the `sg_Light`).
    pub fn wgsl(&self, group: u32, first_binding: u32) -> Result<String> {
        wgsl::host_block(&self.config.technique, group, first_binding)
    }

    /// Plans light `slot` for `key` unless it is planned for it already. A new slot, or a new
    /// map size, is checked against the device's limits and the memory budget with every
    /// other slot's textures counted; a new size drops the slot's old textures.
    fn replan(
        &mut self,
        device: &wgpu::Device,
        slot: usize,
        key: PlanKey,
        light: &LightParams,
    ) -> Result<()> {
        if self.lights.len() <= slot {
            self.lights.resize_with(slot + 1, || None);
        }
        let current = self.lights[slot].as_ref().map(|l| l.planned.key);
        if current == Some(key) {
            return Ok(());
        }
        if light.point {
            // The faces' guard band is the technique's reach: refuse what six faces cannot
            // bound before planning.
            self.point_layout(key.size)?;
        }
        let planned = plan_for(&self.config, light, key.size)?;
        let resized = current.is_none_or(|k| k.size != key.size);
        if resized {
            let others: u64 = self
                .lights
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != slot)
                .filter_map(|(_, l)| l.as_ref())
                .map(|l| l.planned.plan.slot_bytes())
                .sum();
            limits::check(device, &planned.plan, key.size, others)?;
        }
        match &mut self.lights[slot] {
            Some(one) => {
                if resized {
                    // Textures of the old size go back to the device; pipelines stay.
                    one.executor = Executor::new();
                }
                one.planned = planned;
            }
            empty => {
                *empty = Some(LightSlot {
                    executor: Executor::new(),
                    planned,
                    maps: Vec::new(),
                })
            }
        }
        Ok(())
    }

    /// Light slot 0 (made by [`Prefilter::new`]).
    fn first(&self) -> Option<&LightSlot> {
        self.lights.first().and_then(Option::as_ref)
    }

    /// A cascaded directional light's blocks for the config's cascade count, and
    /// `shadowgraph_visibility_cascaded_{name}(l: array<sg_Light, count>, p, n)`, which picks
    /// the receiver's cascade (`l[0]` holding the pick fields, [`cascades::pick_fields`]) and
    /// blends toward the next across the band ([`wgsl::cascades_block`]); cascade `c`'s
    /// bindings start at `first_binding + c · layout_entries(0, …).len()`. Include the
    /// functions once, as for [`Prefilter::wgsl_light`].
    pub fn wgsl_cascades(&self, name: &str, group: u32, first_binding: u32) -> Result<String> {
        wgsl::cascades_block(
            &self.config.technique,
            name,
            group,
            first_binding,
            self.config.cascades.count,
        )
    }

    /// One light's bindings and functions for a shader module holding several lights, without
    /// the functions they call: include [`Prefilter::wgsl_functions`] (or
    /// [`wgsl::functions_for`] the techniques of several stages) once, then one block per
    /// light, each at its own bindings: `shadowgraph_{name}_map{k}` and
    /// `shadowgraph_visibility_{name}(l: sg_Light, p, n)` ([`wgsl::light_block`]).
    pub fn wgsl_light(&self, name: &str, group: u32, first_binding: u32) -> Result<String> {
        wgsl::light_block(&self.config.technique, name, group, first_binding)
    }

    /// The technique's functions (`sg_Light`, `sg_vis_…` and their helpers), no bindings.
    pub fn wgsl_functions(&self) -> Result<String> {
        wgsl::technique_functions(&self.config.technique)
    }

    /// The host's bind group layout entries for [`Prefilter::wgsl`]'s bindings (maps, then
    /// the comparison and filtering samplers where needed), visible to `visibility`.
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

    /// Whether the technique reads f32 summed-area tables (`sat_sums = "float"`) with
    /// filtered fetches: the host binds a filtering sampler ([`SAT_SAMPLER_DESCRIPTOR`]) after
    /// the maps (and after the comparison sampler, where there is one), and the tables bind
    /// as filterable float, which needs the device feature `FLOAT32_FILTERABLE`.
    pub fn needs_filtering_sampler(&self) -> Result<bool> {
        wgsl::needs_filtering_sampler(&self.config.technique)
    }

    /// Times each kernel from now on with GPU timestamps written between the stage's passes
    /// ([`GpuTimer`]); an error when the device was created without `TIMESTAMP_QUERY` and
    /// `TIMESTAMP_QUERY_INSIDE_ENCODERS`.
    pub fn enable_timing(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<()> {
        let spans = self
            .first()
            .map_or(1, |l| l.planned.plan.steps.len().max(1)) as u32;
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
        self.first()
            .map_or(self.config.size, |l| l.planned.key.size)
    }

    /// Light slots in use (slot 0 and every slot recorded since).
    pub fn light_count(&self) -> usize {
        self.lights.iter().flatten().count()
    }

    /// Names of the planned kernels' nodes, in execution order.
    pub fn kernels(&self) -> Vec<String> {
        self.first()
            .into_iter()
            .flat_map(|l| &l.planned.plan.steps)
            .map(|s| s.node.name.clone())
            .collect()
    }

    /// Textures the stage's pools hold, all light slots together (constant while the sizes
    /// stay the same).
    pub fn texture_count(&self) -> usize {
        self.lights
            .iter()
            .flatten()
            .map(|l| l.executor.texture_count())
            .sum()
    }

    /// Compute dispatches the stage has recorded since it was made, every light slot
    /// together: a frame's are the difference across it. Only [`Prefilter::record_light`]
    /// dispatches, so a static light the host does not record again costs none.
    pub fn dispatch_count(&self) -> u64 {
        self.dispatches
    }

    /// Pipelines created so far (shared by every light slot).
    pub fn pipeline_count(&self) -> usize {
        self.kernels.len()
    }
}
