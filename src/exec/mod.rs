//! The executor: records a [`Plan`] into a caller's command encoder, one compute pass per node,
//! each node a span of the caller's [`GpuTimer`] when one is given. It borrows the device and
//! never submits, so it runs the same inside shadowgraph's renderer and inside a host's frame.
//! What a plan needs (textures, the parameter and counter buffers, every dispatch's bind group)
//! is made on its first run and reused while the plan and its imported textures stay the same:
//! a frame records passes and creates nothing.
//!
//! It knows no kernel, technique or filter: a node binds its slots by name and dispatches as
//! its [`crate::graph::Dispatch`] says, several dispatches with their own parameters and mip
//! levels included. By concern: [`pipelines`] (kernels compiled once and cached), [`pool`]
//! (textures by shape, the run's outputs), `record` (bind groups and the passes).

mod buffers;
mod monomorph;
mod node_constants;
mod packed;
pub mod pipelines;
mod placement;
pub mod pool;
mod record;

use std::collections::HashMap;

use self::record::{PreparedStep, RunParams, StepBuffers};
use crate::error::{ExecError, Result};
use crate::graph::{Plan, Slot};
use crate::timer::GpuTimer;
pub use pipelines::{
    ComputeKernel, KERNEL_LAYOUT_ENV, KernelCache, KernelLayout, REDESIGNED_KERNELS,
    REDESIGNED_MODULES, SHADER_CHECKS_ENV, ShaderChecks, WorkgroupInit, specialized_buffer_source,
    specialized_source, wgsl_storage_format,
};
pub use placement::{buffer_slots, slot_in_buffer};
use pool::Held;
pub use pool::{BufferMap, Outputs, TexturePool};

/// Runs plans: owns pipelines, pooled textures and what the last plan's run needs; borrows
/// everything else.
#[derive(Default)]
pub struct Executor {
    /// Compiled kernels.
    pub kernels: KernelCache,
    pool: TexturePool,
    in_use: Vec<(Slot, Held)>,
    prepared: Option<Prepared>,
    /// Compute dispatches recorded so far.
    dispatches: u64,
    /// Whether requested outputs may live in storage buffers ([`Executor::set_output_buffers`]).
    output_buffers: bool,
}

/// What a plan's run needs besides its passes, made once and reused while the plan and the
/// imported textures stay the same.
struct Prepared {
    plan: Plan,
    /// The imported textures bound, by resource name.
    imports: Vec<(String, wgpu::Texture)>,
    /// The layer of each import read as one layer of an array texture.
    layers: HashMap<String, u32>,
    outputs: Outputs,
    /// Every dispatch's parameters.
    params: RunParams,
    /// Per step: its pipeline and dispatches.
    steps: Vec<PreparedStep>,
}

impl Executor {
    /// An executor with empty caches.
    pub fn new() -> Self {
        Self::default()
    }

    /// Compiles every kernel `plan` uses (also done lazily by [`Executor::record`]).
    pub fn prepare(&mut self, device: &wgpu::Device, plan: &Plan) -> Result<()> {
        let in_buffer = self.buffer_slots(device, plan)?;
        for step in &plan.steps {
            record::compile(&mut self.kernels, device, plan, &in_buffer, &step.node)?;
        }
        Ok(())
    }

    /// Per slot of `plan`, whether this executor holds it in a storage buffer on `device`
    /// ([`buffer_slots`] in its kernels' layout, with their sources).
    pub fn buffer_slots(&self, device: &wgpu::Device, plan: &Plan) -> Result<Vec<bool>> {
        let layout = self.kernels.layout_for(device)?;
        let sources = self.kernels.sources_for(device)?;
        let limits = device.limits();
        buffer_slots(
            plan,
            layout,
            &limits,
            sources.as_deref(),
            self.output_buffers,
        )
    }

    /// Lets requested outputs that are never filtered (a fixed-point summed-area table) live
    /// in storage buffers too, in a layout that keeps intermediates in buffers
    /// ([`KernelLayout::buffers_intermediates`]): for a caller whose readers of them are
    /// rewritten as the graph's kernels are (the renderer's shading pass), never for a host,
    /// which binds the outputs as textures. Off by default.
    pub fn set_output_buffers(&mut self, on: bool) {
        self.output_buffers = on;
    }

