//! The executor: records a [`Plan`] into a caller's command encoder, one compute pass per node,
//! each node a span of the caller's [`GpuTimer`] when one is given. It borrows the device and
//! never submits, so it runs the same inside shadowgraph's renderer and inside a host's frame.
//! What a plan needs (textures, the parameter and counter buffers, every node's bind group) is
//! made on its first run and reused while the plan and its imported textures stay the same: a
//! frame records passes and creates nothing.

use std::collections::HashMap;
use std::sync::Arc;

use crate::created;
use crate::error::{Error, Result};
use crate::filter::{MIP_LEVELS_PER_DISPATCH, MipParams, mip_dispatches};
use crate::gpu::{read_buffer, scoped};
use crate::graph::{Dispatch, Plan, Slot};
use crate::kernels::{self, Reflection};
pub use crate::timer::GpuTimer;

/// A compute pipeline with the layouts reflected from its WGSL.
pub struct ComputeKernel {
    /// Kernel name (labels are `shadowgraph.<name>`).
    pub name: String,
    /// Bindings and workgroup size.
    pub reflection: Reflection,
    /// One layout per bind group.
    pub layouts: Vec<wgpu::BindGroupLayout>,
    /// The pipeline (entry point `main`).
    pub pipeline: wgpu::ComputePipeline,
}

impl ComputeKernel {
    /// Validates, reflects and compiles `wgsl`; errors name the kernel.
    pub fn new(device: &wgpu::Device, name: &str, wgsl: &str) -> Result<Self> {
        let (_, reflection) = kernels::reflect(name, wgsl)?;
        let label = format!("shadowgraph.{name}");
        let (layouts, pipeline) = scoped(
            device,
            || {
                let module = created::shader_module(
                    device,
                    wgpu::ShaderModuleDescriptor {
                        label: Some(&label),
                        source: wgpu::ShaderSource::Wgsl(wgsl.into()),
                    },
                );
                let layouts: Vec<wgpu::BindGroupLayout> = (0..reflection.group_count())
                    .map(|g| {
                        created::bind_group_layout(
                            device,
                            &wgpu::BindGroupLayoutDescriptor {
                                label: Some(&label),
                                entries: &reflection.layout_entries(g),
                            },
                        )
                    })
                    .collect();
                let refs: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(Some).collect();
                let layout = created::pipeline_layout(
                    device,
                    &wgpu::PipelineLayoutDescriptor {
                        label: Some(&label),
                        bind_group_layouts: &refs,
                        immediate_size: 0,
                    },
                );
                let pipeline = created::compute_pipeline(
                    device,
                    &wgpu::ComputePipelineDescriptor {
                        label: Some(&label),
                        layout: Some(&layout),
                        module: &module,
                        entry_point: Some("main"),
                        compilation_options: Default::default(),
                        cache: None,
                    },
                );
                (layouts, pipeline)
            },
            |message| Error::Pipeline {
                kernel: name.to_string(),
                message,
            },
        )?;
        Ok(Self {
            name: name.to_string(),
            reflection,
            layouts,
            pipeline,
        })
    }

    /// Workgroups covering a `w × h` texel grid.
    pub fn groups_for(&self, w: u32, h: u32) -> [u32; 3] {
        let wg = self.reflection.workgroup_size.unwrap_or([1, 1, 1]);
        [w.div_ceil(wg[0]), h.div_ceil(wg[1]), 1]
    }
}

/// Pipelines created once per kernel (or generated variant) and reused.
#[derive(Default)]
pub struct KernelCache {
    kernels: HashMap<String, Arc<ComputeKernel>>,
}

impl KernelCache {
    /// The pipeline of `kernels/<name>.wgsl`, compiled on first use.
    pub fn get(&mut self, device: &wgpu::Device, name: &str) -> Result<Arc<ComputeKernel>> {
        self.get_generated(device, name, None)
    }

