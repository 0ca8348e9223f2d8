//! Pipelines: a kernel compiled once per kernel (or generated or re-typed variant), its bind
//! group layouts reflected from its WGSL, cached by [`KernelCache`].

use std::collections::HashMap;
use std::sync::Arc;

use super::node_constants::NodeOverrides;
use crate::created;
use crate::error::{Error, Result};
use crate::gpu::scoped;
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

/// The environment variable that picks [`KernelLayout`] for every device: `gpu` or `cpu`
/// (unset: by the device's type). A/B of the two layouts on one machine.
pub const KERNEL_LAYOUT_ENV: &str = "SHADOWGRAPH_KERNEL_LAYOUT";

pub use crate::kernels::GPU_LAYOUT_CONSTANT;

/// Which of its two variants a kernel that has two compiles (`override GPU_LAYOUT: bool`): today
/// the summed-area tables' pass 3 (`kernels/shared/sat_tile*.wgsl`), whose second sweep over an
/// invocation's sub-block loads and encodes its texels again on a GPU (from its texture cache:
/// 7–13% faster on an H200 than keeping them) and reads the first sweep's encoded texels kept in
/// private memory on a CPU driver (1.1–1.2× faster on llvmpipe); both give the same tables bit
/// for bit (`tests/sat.rs`, `tests/csm_sat.rs`). And the encodings fused into the blur
/// (`kernels/shared/encode_blur.wgsl`): a tile blurred in workgroup memory by 256 invocations on
/// a GPU, walked in strips by 8 on a CPU driver (2–3× less CPU time on llvmpipe), the workgroup
/// size itself an override (`kernels::Reflection::cpu_workgroup_size`); both within
/// `tests/fused.rs`'s tolerances of the f64 reference.
///
/// Variants that staged texels through workgroup memory so that a SIMD group's lanes touch
/// neighbouring texels (the blur's row pass, the fused blurs, the tables' tile passes) were
/// slower on the H200 than each invocation reading its own run or block straight, 1.1–2.7×,
/// and their workgroup memory, declared in both variants, slowed the straight one too
/// (`benches/RESULTS.md`, 2026-11-27): they are gone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelLayout {
    /// A GPU's (`GPU_LAYOUT = true`): recompute from the texture cache.
    Gpu,
    /// A CPU driver's (`GPU_LAYOUT = false`): keep in private memory.
    Cpu,
}

impl KernelLayout {
    /// [`KERNEL_LAYOUT_ENV`] if set, else [`KernelLayout::Cpu`] on a CPU driver
    /// ([`wgpu::DeviceType::Cpu`]) and [`KernelLayout::Gpu`] on anything else.
    pub fn for_device(device: &wgpu::Device) -> Result<Self> {
        match std::env::var(KERNEL_LAYOUT_ENV) {
            Ok(v) => {
                Self::parse(&v).map_err(|e| Error::Invalid(format!("{KERNEL_LAYOUT_ENV}: {e}")))
            }
            Err(_) if crate::timer::is_gpu(device) => Ok(Self::Gpu),
            Err(_) => Ok(Self::Cpu),
        }
    }

    /// `gpu` or `cpu`, as [`KERNEL_LAYOUT_ENV`] and `shadowgraph bench --layouts` spell it;
    /// else what is wrong with `name`.
    pub fn parse(name: &str) -> std::result::Result<Self, String> {
        match name {
            "gpu" => Ok(Self::Gpu),
            "cpu" => Ok(Self::Cpu),
            _ => Err(format!("`{name}`: expected `gpu` or `cpu`")),
        }
    }

    /// The name [`KernelLayout::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gpu => "gpu",
            Self::Cpu => "cpu",
        }
    }
}

