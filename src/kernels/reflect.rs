//! Reflection: a kernel's bindings, workgroup sizes (in each layout) and texels per invocation,
//! read back from naga's IR so that Rust never restates them by hand.

use super::KERNEL_DIR_ENV;
use super::binding_type::{binding_type, sampled_images};
use super::source::replacements;
use super::validate::validate_with_info;
use crate::error::{Error, Result};

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
    /// `@workgroup_size` of the compute entry point `main`, if there is one, as a GPU compiles
    /// it: where the size is an `override` of the layout ([`GPU_LAYOUT_CONSTANT`] true), that
    /// layout's. A [`crate::exec::ComputeKernel`]'s reflection holds its own layout's.
    pub workgroup_size: Option<[u32; 3]>,
    /// The same as a CPU driver compiles it ([`GPU_LAYOUT_CONSTANT`] false): where the kernel's
    /// size does not depend on the layout, [`Reflection::workgroup_size`].
    pub cpu_workgroup_size: Option<[u32; 3]>,
    /// The same as the redesign layout compiles it ([`GPU_LAYOUT_CONSTANT`] and
    /// [`REDESIGN_CONSTANT`] true): where the kernel's size does not depend on `REDESIGN`,
    /// [`Reflection::workgroup_size`].
    pub redesign_workgroup_size: Option<[u32; 3]>,
    /// Texels an invocation of `main` covers along x ([`TEXELS_X_CONSTANT`]; 1 where the
    /// kernel declares none): a workgroup covers `workgroup_size[0] · texels_x` columns. As
    /// [`Reflection::workgroup_size`], the GPU layout's where it is an `override`; a
    /// [`crate::exec::ComputeKernel`]'s reflection holds its own layout's.
    pub texels_x: u32,
    /// [`Reflection::texels_x`] in the CPU driver's layout and in the redesign layout.
    pub other_texels_x: OtherLayouts,
    /// Shader stages of the entry points.
    pub stages: wgpu::ShaderStages,
}

/// A value of a kernel in the two layouts other than a GPU's ([`Reflection::other_texels_x`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OtherLayouts {
    /// As a CPU driver compiles it ([`GPU_LAYOUT_CONSTANT`] false).
    pub cpu: u32,
    /// As the redesign layout compiles it ([`GPU_LAYOUT_CONSTANT`] and [`REDESIGN_CONSTANT`]
    /// true).
    pub redesign: u32,
}

/// The constant (`const TEXELS_X: u32`, or an `override` of the layout, e.g.
/// `select(1u, 4u, REDESIGN)`) by which a compute kernel says that each invocation of `main`
/// covers that many texels along x, `@workgroup_size`'s x apart (`kernels/shade.wgsl`: pixels a
/// lane shades). The dispatch ([`Reflection::groups_for`]; a graph node dispatched
/// [`crate::graph::Dispatch::Texels`]) follows it.
pub const TEXELS_X_CONSTANT: &str = "TEXELS_X";

/// The most texels along x a kernel may give an invocation ([`TEXELS_X_CONSTANT`]).
pub const MAX_TEXELS_X: u32 = 64;

/// The pipeline constant a kernel declares (`override GPU_LAYOUT: bool`) where it has two
/// layouts, one for GPUs and one for CPU drivers (`crate::exec::KernelLayout`). Its workgroup
/// size may depend on it (`kernels/shared/encode_blur.wgsl`: `@workgroup_size(LANES)`).
pub const GPU_LAYOUT_CONSTANT: &str = "GPU_LAYOUT";

/// The pipeline constant a kernel declares (`override REDESIGN: bool`) where it has a variant not
/// yet decided on a GPU (`crate::exec::KernelLayout::Redesign` sets it, with
/// [`GPU_LAYOUT_CONSTANT`]; every other layout leaves it false). Its workgroup size may depend on
/// it.
pub const REDESIGN_CONSTANT: &str = "REDESIGN";

impl Reflection {
    /// This reflection as the kernel compiles in one layout (`gpu`: [`GPU_LAYOUT_CONSTANT`]
    /// true): its workgroup size that layout's.
    pub fn in_layout(mut self, gpu: bool) -> Self {
        if !gpu {
            self.workgroup_size = self.cpu_workgroup_size;
            self.texels_x = self.other_texels_x.cpu;
        }
        self
    }

    /// This reflection as the redesign layout compiles it: its workgroup size and texels an
    /// invocation that layout's.
    pub fn in_redesign(mut self) -> Self {
        self.workgroup_size = self.redesign_workgroup_size;
        self.texels_x = self.other_texels_x.redesign;
        self
    }

    /// The texels a workgroup of `main` covers: `workgroup_size` with its x times
    /// [`Reflection::texels_x`].
    pub fn texel_footprint(&self) -> [u32; 3] {
        let wg = self.workgroup_size.unwrap_or([1, 1, 1]);
        [wg[0] * self.texels_x, wg[1], wg[2]]
    }

    /// The largest workgroup of either layout, dimension by dimension (what the device's limits
    /// must allow).
    pub fn largest_workgroup(&self) -> Option<[u32; 3]> {
        match (self.workgroup_size, self.cpu_workgroup_size) {
            (Some(a), Some(b)) => {
                let c = self.redesign_workgroup_size.unwrap_or(a);
                Some([0, 1, 2].map(|i| a[i].max(b[i]).max(c[i])))
            }
            (a, b) => a.or(b),
        }
    }