    /// The pipeline of `name` with the storage-texture bindings in `formats` re-declared with
    /// those formats (a kernel declares a default; a graph may bind another, e.g. f16 moments).
    pub fn get_specialized(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        formats: &[(String, wgpu::TextureFormat)],
    ) -> Result<Arc<ComputeKernel>> {
        let base = self.get(device, name)?;
        let mut changes = Vec::new();
        for (binding, format) in formats {
            if let Some(b) = base.reflection.binding(binding) {
                if let wgpu::BindingType::StorageTexture {
                    format: declared, ..
                } = b.ty
                {
                    if declared != *format {
                        same_kind(name, binding, declared, *format)?;
                        changes.push((
                            binding.as_str(),
                            wgsl_storage_format(declared)?,
                            wgsl_storage_format(*format)?,
                        ));
                    }
                }
            }
        }
        if changes.is_empty() {
            return Ok(base);
        }
        let key = format!("{name}@{changes:?}");
        if let Some(k) = self.kernels.get(&key) {
            return Ok(k.clone());
        }
        let mut wgsl = kernels::resolve(name, None)?;
        for (binding, from, to) in &changes {
            wgsl = retype_storage(&wgsl, binding, from, to).ok_or_else(|| Error::Kernel {
                kernel: name.to_string(),
                message: format!("cannot find the declaration of storage texture `{binding}`"),
            })?;
        }
        let k = Arc::new(ComputeKernel::new(device, name, &wgsl)?);
        self.kernels.insert(key, k.clone());
        Ok(k)
    }

    /// The pipeline of `name` with a `// #generated` block, keyed by the block's text.
    pub fn get_generated(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        generated: Option<&str>,
    ) -> Result<Arc<ComputeKernel>> {
        let key = generated_key(name, generated);
        if let Some(k) = self.kernels.get(&key) {
            return Ok(k.clone());
        }
        let wgsl = kernels::resolve(name, generated)?;
        let k = Arc::new(ComputeKernel::new(device, name, &wgsl)?);
        self.kernels.insert(key, k.clone());
        Ok(k)
    }

    /// The pipeline cached under `key`, compiled from the kernel `name` and the `// #generated`
    /// block `generated()` makes on a miss: a variant looked up by a key its caller derives
    /// from what the block depends on (the renderer's shading kernel,
    /// [`crate::technique::shade_key`]) instead of generating and hashing the block's text.
    pub fn get_keyed(
        &mut self,
        device: &wgpu::Device,
        key: &str,
        name: &str,
        generated: impl FnOnce() -> String,
    ) -> Result<Arc<ComputeKernel>> {
        if let Some(k) = self.kernels.get(key) {
            return Ok(k.clone());
        }
        let wgsl = kernels::resolve(name, Some(&generated()))?;
        let k = Arc::new(ComputeKernel::new(device, name, &wgsl)?);
        self.kernels.insert(key.to_string(), k.clone());
        Ok(k)
    }

    /// Compiles `wgsl` as the pipeline [`KernelCache::get_keyed`] returns for `key` from now
    /// on: a rewritten variant with the same bindings, e.g. the shading kernel with every
    /// texture fetch counted (`tests/cost.rs`).
    pub fn insert_keyed(
        &mut self,
        device: &wgpu::Device,
        key: &str,
        name: &str,
        wgsl: &str,
    ) -> Result<()> {
        let k = Arc::new(ComputeKernel::new(device, name, wgsl)?);
        self.kernels.insert(key.to_string(), k);
        Ok(())
    }

    /// Compiles `wgsl` as the pipeline [`KernelCache::get_generated`] returns for `name` and
    /// `generated` from now on: a rewritten variant of the kernel with the same bindings, e.g.
    /// the shading kernel with every texture fetch counted (`tests/cost.rs`).
    pub fn insert_generated(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        generated: Option<&str>,
        wgsl: &str,
    ) -> Result<()> {
        let key = generated_key(name, generated);
        let k = Arc::new(ComputeKernel::new(device, name, wgsl)?);
        self.kernels.insert(key, k);
        Ok(())
    }