    /// Compute dispatches this executor has recorded so far, every run together (a run's are
    /// the difference across it).
    pub fn dispatch_count(&self) -> u64 {
        self.dispatches
    }

    /// Textures (and storage buffers) held by the pool (constant across runs of the same
    /// plan).
    pub fn texture_count(&self) -> usize {
        self.pool.texture_count() + self.in_use.len()
    }

    /// Drops every pooled texture and what the last run prepared (whose bind groups hold
    /// them), keeping the compiled kernels: the next run makes its textures again. For a caller
    /// that moves on between plans of very different sizes and would otherwise keep every
    /// shape it used: the kernel benchmark releases after each case, so that a case runs beside
    /// its own textures only, not the gigabytes its predecessors pooled at 8192².
    pub fn release_textures(&mut self) {
        self.prepared = None;
        self.in_use.clear();
        self.pool = TexturePool::default();
    }

    /// Records `plan` into `encoder`. `imports` gives a texture for every imported resource.
    /// With a `timer`, each node is a span named after it, and the last one ends with the plan.
    /// The first run of a plan makes its textures, buffers and bind groups; later runs of the
    /// same plan over the same imported textures reuse them and return the same textures.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        plan: &Plan,
        imports: &HashMap<String, wgpu::Texture>,
        timer: Option<&mut GpuTimer>,
    ) -> Result<Outputs> {
        self.record_layers(device, encoder, plan, imports, &HashMap::new(), timer)
    }

    /// [`Executor::record`] where some imports are one layer of an array texture: `layers`
    /// gives that layer by resource name (read through a 2-D view of it; no copy).
    pub fn record_layers(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        plan: &Plan,
        imports: &HashMap<String, wgpu::Texture>,
        layers: &HashMap<String, u32>,
        timer: Option<&mut GpuTimer>,
    ) -> Result<Outputs> {
        self.record_run(device, encoder, plan, imports, layers, None, timer)
    }

    /// [`Executor::record`] of only the steps `run` marks (one flag per step of `plan`): the
    /// others record nothing, and their outputs keep what they last wrote while the plan, its
    /// imports and its textures stay the same (the returned textures say which) and no
    /// recorded step writes the same texture. The renderer skips a cached light's steps so.
    pub fn record_steps(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        plan: &Plan,
        imports: &HashMap<String, wgpu::Texture>,
        run: &[bool],
        timer: Option<&mut GpuTimer>,
    ) -> Result<Outputs> {
        if run.len() != plan.steps.len() {
            return Err(crate::error::Error::Invalid(format!(
                "{} step flags for a plan of {} steps",
                run.len(),
                plan.steps.len()
            )));
        }
        let layers = HashMap::new();
        self.record_run(device, encoder, plan, imports, &layers, Some(run), timer)
    }

    #[expect(
        clippy::too_many_arguments,
        reason = "a run's inputs and the steps it records"
    )]
    fn record_run(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        plan: &Plan,
        imports: &HashMap<String, wgpu::Texture>,
        layers: &HashMap<String, u32>,
        run: Option<&[bool]>,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<Outputs> {
        // A plan's fields are public: check what the binding below relies on first.
        plan.check()?;
        check_layers(imports, layers)?;
        let same_plan = self.prepared.as_ref().is_some_and(|p| p.plan == *plan);
        let prepared = match self.prepared.take() {
            Some(p) if same_plan && p.imports_match(imports, layers) => p,
            // New imported textures (a host's depth map): the nodes reading them are bound anew.
            Some(p) if same_plan => self.rebind_imports(device, p, imports, layers)?,
            _ => self.prepare_run(device, plan, imports, layers)?,
        };
        self.dispatches += record::encode(encoder, &prepared, run, timer.as_deref_mut());
        let outputs = prepared.outputs.clone();
        self.prepared = Some(prepared);
        // The last node ends here, not at whatever the caller records next.
        if let Some(t) = timer {
            t.end(encoder);
        }
        Ok(outputs)
    }

    /// Takes `plan`'s textures from the pool and makes its buffers and bind groups.
    fn prepare_run(
        &mut self,
        device: &wgpu::Device,
        plan: &Plan,
        imports: &HashMap<String, wgpu::Texture>,
        layers: &HashMap<String, u32>,
    ) -> Result<Prepared> {
        // Textures of the previous run go back to the pool, then each slot takes one (or a
        // buffer, where the layout keeps the slot's intermediates in one).
        for (slot, held) in self.in_use.drain(..) {
            self.pool.give_back(slot, held);
        }
        let in_buffer = self.buffer_slots(device, plan)?;
        let held: Vec<Held> = plan
            .slots
            .iter()
            .zip(&in_buffer)
            .map(|(s, &buffer)| {
                if buffer {
                    Held::Buffer(self.pool.take_buffer(device, s))
                } else {
                    Held::Texture(self.pool.take(device, s))
                }
            })
            .collect();
        self.in_use = plan
            .slots
            .iter()
            .cloned()
            .zip(held.iter().cloned())
            .collect();
        let textures = pool::plan_textures(plan, &held, imports)?;
        let outputs = Outputs::new(device, plan, textures, layers.clone());
        let params = record::params_buffer(device, plan)?;
        let mut bound = Vec::new();
        for (si, step) in plan.steps.iter().enumerate() {
            let buffers = StepBuffers {
                params: &params.buffer,
                at: &params.at[si],
                outputs: &outputs,
                step: si,
            };
            bound.push(record::bind_step(
                &mut self.kernels,
                device,
                &step.node,
                &buffers,
            )?);
        }
        let imports = plan
            .resources
            .iter()
            .filter(|r| r.slot.is_none())
            .filter_map(|r| {
                let t = imports.get(&r.resource.name)?;
                Some((r.resource.name.clone(), t.clone()))
            })
            .collect();
        Ok(Prepared {
            plan: plan.clone(),
            imports,
            layers: layers.clone(),
            outputs,
            params,
            steps: bound,
        })
    }

    /// `prepared` over other imported textures: the same textures and buffers, the steps that
    /// read an import bound anew.
    fn rebind_imports(
        &mut self,
        device: &wgpu::Device,
        mut prepared: Prepared,
        imports: &HashMap<String, wgpu::Texture>,
        layers: &HashMap<String, u32>,
    ) -> Result<Prepared> {
        let held: Vec<Held> = self.in_use.iter().map(|(_, h)| h.clone()).collect();
        let (textures, buffers) = pool::plan_textures(&prepared.plan, &held, imports)?;
        prepared.outputs.textures = textures;
        prepared.outputs.buffers = buffers;
        prepared.outputs.layers = layers.clone();
        prepared.layers = layers.clone();
        for (name, t) in &mut prepared.imports {
            if let Some(new) = imports.get(name) {
                *t = new.clone();
            }
        }
        for (si, step) in prepared.plan.steps.iter().enumerate() {
            let reads_import = step
                .node
                .inputs
                .iter()
                .any(|(_, r)| prepared.imports.iter().any(|(name, _)| name == r));
            if reads_import {
                let buffers = StepBuffers {
                    params: &prepared.params.buffer,
                    at: &prepared.params.at[si],
                    outputs: &prepared.outputs,
                    step: si,
                };
                prepared.steps[si] =
                    record::bind_step(&mut self.kernels, device, &step.node, &buffers)?;
            }
        }
        Ok(prepared)
    }
}

impl Prepared {
    /// Whether `imports` holds the same texture (and layer) for every import this run bound.
    fn imports_match(
        &self,
        imports: &HashMap<String, wgpu::Texture>,
        layers: &HashMap<String, u32>,
    ) -> bool {
        self.layers == *layers
            && self
                .imports
                .iter()
                .all(|(name, t)| imports.get(name) == Some(t))
    }
}

/// Every layer names an import that has it.
fn check_layers(
    imports: &HashMap<String, wgpu::Texture>,
    layers: &HashMap<String, u32>,
) -> Result<()> {
    for (name, &layer) in layers {
        let t = imports
            .get(name)
            .ok_or_else(|| ExecError::MissingImport(name.clone()))?;
        if layer >= t.depth_or_array_layers() {
            return Err(ExecError::NoLayer {
                resource: name.clone(),
                layer,
                layers: t.depth_or_array_layers(),
            }
            .into());
        }
    }
    Ok(())
}
