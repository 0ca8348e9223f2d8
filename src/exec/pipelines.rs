//! Pipelines: a kernel compiled once per kernel (or generated or re-typed variant), its bind
//! group layouts reflected from its WGSL, cached by [`KernelCache`]. The layout a kernel
//! compiles in ([`KernelLayout`], [`WorkgroupInit`]) is `pipelines/layout.rs`; the WGSL
//! re-declared for the textures a node binds ([`specialized_source`]), `pipelines/specialize.rs`.

mod layout;
mod specialize;

use std::collections::HashMap;
use std::sync::Arc;

pub use self::layout::{
    GPU_LAYOUT_CONSTANT, KERNEL_LAYOUT_ENV, KernelLayout, REDESIGN_CONSTANT, REDESIGNED_KERNELS,
    REDESIGNED_MODULES, SHADER_CHECKS_ENV, ShaderChecks, WorkgroupInit,
};
pub(crate) use self::specialize::rewrites_to_buffer;
use self::specialize::{apply, apply_changes, changes};
pub use self::specialize::{specialized_buffer_source, specialized_source, wgsl_storage_format};
use super::node_constants::NodeOverrides;
use crate::error::{Error, Result};
use crate::gpu::scoped;
use crate::gpu_objects;
use crate::kernels::{self, Reflection};

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
    /// The layout it was compiled in.
    pub layout: KernelLayout,
}

impl ComputeKernel {
    /// Validates, reflects and compiles `wgsl` in the device's [`KernelLayout`], its workgroup
    /// memory zeroed ([`WorkgroupInit::Zeroed`]: any WGSL may rely on it); errors name the
    /// kernel.
    pub fn new(device: &wgpu::Device, name: &str, wgsl: &str) -> Result<Self> {
        Self::with_layout(device, name, wgsl, KernelLayout::for_device(device)?)
    }

    /// [`ComputeKernel::new`] in `layout` (where the kernel has two).
    pub fn with_layout(
        device: &wgpu::Device,
        name: &str,
        wgsl: &str,
        layout: KernelLayout,
    ) -> Result<Self> {
        Self::with_options(device, name, wgsl, layout, WorkgroupInit::Zeroed)
    }

    /// [`ComputeKernel::with_layout`], its workgroup memory started as `init` says.
    pub fn with_options(
        device: &wgpu::Device,
        name: &str,
        wgsl: &str,
        layout: KernelLayout,
        init: WorkgroupInit,
    ) -> Result<Self> {
        Self::with_constants(device, name, wgsl, layout, init, &[])
    }

    /// [`ComputeKernel::with_options`] with these pipeline constants set too (a node's
    /// `// #override` values, `exec::KernelCache`), its module checked ([`ShaderChecks::On`]).
    pub fn with_constants(
        device: &wgpu::Device,
        name: &str,
        wgsl: &str,
        layout: KernelLayout,
        init: WorkgroupInit,
        overrides: &[(String, f64)],
    ) -> Result<Self> {
        let kernel = (name, wgsl);
        let compile = (layout, init, ShaderChecks::On);
        Self::with_checks(device, kernel, compile, overrides)
    }