    /// Number of pipelines created so far.
    pub fn len(&self) -> usize {
        self.kernels.len()
    }

    /// Whether no pipeline was created yet.
    pub fn is_empty(&self) -> bool {
        self.kernels.is_empty()
    }
}

/// The cache key of kernel `name` with the `// #generated` block `generated`.
fn generated_key(name: &str, generated: Option<&str>) -> String {
    match generated {
        Some(g) => format!("{name}\u{0}{g}"),
        None => name.to_string(),
    }
}

/// The error for a kernel without a bind group (a plan naming a kernel the executor cannot bind).
fn no_layout(kernel: &str) -> Error {
    Error::Pipeline {
        kernel: kernel.to_string(),
        message: "the kernel declares no bind group".into(),
    }
}

/// Refuses to re-declare storage texture `binding` of kernel `name` as a format of another
/// texel kind (float and integer texels are not interchangeable in the kernel's arithmetic).
fn same_kind(
    name: &str,
    binding: &str,
    declared: wgpu::TextureFormat,
    bound: wgpu::TextureFormat,
) -> Result<()> {
    let float = |f: wgpu::TextureFormat| {
        matches!(
            f.sample_type(None, None),
            Some(wgpu::TextureSampleType::Float { .. })
        )
    };
    if float(declared) == float(bound) {
        return Ok(());
    }
    Err(Error::Pipeline {
        kernel: name.to_string(),
        message: format!(
            "storage texture `{binding}` is {declared:?}; a {bound:?} texture cannot be bound to it"
        ),
    })
}

/// The WGSL name of a storage texel format.
pub fn wgsl_storage_format(f: wgpu::TextureFormat) -> Result<&'static str> {
    use wgpu::TextureFormat as T;
    Ok(match f {
        T::R32Float => "r32float",
        T::Rg32Float => "rg32float",
        T::Rgba32Float => "rgba32float",
        T::Rgba16Float => "rgba16float",
        T::Rgba16Unorm => "rgba16unorm",
        T::Rgba8Unorm => "rgba8unorm",
        T::R32Uint => "r32uint",
        T::Rg32Uint => "rg32uint",
        T::Rgba32Uint => "rgba32uint",
        other => {
            return Err(Error::Invalid(format!(
                "{other:?} is not a storage format shadowgraph uses"
            )));
        }
    })
}

/// `wgsl` with the storage texture `binding` declared as `to` instead of `from`.
fn retype_storage(wgsl: &str, binding: &str, from: &str, to: &str) -> Option<String> {
    let decl = format!("var {binding}: texture_storage_2d<{from},");
    let at = wgsl.find(&decl)?;
    let new = format!("var {binding}: texture_storage_2d<{to},");
    Some(format!("{}{new}{}", &wgsl[..at], &wgsl[at + decl.len()..]))
}

/// Textures kept across runs, keyed by shape; a plan takes the ones it needs in order.
#[derive(Default)]
pub struct TexturePool {
    free: HashMap<Slot, Vec<wgpu::Texture>>,
}

