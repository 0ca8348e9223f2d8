//! WGSL kernels: embedded sources, the `// #import` resolver, naga validation and reflection.
//!
//! Every kernel lives in `kernels/<name>.wgsl`; import-only modules live in
//! `kernels/shared/<name>.wgsl`. A line `// #import shared/<name>` pulls a module in (once per
//! kernel, recursively). A line `// #generated` marks where a generated block (the per-scene
//! visibility dispatch of the shading kernel) is spliced in. Bindings and workgroup sizes are
//! read back from naga's IR, so Rust never restates them by hand.

use std::collections::HashSet;

use crate::error::{Error, Result};

/// One embedded WGSL file.
#[derive(Clone, Copy, Debug)]
pub struct Source {
    /// Path below `kernels/` without the extension, e.g. `linearize` or `shared/light`.
    pub name: &'static str,
    /// The file's text.
    pub text: &'static str,
}

macro_rules! sources {
    ($($name:literal),* $(,)?) => {
        &[$(Source { name: $name, text: include_str!(concat!("../kernels/", $name, ".wgsl")) }),*]
    };
}

/// Every WGSL file of the project; a test checks this against the `kernels/` folder.
pub const SOURCES: &[Source] = sources![
    "copy",
    "copy_texture",
    "copy_texture_u32",
    "linearize",
    "shadow_depth",
    "gbuffer",
    "shade",
    "vsm",
    "evsm",
    "esm",
    "blur",
    "blur_log",
    "msm",
    "csm",
    "mips",
    "mips_log",
    "sat_tile_sums",
    "sat_tile_sums_f32",
    "sat_carries",
    "sat_tiles",
    "sat_tiles_f32",
    "sat_rows",
    "sat_carry",
    "sat_cols_reduce",
    "sat_cols",
    "sat_cols_f32",
    "truth_accumulate",
    "shared/light",
    "shared/linear_depth",
    "shared/vertex",
    "shared/exp_params",
    "shared/sampling",
    "shared/vis_hard",
    "shared/vis_pcf",
    "shared/vis_pcss",
    "shared/vis_vsm",
    "shared/vis_evsm",
    "shared/vis_esm",
    "shared/msm_quantize",
    "shared/vis_msm",
    "shared/csm_basis",
    "shared/vis_csm",
    "shared/blocker",
    "shared/vis_cssm",
    "shared/vis_vssm",
    "shared/vis_msm_soft",
    "shared/mip_chain",
    "shared/blur_pass",
    "shared/sat_params",
    "shared/sat_tile",
    "shared/sat_tile_sums",
    "shared/sat_tile_scan",
    "shared/sat_scan",
    "shared/sat",
    "shared/sat_lookup",
];

/// The embedded text of `kernels/<name>.wgsl`.
pub fn source(name: &str) -> Result<&'static str> {
    SOURCES
        .iter()
        .find(|s| s.name == name)
        .map(|s| s.text)
        .ok_or_else(|| Error::Kernel {
            kernel: name.to_string(),
            message: "no such kernel in kernels/".into(),
        })
}

/// Resolves `// #import` lines (and `// #generated`, replaced by `generated`, whose own
/// imports are resolved too) of kernel `name`.
pub fn resolve(name: &str, generated: Option<&str>) -> Result<String> {
    let mut seen = HashSet::from([name.to_string()]);
    let mut out = String::new();
    resolve_text(name, source(name)?, generated, &mut seen, &mut out)?;
    Ok(out)
}

/// Resolves the `// #import` lines of `text`, WGSL that is not a file in `kernels/` (e.g. the
/// plug-in stage's exported library); `name` labels errors.
pub fn resolve_source(name: &str, text: &str) -> Result<String> {
    let mut seen = HashSet::new();
    let mut out = String::new();
    resolve_text(name, text, None, &mut seen, &mut out)?;
    Ok(out)
}