    /// [`ComputeKernel::with_constants`] of kernel `(name, wgsl)` in `(layout, init, checks)`:
    /// [`ShaderChecks::Off`] only for the kernels of `kernels/` (see it).
    pub fn with_checks(
        device: &wgpu::Device,
        (name, wgsl): (&str, &str),
        (layout, init, checks): (KernelLayout, WorkgroupInit, ShaderChecks),
        overrides: &[(String, f64)],
    ) -> Result<Self> {
        let (module, reflection) = kernels::reflect(name, wgsl)?;
        let mut constants: Vec<(&str, f64)> =
            overrides.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        for (name, value) in [
            (GPU_LAYOUT_CONSTANT, layout.is_gpu()),
            (REDESIGN_CONSTANT, layout.is_redesign()),
        ] {
            if module
                .overrides
                .iter()
                .any(|(_, o)| o.name.as_deref() == Some(name))
            {
                constants.push((name, f64::from(u8::from(value))));
            }
        }
        let constants: &[(&str, f64)] = &constants;
        let label = format!("shadowgraph.{name}");
        let (layouts, pipeline) = scoped(
            device,
            || {
                let desc = wgpu::ShaderModuleDescriptor {
                    label: Some(&label),
                    source: wgpu::ShaderSource::Wgsl(wgsl.into()),
                };
                let module = match checks {
                    ShaderChecks::On => gpu_objects::shader_module(device, desc),
                    ShaderChecks::Off => gpu_objects::shader_module_unchecked(device, desc),
                };
                let layouts: Vec<wgpu::BindGroupLayout> = (0..reflection.group_count())
                    .map(|g| {
                        gpu_objects::bind_group_layout(
                            device,
                            &wgpu::BindGroupLayoutDescriptor {
                                label: Some(&label),
                                entries: &reflection.layout_entries(g),
                            },
                        )
                    })
                    .collect();
                let refs: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(Some).collect();
                let layout = gpu_objects::pipeline_layout(
                    device,
                    &wgpu::PipelineLayoutDescriptor {
                        label: Some(&label),
                        bind_group_layouts: &refs,
                        immediate_size: 0,
                    },
                );
                let pipeline = gpu_objects::compute_pipeline(
                    device,
                    &wgpu::ComputePipelineDescriptor {
                        label: Some(&label),
                        layout: Some(&layout),
                        module: &module,
                        entry_point: Some("main"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants,
                            zero_initialize_workgroup_memory: init == WorkgroupInit::Zeroed,
                        },
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
            reflection: if layout.is_redesign() {
                reflection.in_redesign()
            } else {
                reflection.in_layout(layout.is_gpu())
            },
            layouts,
            pipeline,
            layout,
        })
    }

    /// Workgroups covering a `w × h` texel grid ([`crate::kernels::Reflection::groups_for`]).
    pub fn groups_for(&self, w: u32, h: u32) -> [u32; 3] {
        self.reflection.groups_for(w, h)
    }
}

/// Pipelines created once per kernel (or generated variant) and reused.
#[derive(Default)]
pub struct KernelCache {
    kernels: HashMap<String, Arc<ComputeKernel>>,
    /// The layout kernels compile in; `None`: [`KernelLayout::for_device`].
    layout: Option<KernelLayout>,
    /// Kernels compiled from these texts instead of the embedded ones (and
    /// [`kernels::KERNEL_DIR_ENV`]'s), where they name them.
    replaced: Option<Arc<kernels::Replacements>>,
    /// Zero every kernel's workgroup memory first ([`WorkgroupInit::Zeroed`]); `false`, the
    /// default: [`WorkgroupInit::AsLeft`].
    zeroed: bool,
    /// How modules are created; `None`: [`ShaderChecks::from_env`].
    checks: Option<ShaderChecks>,
    /// Each kernel's `// #override` declarations, read on first use.
    node_overrides: HashMap<String, Arc<NodeOverrides>>,
}

impl KernelCache {
    /// Compiles every kernel from now on with `replaced` in place of the files it names (the
    /// pipelines made so far are dropped): kernel variants side by side in one process
    /// (`shadowgraph bench --kernel-dirs`).
    pub fn set_replacements(&mut self, replaced: Arc<kernels::Replacements>) {
        self.replaced = Some(replaced);
        self.kernels.clear();
        self.node_overrides.clear();
    }

    /// Compiles every kernel from now on in `layout` whatever the device (the pipelines made
    /// so far are dropped): both layouts tested on one device.
    pub fn set_layout(&mut self, layout: KernelLayout) {
        self.layout = Some(layout);
        self.kernels.clear();
    }

    /// Compiles every kernel from now on with its workgroup memory zeroed first
    /// ([`WorkgroupInit::Zeroed`], wgpu's default; the pipelines made so far are dropped): what
    /// the kernels' [`WorkgroupInit::AsLeft`] saves, timed on one device.
    pub fn set_zeroed_workgroup_memory(&mut self) {
        self.zeroed = true;
        self.kernels.clear();
    }

    /// Creates every kernel's module from now on as `checks` says, whatever
    /// [`SHADER_CHECKS_ENV`] (the pipelines made so far are dropped): the runtime checks' cost
    /// timed on one device.
    pub fn set_shader_checks(&mut self, checks: ShaderChecks) {
        self.checks = Some(checks);
        self.kernels.clear();
    }

    fn compile(&self, device: &wgpu::Device, name: &str, wgsl: &str) -> Result<ComputeKernel> {
        self.compile_with(device, name, wgsl, &[])
    }

    fn compile_with(
        &self,
        device: &wgpu::Device,
        name: &str,
        wgsl: &str,
        overrides: &[(String, f64)],
    ) -> Result<ComputeKernel> {
        let layout = self.layout_for(device)?;
        let init = if self.zeroed {
            WorkgroupInit::Zeroed
        } else {
            WorkgroupInit::AsLeft
        };
        let checks = match self.checks {
            Some(checks) => checks,
            None => ShaderChecks::from_env()?,
        };
        ComputeKernel::with_checks(device, (name, wgsl), (layout, init, checks), overrides)
    }

    /// The layout kernels compile in on `device`.
    pub(crate) fn layout_for(&self, device: &wgpu::Device) -> Result<KernelLayout> {
        match self.layout {
            Some(layout) => Ok(layout),
            None => KernelLayout::for_device(device),
        }
    }

    /// The texts kernels resolve with on `device`: [`KernelCache::set_replacements`]'s, and the
    /// redesigned modules its layout and features take ([`KernelLayout::module_sources`]) where
    /// those do not replace the shipped module themselves.
    pub(crate) fn sources_for(
        &self,
        device: &wgpu::Device,
    ) -> Result<Option<Arc<kernels::Replacements>>> {
        let modules = self.layout_for(device)?.module_sources(device.features());
        if modules.is_empty() {
            return Ok(self.replaced.clone());
        }
        let mut all = self.replaced.as_deref().cloned().unwrap_or_default();
        for (shipped, redesign) in modules {
            if !all.contains_key(shipped) {
                let text = kernels::source_in(redesign, self.replaced.as_deref())?;
                all.insert(shipped.to_string(), text.to_string());
            }
        }
        Ok(Some(Arc::new(all)))
    }

    /// The pipeline constants a node of kernel `name` named `node` with parameters `params`
    /// sets (the kernel's `// #override` declarations; none for most kernels).
    pub fn node_constants(
        &mut self,
        name: &str,
        node: &str,
        params: &[u8],
    ) -> Result<Vec<(String, f64)>> {
        let decls = match self.node_overrides.get(name) {
            Some(d) => d.clone(),
            None => {
                let wgsl = kernels::resolve_in(name, None, self.replaced.as_deref())?;
                let d = Arc::new(NodeOverrides::new(name, &wgsl)?);
                self.node_overrides.insert(name.to_string(), d.clone());
                d
            }
        };
        if decls.is_empty() {
            return Ok(Vec::new());
        }
        decls.values(name, node, params)
    }

    /// The pipeline of `kernels/<name>.wgsl`, compiled on first use.
    pub fn get(&mut self, device: &wgpu::Device, name: &str) -> Result<Arc<ComputeKernel>> {
        self.get_generated(device, name, None)
    }

    /// The pipeline of `name` with the texture bindings in `formats` re-declared for the
    /// texture formats bound to them (a kernel declares a default; a graph may bind another,
    /// e.g. f16 moments): a storage texture of another float format is re-typed; a float
    /// storage texture or float texture bound to an `r32uint` texture holds a
    /// [`crate::graph::PACKED_F16X2`] representation and is stored packed and read unpacked
    /// (`exec::packed`).
    pub fn get_specialized(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        formats: &[(String, wgpu::TextureFormat)],
    ) -> Result<Arc<ComputeKernel>> {
        self.get_for_node(device, name, formats, &[], &[])
    }

    /// [`KernelCache::get_specialized`] with the bindings of `buffers` bound to storage buffers
    /// of maps of `[width, height]` texels (`exec::buffers`) and the pipeline constants
    /// `overrides` set (a node's, [`KernelCache::node_constants`]): one pipeline for each set.
    pub fn get_for_node(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        formats: &[(String, wgpu::TextureFormat)],
        buffers: &[(String, [u32; 2])],
        overrides: &[(String, f64)],
    ) -> Result<Arc<ComputeKernel>> {
        let base = self.get(device, name)?;
        let changes = changes(name, &base.reflection, formats, buffers)?;
        if changes.is_empty() && overrides.is_empty() {
            return Ok(base);
        }
        let key = format!("{name}@{changes:?}#{overrides:?}");
        if let Some(k) = self.kernels.get(&key) {
            return Ok(k.clone());
        }
        // The file `base` compiled (a redesign's own in `KernelLayout::Redesign`).
        let wgsl = apply(&base.name, &changes, self.sources_for(device)?.as_deref())?;
        let k = Arc::new(self.compile_with(device, &base.name, &wgsl, overrides)?);
        self.kernels.insert(key, k.clone());
        Ok(k)
    }

    /// The pipeline of `name` with a `// #generated` block, keyed by the block's text; in
    /// [`KernelLayout::Redesign`] compiled from the redesign's file where it has its own
    /// ([`KernelLayout::kernel_source`]).
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
        let layout = self.layout_for(device)?;
        let source = layout.kernel_source(name);
        let wgsl = kernels::resolve_in(source, generated, self.sources_for(device)?.as_deref())?;
        let k = Arc::new(self.compile(device, source, &wgsl)?);
        self.kernels.insert(key, k.clone());
        Ok(k)
    }

    /// [`KernelCache::get_keyed`] with the bindings of `buffers` bound to storage buffers of
    /// maps of `[width, height]` texels of their formats in `formats` (`exec::buffers`: the
    /// renderer's shading pass over tables held in buffers), cached under `key` and the
    /// buffers; [`KernelCache::get_keyed`] itself where `buffers` is empty.
    pub fn get_keyed_buffers(
        &mut self,
        device: &wgpu::Device,
        (key, name): (&str, &str),
        generated: impl FnOnce() -> String,
        formats: &[(String, wgpu::TextureFormat)],
        buffers: &[(String, [u32; 2])],
    ) -> Result<Arc<ComputeKernel>> {
        if buffers.is_empty() {
            return self.get_keyed(device, key, name, generated);
        }
        let key = format!("{key}@{buffers:?}");
        if let Some(k) = self.kernels.get(&key) {
            return Ok(k.clone());
        }
        let wgsl = kernels::resolve_in(name, Some(&generated()), self.replaced.as_deref())?;
        let (_, reflection) = kernels::reflect(name, &wgsl)?;
        let bound: Vec<(String, wgpu::TextureFormat)> = formats
            .iter()
            .filter(|(b, _)| buffers.iter().any(|(n, _)| n == b))
            .cloned()
            .collect();
        let changes = changes(name, &reflection, &bound, buffers)?;
        let wgsl = apply_changes(name, wgsl, &changes)?;
        let k = Arc::new(self.compile(device, name, &wgsl)?);
        self.kernels.insert(key, k.clone());
        Ok(k)
    }

    /// The pipeline cached under `key`, compiled from the kernel `name` and the `// #generated`
    /// block `generated()` makes on a miss: a variant looked up by a key its caller derives
    /// from what the block depends on (the renderer's shading kernel, keyed by
    /// `technique::shade_key`) instead of generating and hashing the block's text.
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
        let wgsl = kernels::resolve_in(name, Some(&generated()), self.replaced.as_deref())?;
        let k = Arc::new(self.compile(device, name, &wgsl)?);
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
        let k = Arc::new(self.compile(device, name, wgsl)?);
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
        let k = Arc::new(self.compile(device, name, wgsl)?);
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
pub(super) fn no_layout(kernel: &str) -> Error {
    Error::Pipeline {
        kernel: kernel.to_string(),
        message: "the kernel declares no bind group".into(),
    }
}