impl TexturePool {
    fn take(&mut self, device: &wgpu::Device, slot: &Slot) -> wgpu::Texture {
        if let Some(t) = self.free.get_mut(slot).and_then(Vec::pop) {
            return t;
        }
        created::texture(
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
                format: slot.format,
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
    /// One counter per step that a kernel may increment (e.g. non-finite texels replaced).
    pub stats: wgpu::Buffer,
    stats_readback: wgpu::Buffer,
    /// Step names, in the order of the counters.
    pub steps: Vec<String>,
}

/// Stride between per-step counters: storage binding offsets must be 256-byte aligned.
const STATS_STRIDE: u64 = 256;

impl Outputs {
    /// A default view of resource `name`.
    pub fn view(&self, name: &str) -> Result<wgpu::TextureView> {
        self.textures
            .get(name)
            .map(|t| created::view(t, &Default::default()))
            .ok_or_else(|| Error::Invalid(format!("the plan has no resource `{name}`")))
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

/// Runs plans: owns pipelines, pooled textures and what the last plan's run needs; borrows
/// everything else.
#[derive(Default)]
pub struct Executor {
    /// Compiled kernels.
    pub kernels: KernelCache,
    pool: TexturePool,
    in_use: Vec<(Slot, wgpu::Texture)>,
    prepared: Option<Prepared>,
}

/// What a plan's run needs besides its passes, made once and reused while the plan and the
/// imported textures stay the same.
struct Prepared {
    plan: Plan,
    /// The imported textures bound, by resource name.
    imports: Vec<(String, wgpu::Texture)>,
    outputs: Outputs,
    /// Every step's parameters, and per step its `(offset, size)` there.
    params: (wgpu::Buffer, Vec<(u64, u64)>),
    /// Per step: its pipeline and dispatches.
    steps: Vec<PreparedStep>,
}

/// One node's pipeline and its dispatches in one pass, each a bind group and workgroups (a
/// mip chain: one per group of levels).
struct PreparedStep {
    kernel: Arc<ComputeKernel>,
    dispatches: Vec<(wgpu::BindGroup, [u32; 3])>,
}

impl Executor {
    /// An executor with empty caches.
    pub fn new() -> Self {
        Self::default()
    }

    /// Compiles every kernel `plan` uses (also done lazily by [`Executor::record`]).
    pub fn prepare(&mut self, device: &wgpu::Device, plan: &Plan) -> Result<()> {
        for step in &plan.steps {
            let base = self.kernels.get(device, step.node.kernel.name())?;
            let formats: Vec<(String, wgpu::TextureFormat)> = bound_outputs(&base, &step.node)
                .into_iter()
                .filter_map(|(slot, r)| plan.resource(&r).map(|p| (slot, p.resource.format)))
                .collect();
            self.kernels
                .get_specialized(device, step.node.kernel.name(), &formats)?;
        }
        Ok(())
    }

    /// Textures held by the pool (constant across runs of the same plan).
    pub fn texture_count(&self) -> usize {
        self.pool.texture_count() + self.in_use.len()
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
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<Outputs> {
        // A plan's fields are public: check what the indexing below relies on first.
        plan.check()?;
        let same_plan = self.prepared.as_ref().is_some_and(|p| p.plan == *plan);
        let prepared = match self.prepared.take() {
            Some(p) if same_plan && p.imports_match(imports) => p,
            // New imported textures (a host's depth map): the nodes reading them are bound anew.
            Some(p) if same_plan => self.rebind_imports(device, p, imports)?,
            _ => self.prepare_run(device, plan, imports)?,
        };
        let result = self.encode(encoder, &prepared, timer.as_deref_mut());
        let outputs = prepared.outputs.clone();
        self.prepared = Some(prepared);
        result?;
        // The last node ends here, not at whatever the caller records next.
        if let Some(t) = timer {
            t.end(encoder);
        }
        Ok(outputs)
    }

    /// Records the passes of a prepared plan.
    fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &Prepared,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        encoder.clear_buffer(&prepared.outputs.stats, 0, None);
        for (step, bound) in prepared.plan.steps.iter().zip(&prepared.steps) {
            let node = &step.node;
            if let Some(t) = timer.as_deref_mut() {
                t.begin(encoder, &node.name);
            }
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(&node.name),
                timestamp_writes: None,
            });
            pass.set_pipeline(&bound.kernel.pipeline);
            for (bind_group, g) in &bound.dispatches {
                pass.set_bind_group(0, bind_group, &[]);
                pass.dispatch_workgroups(g[0], g[1], g[2]);
            }
        }
        Ok(())
    }

    /// Takes `plan`'s textures from the pool and makes its buffers and bind groups.
    fn prepare_run(
        &mut self,
        device: &wgpu::Device,
        plan: &Plan,
        imports: &HashMap<String, wgpu::Texture>,
    ) -> Result<Prepared> {
        // Textures of the previous run go back to the pool, then each slot takes one.
        for (slot, t) in self.in_use.drain(..) {
            self.pool.free.entry(slot).or_default().push(t);
        }
        let slot_textures: Vec<wgpu::Texture> = plan
            .slots
            .iter()
            .map(|s| self.pool.take(device, s))
            .collect();
        self.in_use = plan
            .slots
            .iter()
            .cloned()
            .zip(slot_textures.iter().cloned())
            .collect();
        let textures = plan_textures(plan, &slot_textures, imports)?;
        let steps = plan.steps.len().max(1) as u64;
        let counters = |label, usage| {
            created::buffer(
                device,
                &wgpu::BufferDescriptor {
                    label: Some(label),
                    size: steps * STATS_STRIDE,
                    usage,
                    mapped_at_creation: false,
                },
            )
        };
        let outputs = Outputs {
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
        };
        let (params, params_at) = params_buffer(device, plan);
        let mut bound = Vec::new();
        for (si, step) in plan.steps.iter().enumerate() {
            bound.push(self.bind_step(device, &step.node, &outputs, si, &params, params_at[si])?);
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
            outputs,
            params: (params, params_at),
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
    ) -> Result<Prepared> {
        let slots: Vec<wgpu::Texture> = self.in_use.iter().map(|(_, t)| t.clone()).collect();
        prepared.outputs.textures = plan_textures(&prepared.plan, &slots, imports)?;
        for (name, t) in &mut prepared.imports {
            if let Some(new) = imports.get(name) {
                *t = new.clone();
            }
        }
        let plan = prepared.plan.clone();
        for (si, step) in plan.steps.iter().enumerate() {
            let reads_import = step
                .node
                .inputs
                .iter()
                .any(|(_, r)| prepared.imports.iter().any(|(name, _)| name == r));
            if reads_import {
                let (params, at) = &prepared.params;
                prepared.steps[si] =
                    self.bind_step(device, &step.node, &prepared.outputs, si, params, at[si])?;
            }
        }
        Ok(prepared)
    }

    /// A node's pipeline and dispatches (a mip chain's by [`Executor::bind_mip_chain`]);
    /// `params_at` is its slice of `params`.
    fn bind_step(
        &mut self,
        device: &wgpu::Device,
        node: &crate::graph::Node,
        outputs: &Outputs,
        si: usize,
        params: &wgpu::Buffer,
        (offset, size): (u64, u64),
    ) -> Result<PreparedStep> {
        if node.dispatch == Dispatch::MipChain {
            return self.bind_mip_chain(device, node, &outputs.textures);
        }
        let textures = &outputs.textures;
        let base = self.kernels.get(device, node.kernel.name())?;
        let node_outputs = bound_outputs(&base, node);
        let formats: Vec<(String, wgpu::TextureFormat)> = node_outputs
            .iter()
            .filter_map(|(slot, r)| textures.get(r).map(|t| (slot.clone(), t.format())))
            .collect();
        let kernel = self
            .kernels
            .get_specialized(device, node.kernel.name(), &formats)?;
        let mut views: Vec<(u32, wgpu::TextureView)> = Vec::new();
        for b in kernel.reflection.bindings.iter().filter(|b| b.group == 0) {
            let bound = node
                .inputs
                .iter()
                .chain(&node_outputs)
                .find(|(slot, _)| *slot == b.name);
            if let Some((_, res)) = bound {
                views.push((b.binding, aspect_view(&textures[res])));
            } else if b.name != "params" && b.name != "stats" {
                return Err(Error::Pipeline {
                    kernel: node.kernel.to_string(),
                    message: format!("node `{}` binds nothing to `{}`", node.name, b.name),
                });
            }
        }
        let mut entries: Vec<wgpu::BindGroupEntry> = views
            .iter()
            .map(|(binding, view)| wgpu::BindGroupEntry {
                binding: *binding,
                resource: wgpu::BindingResource::TextureView(view),
            })
            .collect();
        if let Some(b) = kernel.reflection.binding("params") {
            entries.push(buffer_entry(
                b.binding,
                params,
                offset,
                size.div_ceil(16) * 16,
            ));
        }
        if let Some(b) = kernel.reflection.binding("stats") {
            entries.push(buffer_entry(
                b.binding,
                &outputs.stats,
                si as u64 * STATS_STRIDE,
                4,
            ));
        }
        let layout = kernel
            .layouts
            .first()
            .ok_or_else(|| no_layout(&kernel.name))?;
        let bind_group = scoped(
            device,
            || {
                created::bind_group(
                    device,
                    &wgpu::BindGroupDescriptor {
                        label: Some(&node.name),
                        layout,
                        entries: &entries,
                    },
                )
            },
            |message| Error::Pipeline {
                kernel: node.kernel.to_string(),
                message: format!("binding node `{}`: {message}", node.name),
            },
        )?;
        let wg = kernel.reflection.workgroup_size.unwrap_or([1, 1, 1]);
        let size = |r: &str| textures.get(r).map(|t| (t.width(), t.height()));
        let groups = node.dispatch.groups(size, wg).ok_or_else(|| {
            Error::Invalid(format!(
                "node `{}` dispatches over a resource that is not in the plan",
                node.name
            ))
        })?;
        Ok(PreparedStep {
            kernel,
            dispatches: vec![(bind_group, groups)],
        })
    }

    /// Binds a [`Dispatch::MipChain`] node: one compute pass with the dispatches of
    /// [`crate::filter::mip_dispatches`] (`kernels/mips.wgsl` or `mips_log.wgsl`, up to six
    /// levels each), each reading one level (the `src` input for the first, which also stores
    /// it as level 0) through a one-level view and writing the levels after it through
    /// one-level views.
    fn bind_mip_chain(
        &mut self,
        device: &wgpu::Device,
        node: &crate::graph::Node,
        textures: &HashMap<String, wgpu::Texture>,
    ) -> Result<PreparedStep> {
        let mip = MipNode::new(node, textures)?;
        let formats: Vec<(String, wgpu::TextureFormat)> = (0..=MIP_LEVELS_PER_DISPATCH)
            .map(|k| (format!("dst{k}"), mip.dst.format()))
            .collect();
        let kernel = self
            .kernels
            .get_specialized(device, node.kernel.name(), &formats)?;
        let dispatches = mip_dispatches(mip.dst.width(), mip.dst.height());
        let align = u64::from(device.limits().min_uniform_buffer_offset_alignment).max(32);
        let params = mip.params_buffer(device, &dispatches, align)?;
        let mut bound = Vec::new();
        for (k, &(first, count)) in dispatches.iter().enumerate() {
            let bg = mip.bind_group(device, &kernel, &params, k as u64 * align, first, count)?;
            let groups =
                crate::filter::mip_dispatch_groups(mip.dst.width(), mip.dst.height(), first);
            bound.push((bg, groups));
        }
        Ok(PreparedStep {
            kernel,
            dispatches: bound,
        })
    }
}

impl Prepared {
    /// Whether `imports` holds the same texture for every import this run bound.
    fn imports_match(&self, imports: &HashMap<String, wgpu::Texture>) -> bool {
        self.imports
            .iter()
            .all(|(name, t)| imports.get(name) == Some(t))
    }
}

/// The texture of every planned resource: its slot's, or the caller's for an import; sizes
/// checked against the plan.
fn plan_textures(
    plan: &Plan,
    slot_textures: &[wgpu::Texture],
    imports: &HashMap<String, wgpu::Texture>,
) -> Result<HashMap<String, wgpu::Texture>> {
    let mut textures = HashMap::new();
    for r in &plan.resources {
        let t = match r.slot {
            Some(s) => slot_textures[s].clone(),
            None => imports.get(&r.resource.name).cloned().ok_or_else(|| {
                Error::Invalid(format!(
                    "imported resource `{}` was not provided",
                    r.resource.name
                ))
            })?,
        };
        if (t.width(), t.height()) != (r.width, r.height) {
            return Err(Error::Invalid(format!(
                "`{}` is {}x{}, the plan expects {}x{}",
                r.resource.name,
                t.width(),
                t.height(),
                r.width,
                r.height
            )));
        }
        textures.insert(r.resource.name.clone(), t);
    }
    Ok(textures)
}

/// One uniform buffer of every step's parameters, each at an offset aligned for binding, and
/// per step its `(offset, size)`.
fn params_buffer(device: &wgpu::Device, plan: &Plan) -> (wgpu::Buffer, Vec<(u64, u64)>) {
    let align = u64::from(device.limits().min_uniform_buffer_offset_alignment).max(16);
    let mut bytes = Vec::new();
    let mut at = Vec::new();
    for step in &plan.steps {
        let offset = (bytes.len() as u64).div_ceil(align) * align;
        bytes.resize(offset as usize, 0);
        at.push((offset, step.node.params.len().max(16) as u64));
        bytes.extend_from_slice(&step.node.params);
    }
    bytes.resize(bytes.len().max(16).div_ceil(16) * 16 + 16, 0);
    let buffer = created::buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("shadowgraph.params"),
            contents: &bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    (buffer, at)
}

/// A bind group entry of `size` bytes of `buffer` from `offset`.
fn buffer_entry(
    binding: u32,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset,
            size: wgpu::BufferSize::new(size),
        }),
    }
}