fn resolve_text(
    name: &str,
    text: &str,
    generated: Option<&str>,
    seen: &mut HashSet<String>,
    out: &mut String,
) -> Result<()> {
    for line in text.lines() {
        let t = line.trim();
        if let Some(module) = t.strip_prefix("// #import ") {
            let module = module.trim();
            if seen.insert(module.to_string()) {
                let imported = source(module).map_err(|e| Error::Kernel {
                    kernel: name.to_string(),
                    message: format!("import `{module}`: {e}"),
                })?;
                resolve_text(module, imported, None, seen, out)?;
            }
        } else if t == "// #generated" {
            let block = generated.ok_or_else(|| Error::Kernel {
                kernel: name.to_string(),
                message: "has a `// #generated` block but none was supplied".into(),
            })?;
            resolve_text(name, block, None, seen, out)?;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(())
}

/// A binding of a kernel, read from naga's IR.
#[derive(Clone, Debug)]
pub struct Binding {
    /// The WGSL variable name (the slot name a graph node binds by).
    pub name: String,
    /// `@group`.
    pub group: u32,
    /// `@binding`.
    pub binding: u32,
    /// The wgpu binding type derived from the WGSL type.
    pub ty: wgpu::BindingType,
}

/// What reflection tells about a kernel.
#[derive(Clone, Debug)]
pub struct Reflection {
    /// All resource bindings, sorted by (group, binding).
    pub bindings: Vec<Binding>,
    /// `@workgroup_size` of the compute entry point `main`, if there is one.
    pub workgroup_size: Option<[u32; 3]>,
    /// Shader stages of the entry points.
    pub stages: wgpu::ShaderStages,
}

impl Reflection {
    /// The binding named `name`.
    pub fn binding(&self, name: &str) -> Option<&Binding> {
        self.bindings.iter().find(|b| b.name == name)
    }

    /// Number of bind groups used (highest group + 1).
    pub fn group_count(&self) -> u32 {
        self.bindings.iter().map(|b| b.group + 1).max().unwrap_or(0)
    }

    /// Bind group layout entries of `group`.
    pub fn layout_entries(&self, group: u32) -> Vec<wgpu::BindGroupLayoutEntry> {
        self.bindings
            .iter()
            .filter(|b| b.group == group)
            .map(|b| wgpu::BindGroupLayoutEntry {
                binding: b.binding,
                visibility: self.stages,
                ty: b.ty,
                count: None,
            })
            .collect()
    }
}

/// Parses and validates WGSL text, returning the module.
pub fn validate(kernel: &str, wgsl: &str) -> Result<naga::Module> {
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| Error::Kernel {
        kernel: kernel.to_string(),
        message: e.emit_to_string(wgsl),
    })?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| Error::Kernel {
        kernel: kernel.to_string(),
        message: e.emit_to_string(wgsl),
    })?;
    Ok(module)
}

/// Validates `wgsl` and reads its bindings and workgroup size.
pub fn reflect(kernel: &str, wgsl: &str) -> Result<(naga::Module, Reflection)> {
    let module = validate(kernel, wgsl)?;
    let has_filtering_sampler = module.global_variables.iter().any(|(_, g)| {
        matches!(
            module.types[g.ty].inner,
            naga::TypeInner::Sampler { comparison: false }
        )
    });
    let mut bindings = Vec::new();
    for (_, g) in module.global_variables.iter() {
        let Some(rb) = &g.binding else { continue };
        let name = g.name.clone().unwrap_or_default();
        let ty = binding_type(&module, g, has_filtering_sampler).map_err(|m| Error::Kernel {
            kernel: kernel.to_string(),
            message: format!("binding `{name}`: {m}"),
        })?;
        bindings.push(Binding {
            name,
            group: rb.group,
            binding: rb.binding,
            ty,
        });
    }
    bindings.sort_by_key(|b| (b.group, b.binding));
    let mut stages = wgpu::ShaderStages::NONE;
    let mut workgroup_size = None;
    for ep in &module.entry_points {
        match ep.stage {
            naga::ShaderStage::Compute => {
                stages |= wgpu::ShaderStages::COMPUTE;
                if ep.name == "main" {
                    workgroup_size = Some(ep.workgroup_size);
                }
            }
            naga::ShaderStage::Vertex => stages |= wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => stages |= wgpu::ShaderStages::FRAGMENT,
            _ => {}
        }
    }
    Ok((
        module,
        Reflection {
            bindings,
            workgroup_size,
            stages,
        },
    ))
}