/// How a kernel's workgroup memory starts. WebGPU guarantees zeros, and wgpu keeps the
/// guarantee by default: each workgroup first stores its whole declared workgroup memory and
/// waits at a barrier (the driver's zeroing, or code naga writes where the driver has none),
/// whichever of its entries the kernel reads. Every kernel in `kernels/` writes each entry of
/// its workgroup memory before it reads it, so [`KernelCache`] compiles them
/// [`WorkgroupInit::AsLeft`]: `tests/workgroup_memory.rs` fills that memory with NaN bit
/// patterns before each kernel's body runs, and every map of every plan that runs the kernels
/// stays the same bit for bit. (On the H200 a kernel's declared workgroup memory cost time even
/// where the branch using it never ran: `benches/RESULTS.md`, 2026-11-27;
/// `shadowgraph bench --kernel-dirs shipped,zeroed` times both.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WorkgroupInit {
    /// Zeroed before the kernel's body runs (wgpu's default).
    #[default]
    Zeroed,
    /// Left as the device leaves it: for kernels that write before they read.
    AsLeft,
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
    /// `// #override` values, `exec::KernelCache`).
    pub fn with_constants(
        device: &wgpu::Device,
        name: &str,
        wgsl: &str,
        layout: KernelLayout,
        init: WorkgroupInit,
        overrides: &[(String, f64)],
    ) -> Result<Self> {
        let (module, reflection) = kernels::reflect(name, wgsl)?;
        let two_layouts = module
            .overrides
            .iter()
            .any(|(_, o)| o.name.as_deref() == Some(GPU_LAYOUT_CONSTANT));
        let gpu = f64::from(u8::from(layout == KernelLayout::Gpu));
        let mut constants: Vec<(&str, f64)> =
            overrides.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        if two_layouts {
            constants.push((GPU_LAYOUT_CONSTANT, gpu));
        }
        let constants: &[(&str, f64)] = &constants;
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
            reflection: reflection.in_layout(layout == KernelLayout::Gpu),
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
        let layout = match self.layout {
            Some(layout) => layout,
            None => KernelLayout::for_device(device)?,
        };
        let init = if self.zeroed {
            WorkgroupInit::Zeroed
        } else {
            WorkgroupInit::AsLeft
        };
        ComputeKernel::with_constants(device, name, wgsl, layout, init, overrides)
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
        self.get_for_node(device, name, formats, &[])
    }

    /// [`KernelCache::get_specialized`] with the pipeline constants `overrides` set (a node's,
    /// [`KernelCache::node_constants`]): one pipeline for each set of values.
    pub fn get_for_node(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        formats: &[(String, wgpu::TextureFormat)],
        overrides: &[(String, f64)],
    ) -> Result<Arc<ComputeKernel>> {
        let base = self.get(device, name)?;
        let changes = changes(name, &base.reflection, formats)?;
        if changes.is_empty() && overrides.is_empty() {
            return Ok(base);
        }
        let key = format!("{name}@{changes:?}#{overrides:?}");
        if let Some(k) = self.kernels.get(&key) {
            return Ok(k.clone());
        }
        let wgsl = apply(name, &changes, self.replaced.as_deref())?;
        let k = Arc::new(self.compile_with(device, name, &wgsl, overrides)?);
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
        let wgsl = kernels::resolve_in(name, generated, self.replaced.as_deref())?;
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

/// The WGSL of kernel `name` as [`KernelCache::get_specialized`] compiles it for the texture
/// formats `formats` bound by binding name (no GPU needed: `tests/kernels_validate.rs`
/// validates every variant a technique can bind).
pub fn specialized_source(name: &str, formats: &[(String, wgpu::TextureFormat)]) -> Result<String> {
    let (_, reflection) = kernels::reflect(name, &kernels::resolve(name, None)?)?;
    apply(name, &changes(name, &reflection, formats)?, None)
}

/// The changes binding `formats` to kernel `name` needs.
fn changes(
    name: &str,
    reflection: &Reflection,
    formats: &[(String, wgpu::TextureFormat)],
) -> Result<Vec<Change>> {
    let mut changes = Vec::new();
    for (binding, format) in formats {
        if let Some(b) = reflection.binding(binding) {
            if let Some(change) = change_for(name, binding, b.ty, *format)? {
                changes.push(change);
            }
            if let Some(change) = channels_for(binding, b.ty, *format) {
                changes.push(change);
            }
        }
    }
    Ok(changes)
}

/// Kernel `name`'s resolved WGSL (with `extra`'s replacements) with `changes` applied.
fn apply(name: &str, changes: &[Change], extra: Option<&kernels::Replacements>) -> Result<String> {
    let mut wgsl = kernels::resolve_in(name, None, extra)?;
    for change in changes {
        wgsl = change.apply(&wgsl).ok_or_else(|| Error::Kernel {
            kernel: name.to_string(),
            message: format!(
                "cannot re-declare `{}` for its bound format",
                change.binding()
            ),
        })?;
    }
    Ok(wgsl)
}

/// How a kernel's binding is re-declared for the texture bound to it.
#[derive(Debug)]
enum Change {
    /// A storage texture of another format of the same texel kind.
    Retype {
        binding: String,
        from: &'static str,
        to: &'static str,
    },
    /// A float storage texture bound to a packed texture.
    PackStores { binding: String, from: &'static str },
    /// A float texture bound to a packed texture.
    UnpackLoads { binding: String },
    /// The channel count of a storage texture bound with another count than declared, where
    /// the kernel reads it: `const NAME: u32 = N; // #channels <binding>` (e.g. `blur`'s run
    /// length along columns).
    Channels { binding: String, count: u32 },
}

impl Change {
    fn binding(&self) -> &str {
        match self {
            Change::Retype { binding, .. }
            | Change::PackStores { binding, .. }
            | Change::UnpackLoads { binding }
            | Change::Channels { binding, .. } => binding,
        }
    }

    fn apply(&self, wgsl: &str) -> Option<String> {
        match self {
            Change::Retype { binding, from, to } => retype_storage(wgsl, binding, from, to),
            Change::PackStores { binding, from } => super::packed::pack_stores(wgsl, binding, from),
            Change::UnpackLoads { binding } => super::packed::unpack_loads(wgsl, binding),
            Change::Channels { binding, count } => set_channels(wgsl, binding, *count),
        }
    }
}

/// Whether `format` is a float texel format.
fn is_float(format: wgpu::TextureFormat) -> bool {
    matches!(
        format.sample_type(None, None),
        Some(wgpu::TextureSampleType::Float { .. })
    )
}

/// The change binding `binding` (of type `ty`) of kernel `name` needs for a texture of
/// `bound` format; refuses a storage texture of another texel kind (float and integer texels
/// are not interchangeable in the kernel's arithmetic) unless it is the packed f16 word.
fn change_for(
    name: &str,
    binding: &str,
    ty: wgpu::BindingType,
    bound: wgpu::TextureFormat,
) -> Result<Option<Change>> {
    let packed = bound == crate::graph::texture_format(crate::graph::PACKED_F16X2);
    match ty {
        wgpu::BindingType::StorageTexture {
            format: declared, ..
        } if declared != bound => {
            if packed && is_float(declared) {
                return Ok(Some(Change::PackStores {
                    binding: binding.to_string(),
                    from: wgsl_storage_format(declared)?,
                }));
            }
            if is_float(declared) != is_float(bound) {
                return Err(Error::Pipeline {
                    kernel: name.to_string(),
                    message: format!(
                        "storage texture `{binding}` is {declared:?}; a {bound:?} texture cannot be bound to it"
                    ),
                });
            }
            Ok(Some(Change::Retype {
                binding: binding.to_string(),
                from: wgsl_storage_format(declared)?,
                to: wgsl_storage_format(bound)?,
            }))
        }
        wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { .. },
            view_dimension: wgpu::TextureViewDimension::D2,
            ..
        } if packed => Ok(Some(Change::UnpackLoads {
            binding: binding.to_string(),
        })),
        _ => Ok(None),
    }
}

/// The channels of a storage texel format as a kernel sees them: a packed
/// [`crate::graph::PACKED_F16X2`] word holds two.
fn channels_of(format: wgpu::TextureFormat) -> u32 {
    if format == crate::graph::texture_format(crate::graph::PACKED_F16X2) {
        2
    } else {
        u32::from(format.components())
    }
}

/// The [`Change::Channels`] binding a `bound` texture to storage texture `binding` (of type
/// `ty`) needs: where the channel counts differ (applied only where the kernel marks a
/// constant for it).
fn channels_for(
    binding: &str,
    ty: wgpu::BindingType,
    bound: wgpu::TextureFormat,
) -> Option<Change> {
    let wgpu::BindingType::StorageTexture {
        format: declared, ..
    } = ty
    else {
        return None;
    };
    let count = channels_of(bound);
    (count != channels_of(declared)).then(|| Change::Channels {
        binding: binding.to_string(),
        count,
    })
}

/// `wgsl` with the constant marked `// #channels <binding>` (`const NAME: u32 = N;`, the
/// declared format's count) set to `count`; unchanged where no constant is marked. None for
/// a marked line of another shape.
fn set_channels(wgsl: &str, binding: &str, count: u32) -> Option<String> {
    let marker = format!("// #channels {binding}");
    let mut out = String::with_capacity(wgsl.len());
    for line in wgsl.split_inclusive('\n') {
        let Some(code) = line.trim_end().strip_suffix(&marker) else {
            out.push_str(line);
            continue;
        };
        let (decl, value) = code.trim_end().split_once(" = ")?;
        if !decl.trim_start().starts_with("const ") || !decl.ends_with(": u32") {
            return None;
        }
        value.strip_suffix("u;")?.parse::<u32>().ok()?;
        out.push_str(&format!("{decl} = {count}u; {marker}\n"));
    }
    Some(out)
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

#[cfg(test)]
mod tests {
    use super::*;

    const MARKED: &str =
        "const A: u32 = 1u;\nconst DST_CHANNELS: u32 = 2u; // #channels dst\nfn f() {}\n";

    #[test]
    fn set_channels_rewrites_only_the_marked_constant() {
        let out = set_channels(MARKED, "dst", 4).unwrap();
        assert_eq!(
            out,
            "const A: u32 = 1u;\nconst DST_CHANNELS: u32 = 4u; // #channels dst\nfn f() {}\n"
        );
        // Another binding's marker, or none: unchanged.
        assert_eq!(set_channels(MARKED, "src", 4).unwrap(), MARKED);
        // A marked line that is not a u32 constant is refused, not guessed at.
        assert!(set_channels("let c = 2u; // #channels dst\n", "dst", 4).is_none());
        assert!(set_channels("const C: i32 = 2; // #channels dst\n", "dst", 4).is_none());
    }

    #[test]
    fn blur_sees_the_bound_formats_channels() {
        use wgpu::TextureFormat as T;
        let channels = |f: T| {
            let wgsl = specialized_source("blur", &[("dst".to_string(), f)]).unwrap();
            wgsl.lines()
                .find(|l| l.ends_with("// #channels dst"))
                .expect("blur marks DST_CHANNELS")
                .to_string()
        };
        assert!(channels(T::Rg32Float).contains("= 2u;"));
        assert!(channels(T::R32Float).contains("= 1u;"));
        assert!(channels(T::Rgba32Float).contains("= 4u;"));
        assert!(channels(T::Rgba16Float).contains("= 4u;"));
        let packed = crate::graph::texture_format(crate::graph::PACKED_F16X2);
        assert!(channels(packed).contains("= 2u;"));
    }
}