/// A view of all of `t` (its depth aspect for a depth texture).
fn aspect_view(t: &wgpu::Texture) -> wgpu::TextureView {
    created::view(
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

/// `node`'s outputs as `kernel` binds them: a kernel may declare more write-only storage
/// outputs than a node writes (`kernels/csm.wgsl` writes up to four maps from one read of the
/// depth); each one the node leaves unbound repeats the node's last output, which the kernel
/// does not store to through it (as a mip chain's unused levels do), and which the cost model
/// does not count.
fn bound_outputs(kernel: &ComputeKernel, node: &crate::graph::Node) -> Vec<(String, String)> {
    let mut outputs = node.outputs.clone();
    let Some((_, last)) = node.outputs.last().cloned() else {
        return outputs;
    };
    for b in kernel.reflection.bindings.iter().filter(|b| b.group == 0) {
        let write_only = matches!(
            b.ty,
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                ..
            }
        );
        let bound = node
            .inputs
            .iter()
            .chain(&node.outputs)
            .any(|(s, _)| *s == b.name);
        if write_only && !bound {
            outputs.push((b.name.clone(), last.clone()));
        }
    }
    outputs
}

/// A mip-chain node's textures and the pieces of its dispatches.
struct MipNode<'a> {
    node: &'a crate::graph::Node,
    src: wgpu::Texture,
    dst: wgpu::Texture,
}