/// Size in bytes of the WGSL struct `name` as naga lays it out (for the Rust mirrors' tests).
pub fn struct_size(module: &naga::Module, name: &str) -> Option<u32> {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).ok()?;
    module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .map(|(h, _)| layouter[h].size)
}

fn binding_type(
    module: &naga::Module,
    g: &naga::GlobalVariable,
    filterable: bool,
) -> std::result::Result<wgpu::BindingType, String> {
    use naga::{AddressSpace, ImageClass, ScalarKind, TypeInner};
    Ok(match (&module.types[g.ty].inner, g.space) {
        (_, AddressSpace::Uniform) => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        (_, AddressSpace::Storage { access }) => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage {
                read_only: !access.contains(naga::StorageAccess::STORE),
            },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        (TypeInner::Sampler { comparison }, _) => wgpu::BindingType::Sampler(if *comparison {
            wgpu::SamplerBindingType::Comparison
        } else {
            wgpu::SamplerBindingType::Filtering
        }),
        (
            TypeInner::Image {
                dim,
                arrayed,
                class,
            },
            _,
        ) => {
            let view_dimension = match (dim, arrayed) {
                (naga::ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
                (naga::ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
                other => return Err(format!("unsupported image dimension {other:?}")),
            };
            match class {
                ImageClass::Sampled { kind, multi } => wgpu::BindingType::Texture {
                    sample_type: match kind {
                        // Kernels read with textureLoad unless the module has a filtering
                        // sampler; unfilterable float also admits depth32float views.
                        ScalarKind::Float => wgpu::TextureSampleType::Float { filterable },
                        ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                        ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                        other => return Err(format!("unsupported sample kind {other:?}")),
                    },
                    view_dimension,
                    multisampled: *multi,
                },
                ImageClass::Depth { multi } => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension,
                    multisampled: *multi,
                },
                ImageClass::Storage { format, access } => wgpu::BindingType::StorageTexture {
                    access: if access
                        .contains(naga::StorageAccess::LOAD | naga::StorageAccess::STORE)
                    {
                        wgpu::StorageTextureAccess::ReadWrite
                    } else if access.contains(naga::StorageAccess::STORE) {
                        wgpu::StorageTextureAccess::WriteOnly
                    } else {
                        wgpu::StorageTextureAccess::ReadOnly
                    },
                    format: storage_format(*format)?,
                    view_dimension,
                },
                other => return Err(format!("unsupported image class {other:?}")),
            }
        }
        (other, space) => return Err(format!("unsupported binding {other:?} in {space:?}")),
    })
}

fn storage_format(f: naga::StorageFormat) -> std::result::Result<wgpu::TextureFormat, String> {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    Ok(match f {
        S::R32Float => T::R32Float,
        S::Rg32Float => T::Rg32Float,
        S::Rgba32Float => T::Rgba32Float,
        S::R16Float => T::R16Float,
        S::Rg16Float => T::Rg16Float,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba16Unorm => T::Rgba16Unorm,
        S::Rgba16Snorm => T::Rgba16Snorm,
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::R32Uint => T::R32Uint,
        S::Rg32Uint => T::Rg32Uint,
        S::Rgba32Uint => T::Rgba32Uint,
        other => return Err(format!("unsupported storage format {other:?}")),
    })
}
