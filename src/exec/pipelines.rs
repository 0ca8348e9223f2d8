//! Pipelines: a kernel compiled once per kernel (or generated or re-typed variant), its bind
//! group layouts reflected from its WGSL, cached by [`KernelCache`].

use std::collections::HashMap;
use std::sync::Arc;

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
pub(super) fn no_layout(kernel: &str) -> Error {
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