impl<'a> MipNode<'a> {
    fn new(
        node: &'a crate::graph::Node,
        textures: &HashMap<String, wgpu::Texture>,
    ) -> Result<Self> {
        let find = |list: &[(String, String)], slot: &str| {
            list.iter()
                .find(|(s, _)| s == slot)
                .and_then(|(_, r)| textures.get(r).cloned())
                .ok_or_else(|| Self::error(node, format!("binds nothing to `{slot}`")))
        };
        Ok(Self {
            node,
            src: find(&node.inputs, "src")?,
            dst: find(&node.outputs, "dst")?,
        })
    }

    fn error(node: &crate::graph::Node, message: String) -> Error {
        Error::Pipeline {
            kernel: node.kernel.to_string(),
            message: format!("node `{}`: {message}", node.name),
        }
    }

    /// One `MipParams` per dispatch, `align` bytes apart.
    fn params_buffer(
        &self,
        device: &wgpu::Device,
        dispatches: &[(u32, u32)],
        align: u64,
    ) -> Result<wgpu::Buffer> {
        let size = std::mem::size_of::<MipParams>();
        let base: MipParams = self
            .node
            .params
            .get(..size)
            .and_then(|b| bytemuck::try_pod_read_unaligned(b).ok())
            .ok_or_else(|| Self::error(self.node, "params are not a MipParams".into()))?;
        let (w, h) = (self.dst.width(), self.dst.height());
        let odd = |n: u32| n > 1 && n % 2 == 1;
        let mut bytes = vec![0u8; dispatches.len() * align as usize];
        for (k, &(first, count)) in dispatches.iter().enumerate() {
            let p = MipParams {
                base: [w, h],
                first,
                count,
                copy: u32::from(first == 0),
                general: u32::from(odd((w >> first).max(1)) || odd((h >> first).max(1))),
                ..base
            };
            let at = k * align as usize;
            bytes[at..at + size].copy_from_slice(bytemuck::bytes_of(&p));
        }
        Ok(created::buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some(&self.node.name),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            },
        ))
    }

    /// The bind group of the dispatch reading level `first` and writing `count` levels:
    /// `dst0` is level 0 in the first dispatch; unused bindings repeat the last level written
    /// (the kernel stores only levels 0 … count).
    fn bind_group(
        &self,
        device: &wgpu::Device,
        kernel: &ComputeKernel,
        params: &wgpu::Buffer,
        offset: u64,
        first: u32,
        count: u32,
    ) -> Result<wgpu::BindGroup> {
        let level_view = |t: &wgpu::Texture, level: u32| {
            created::view(
                t,
                &wgpu::TextureViewDescriptor {
                    base_mip_level: level,
                    mip_level_count: Some(1),
                    ..Default::default()
                },
            )
        };
        let binding = |name: &str| {
            kernel
                .reflection
                .binding(name)
                .map(|b| b.binding)
                .ok_or_else(|| Self::error(self.node, format!("kernel has no binding `{name}`")))
        };
        let src_view = match first {
            0 => level_view(&self.src, 0),
            l => level_view(&self.dst, l),
        };
        let views: Vec<(String, wgpu::TextureView)> = (0..=MIP_LEVELS_PER_DISPATCH)
            .map(|j| {
                let level = match j {
                    0 if first == 0 => 0,
                    j if (1..=count).contains(&j) => first + j,
                    _ => first + count,
                };
                (format!("dst{j}"), level_view(&self.dst, level))
            })
            .collect();
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: binding("src")?,
            resource: wgpu::BindingResource::TextureView(&src_view),
        }];
        for (name, view) in &views {
            entries.push(wgpu::BindGroupEntry {
                binding: binding(name)?,
                resource: wgpu::BindingResource::TextureView(view),
            });
        }
        entries.push(wgpu::BindGroupEntry {
            binding: binding("params")?,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: params,
                offset,
                size: wgpu::BufferSize::new(std::mem::size_of::<MipParams>() as u64),
            }),
        });
        scoped(
            device,
            || {
                created::bind_group(
                    device,
                    &wgpu::BindGroupDescriptor {
                        label: Some(&self.node.name),
                        layout: &kernel.layouts[0],
                        entries: &entries,
                    },
                )
            },
            |message| Self::error(self.node, format!("binding level {first}: {message}")),
        )
    }
}