    /// Workgroups of `main` covering a `w × h` texel grid: `workgroup_size[0] · texels_x`
    /// columns and `workgroup_size[1]` rows a workgroup.
    pub fn groups_for(&self, w: u32, h: u32) -> [u32; 3] {
        let wg = self.texel_footprint();
        [w.div_ceil(wg[0]), h.div_ceil(wg[1]), 1]
    }

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

/// Validates `wgsl` and reads its bindings and workgroup size.
pub fn reflect(kernel: &str, wgsl: &str) -> Result<(naga::Module, Reflection)> {
    let replaced = replacements().is_ok_and(|r| !r.is_empty());
    let origin = format!("kernels replaced by {KERNEL_DIR_ENV}");
    let (module, info) = validate_with_info(kernel, wgsl, replaced.then_some(origin.as_str()))?;
    reflect_module(kernel, module, &info)
}

/// [`reflect`] of a kernel replaced from `origin` (a folder of variants): a validation error
/// is one line tagged `[origin]`.
pub fn reflect_replaced(
    kernel: &str,
    wgsl: &str,
    origin: &str,
) -> Result<(naga::Module, Reflection)> {
    let (module, info) = validate_with_info(kernel, wgsl, Some(origin))?;
    reflect_module(kernel, module, &info)
}

fn reflect_module(
    kernel: &str,
    module: naga::Module,
    info: &naga::valid::ModuleInfo,
) -> Result<(naga::Module, Reflection)> {
    let sampled = sampled_images(&module);
    let mut bindings = Vec::new();
    for (h, g) in module.global_variables.iter() {
        let Some(rb) = &g.binding else { continue };
        let name = g.name.clone().unwrap_or_default();
        let ty = binding_type(&module, g, sampled.contains(&h)).map_err(|m| Error::Kernel {
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
    // A `TEXELS_X` that is an override of the layout: evaluated in each layout.
    let overrides_texels = module
        .overrides
        .iter()
        .any(|(_, o)| o.name.as_deref() == Some(TEXELS_X_CONSTANT));
    let mut stages = wgpu::ShaderStages::NONE;
    let mut workgroup_size = None;
    let mut cpu_workgroup_size = None;
    let mut redesign_workgroup_size = None;
    let mut texels = [1; 3];
    for ep in &module.entry_points {
        match ep.stage {
            naga::ShaderStage::Compute => {
                stages |= wgpu::ShaderStages::COMPUTE;
                if ep.name == "main" {
                    let layouts = [(true, false), (false, false), (true, true)];
                    let sizes = if ep.workgroup_size_overrides.is_some() || overrides_texels {
                        layouts.map(|(gpu, redesign)| {
                            layout_main(kernel, &module, info, gpu, redesign)
                        })
                    } else {
                        [(); 3].map(|()| Ok((ep.workgroup_size, texels_x(kernel, &module)?)))
                    };
                    let [gpu, cpu, redesign] = sizes;
                    let ((gpu, tg), (cpu, tc), (redesign, tr)) = (gpu?, cpu?, redesign?);
                    workgroup_size = Some(gpu);
                    cpu_workgroup_size = Some(cpu);
                    redesign_workgroup_size = Some(redesign);
                    texels = [tg, tc, tr];
                }
            }
            naga::ShaderStage::Vertex => stages |= wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => stages |= wgpu::ShaderStages::FRAGMENT,
            _ => {}
        }
    }
    let texels_x = match module.entry_points.iter().any(|e| e.name == "main") {
        true => texels[0],
        false => texels_x(kernel, &module)?,
    };
    Ok((
        module,
        Reflection {
            bindings,
            workgroup_size,
            cpu_workgroup_size,
            redesign_workgroup_size,
            texels_x,
            other_texels_x: OtherLayouts {
                cpu: texels[1],
                redesign: texels[2],
            },
            stages,
        },
    ))
}

/// `main`'s workgroup size and [`TEXELS_X_CONSTANT`] where either is an `override`
/// expression: as the layout `gpu` (and `redesign`) compiles them ([`GPU_LAYOUT_CONSTANT`] and
/// [`REDESIGN_CONSTANT`] set where the kernel declares them, every other override its
/// default), naga's own evaluation of the pipeline constants.
fn layout_main(
    kernel: &str,
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    gpu: bool,
    redesign: bool,
) -> Result<([u32; 3], u32)> {
    let mut constants = naga::back::PipelineConstants::default();
    for (name, value) in [(GPU_LAYOUT_CONSTANT, gpu), (REDESIGN_CONSTANT, redesign)] {
        if module
            .overrides
            .iter()
            .any(|(_, o)| o.name.as_deref() == Some(name))
        {
            constants.insert(name.to_string(), f64::from(u8::from(value)));
        }
    }
    let stage = (naga::ShaderStage::Compute, "main");
    let (resolved, _) =
        naga::back::pipeline_constants::process_overrides(module, info, Some(stage), &constants)
            .map_err(|e| Error::Kernel {
                kernel: kernel.to_string(),
                message: format!("its workgroup size's overrides: {e}"),
            })?;
    let ep = resolved
        .entry_points
        .iter()
        .find(|e| e.name == "main")
        .expect("process_overrides keeps the entry point it was given");
    Ok((ep.workgroup_size, texels_x(kernel, &resolved)?))
}

/// `kernel`'s [`TEXELS_X_CONSTANT`] (a constant; an override once naga has resolved it): 1 if
/// it declares none, else a u32 in 1..=[`MAX_TEXELS_X`].
fn texels_x(kernel: &str, module: &naga::Module) -> Result<u32> {
    let Some((_, c)) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(TEXELS_X_CONSTANT))
    else {
        return Ok(1);
    };
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(n)) if (1..=MAX_TEXELS_X).contains(&n) => {
            Ok(n)
        }
        _ => Err(Error::Kernel {
            kernel: kernel.to_string(),
            message: format!(
                "`const {TEXELS_X_CONSTANT}` must be a u32 literal in 1..={MAX_TEXELS_X}"
            ),
        }),
    }
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
