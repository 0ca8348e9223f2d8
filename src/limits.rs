//! What kernels and plans need of a device (bindings per stage, workgroup sizes and memory,
//! dispatch sizes), read from the WGSL by reflection and compared with `wgpu::Limits` before
//! anything is created, and the device features the lights' techniques need; `scene` (feature
//! `cli`) adds what a frame needs (buffers, the shading pass, memory against a budget) and
//! names the scene key that would fix it.

mod budget;
#[cfg(feature = "cli")]
pub mod scene;

use std::collections::HashMap;

pub use budget::{DEFAULT_MEMORY_BUDGET, MEMORY_BUDGET_ENV, memory_budget, parse_bytes};
#[cfg(feature = "cli")]
pub use scene::{Memory, check_scene, render_memory};

use crate::error::{Error, Result};
use crate::graph::{Dispatch, Node, Plan};
use crate::kernels;
use crate::model::{Light, Storage};

/// One thing a kernel needs of the device, and the device's limit on it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Need {
    /// What is counted, e.g. `sampled textures`.
    pub what: &'static str,
    /// The `wgpu::Limits` field that bounds it.
    pub limit_name: &'static str,
    /// How many the kernel needs.
    pub requested: u64,
    /// How many the device allows.
    pub limit: u64,
}

impl Need {
    fn new(what: &'static str, limit_name: &'static str, requested: u64, limit: u32) -> Self {
        Self {
            what,
            limit_name,
            requested,
            limit: u64::from(limit),
        }
    }

    /// Whether the need exceeds the limit.
    pub fn over(&self) -> bool {
        self.requested > self.limit
    }

    /// `what (limit_name)`.
    pub fn describe(&self) -> String {
        format!("{} ({})", self.what, self.limit_name)
    }
}

/// A plan step that needs more than the device allows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StepOver {
    /// The node's name (`light0.vsm.blur_h`).
    pub node: String,
    /// The light the node works for.
    pub light: Option<usize>,
    /// `kernel `vsm_blur`: workgroup memory in bytes (max_compute_workgroup_storage_size)` or
    /// `node `…`: workgroups per dimension (…)`.
    pub what: String,
    /// Whether the size of the map (not the technique's kernel) is what is too large.
    pub dispatch: bool,
    /// What it needs.
    pub requested: u64,
    /// What the device allows.
    pub limit: u64,
}

/// What the compute kernel `module` (reflected as `refl`) needs, against `l`.
pub fn kernel_needs(
    module: &naga::Module,
    refl: &kernels::Reflection,
    l: &wgpu::Limits,
) -> Result<Vec<Need>> {
    let mut needs = workgroup_needs(refl, workgroup_bytes(module)?, l).to_vec();
    needs.extend(binding_needs(refl, l));
    Ok(needs)
}

/// The workgroup's shape, size and memory (`shared` bytes) against `l`.
fn workgroup_needs(refl: &kernels::Reflection, shared: u64, l: &wgpu::Limits) -> [Need; 5] {
    let wg = refl.largest_workgroup().unwrap_or([1, 1, 1]).map(u64::from);
    [
        Need::new(
            "workgroup width",
            "max_compute_workgroup_size_x",
            wg[0],
            l.max_compute_workgroup_size_x,
        ),
        Need::new(
            "workgroup height",
            "max_compute_workgroup_size_y",
            wg[1],
            l.max_compute_workgroup_size_y,
        ),
        Need::new(
            "workgroup depth",
            "max_compute_workgroup_size_z",
            wg[2],
            l.max_compute_workgroup_size_z,
        ),
        Need::new(
            "invocations per workgroup",
            "max_compute_invocations_per_workgroup",
            wg.iter().product(),
            l.max_compute_invocations_per_workgroup,
        ),
        Need::new(
            "workgroup memory in bytes",
            "max_compute_workgroup_storage_size",
            shared,
            l.max_compute_workgroup_storage_size,
        ),
    ]
}

/// The kernel's bindings, by the per-stage limit each counts against, and its bind groups.
fn binding_needs(refl: &kernels::Reflection, l: &wgpu::Limits) -> [Need; 6] {
    let b = BindingCounts::of(refl);
    [
        Need::new(
            "storage textures",
            "max_storage_textures_per_shader_stage",
            b.storage_textures,
            l.max_storage_textures_per_shader_stage,
        ),
        Need::new(
            "storage buffers",
            "max_storage_buffers_per_shader_stage",
            b.storage_buffers,
            l.max_storage_buffers_per_shader_stage,
        ),
        Need::new(
            "sampled textures",
            "max_sampled_textures_per_shader_stage",
            b.sampled_textures,
            l.max_sampled_textures_per_shader_stage,
        ),
        Need::new(
            "samplers",
            "max_samplers_per_shader_stage",
            b.samplers,
            l.max_samplers_per_shader_stage,
        ),
        Need::new(
            "uniform buffers",
            "max_uniform_buffers_per_shader_stage",
            b.uniform_buffers,
            l.max_uniform_buffers_per_shader_stage,
        ),
        Need::new(
            "bind groups",
            "max_bind_groups",
            refl.group_count().into(),
            l.max_bind_groups,
        ),
    ]
}

/// Bytes of a kernel's workgroup-memory variables, laid out as naga lays them out.
fn workgroup_bytes(module: &naga::Module) -> Result<u64> {
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| Error::Invalid(format!("workgroup memory layout: {e}")))?;
    Ok(module
        .global_variables
        .iter()
        .filter(|(_, g)| g.space == naga::AddressSpace::WorkGroup)
        .map(|(_, g)| u64::from(layouter[g.ty].size))
        .sum())
}

/// A kernel's bindings by the per-stage limit each counts against.
struct BindingCounts {
    storage_textures: u64,
    storage_buffers: u64,
    sampled_textures: u64,
    samplers: u64,
    uniform_buffers: u64,
}

impl BindingCounts {
    fn of(refl: &kernels::Reflection) -> Self {
        use wgpu::BindingType as B;
        use wgpu::BufferBindingType as Buf;
        let count = |f: fn(&B) -> bool| refl.bindings.iter().filter(|b| f(&b.ty)).count() as u64;
        Self {
            storage_textures: count(|t| matches!(t, B::StorageTexture { .. })),
            storage_buffers: count(|t| {
                matches!(
                    t,
                    B::Buffer {
                        ty: Buf::Storage { .. },
                        ..
                    }
                )
            }),
            sampled_textures: count(|t| matches!(t, B::Texture { .. })),
            samplers: count(|t| matches!(t, B::Sampler(_))),
            uniform_buffers: count(|t| {
                matches!(
                    t,
                    B::Buffer {
                        ty: Buf::Uniform,
                        ..
                    }
                )
            }),
        }
    }
}

/// The first of kernel `name`'s needs (WGSL `wgsl`) past `l`, if any.
pub fn kernel_over(name: &str, wgsl: &str, l: &wgpu::Limits) -> Result<Option<Need>> {
    let (module, refl) = kernels::reflect(name, wgsl)?;
    Ok(kernel_needs(&module, &refl, l)?
        .into_iter()
        .find(Need::over))
}

/// Texture sides given on the command line (`what` names the flag, `--image (width)`) against
/// the device's largest side `max`: the first past it is an error naming its flag. Checked
/// before the flag's value reaches a scene, whose own check would name the scene file's key and
/// line, which the user did not write.
pub fn flag_sides<S: Into<String>>(
    max: u32,
    sides: impl IntoIterator<Item = (S, Option<u32>)>,
) -> Result<()> {
    match sides
        .into_iter()
        .find_map(|(what, n)| n.filter(|&n| n > max).map(|n| (what, n)))
    {
        Some((what, n)) => Err(Error::Limit {
            what: what.into(),
            requested: u64::from(n),
            limit: u64::from(max),
        }),
        None => Ok(()),
    }
}

/// The first step of `plan` whose kernel or dispatch exceeds `l`, if any, or else the first
/// texture wider or taller than the device allows (tables interleaved along x are several
/// times as wide as the map: `Graph::interleaved`).
pub fn plan_over(plan: &Plan, l: &wgpu::Limits) -> Result<Option<StepOver>> {
    if let Some(over) = steps_over(plan, l)? {
        return Ok(Some(over));
    }
    let max = l.max_texture_dimension_2d;
    Ok(plan
        .resources
        .iter()
        .find(|r| r.width.max(r.height) > max)
        .map(|r| StepOver {
            node: r
                .producer
                .map_or_else(String::new, |s| plan.steps[s].node.name.clone()),
            light: r.resource.light,
            what: format!(
                "texture `{}` ({}×{}): its side (max_texture_dimension_2d)",
                r.resource.name, r.width, r.height
            ),
            dispatch: true,
            requested: r.width.max(r.height).into(),
            limit: max.into(),
        }))
}

/// The first step of `plan` whose kernel or dispatch exceeds `l`, if any.
fn steps_over(plan: &Plan, l: &wgpu::Limits) -> Result<Option<StepOver>> {
    let mut workgroups: HashMap<&str, [u32; 3]> = HashMap::new();
    for step in &plan.steps {
        let node = &step.node;
        let name = node.kernel.as_str();
        if !workgroups.contains_key(name) {
            let wgsl = kernels::resolve(name, None)?;
            let (module, refl) = kernels::reflect(name, &wgsl)?;
            if let Some(n) = kernel_needs(&module, &refl, l)?
                .into_iter()
                .find(Need::over)
            {
                return Ok(Some(StepOver {
                    node: node.name.clone(),
                    light: node.light,
                    what: format!("kernel `{name}`: {}", n.describe()),
                    dispatch: false,
                    requested: n.requested,
                    limit: n.limit,
                }));
            }
            workgroups.insert(name, refl.workgroup_size.unwrap_or([1, 1, 1]));
        }
        let wg = workgroups.get(name).copied().unwrap_or([1, 1, 1]);
        let max = l.max_compute_workgroups_per_dimension;
        if let Some(g) = dispatch_groups(plan, node, wg)
            .into_iter()
            .find(|&g| g > max)
        {
            return Ok(Some(StepOver {
                node: node.name.clone(),
                light: node.light,
                what: format!(
                    "node `{}`: workgroups per dimension (max_compute_workgroups_per_dimension)",
                    node.name
                ),
                dispatch: true,
                requested: g.into(),
                limit: max.into(),
            }));
        }
    }
    Ok(None)
}

/// Workgroup counts of a node's dispatch (as the executor computes them, the largest of the
/// kernel layouts' along each axis where they differ, [`Dispatch::Tiles`] and
/// [`Dispatch::Redesigned`]; for several dispatches the largest along each axis, e.g. a mip
/// chain's first).
pub fn dispatch_groups(plan: &Plan, node: &Node, wg: [u32; 3]) -> [u32; 3] {
    let size = |r: &str| plan.resource(r).map(|p| (p.width, p.height));
    let wg = wg.map(|w| w.max(1));
    if let Dispatch::Several(subs) = &node.dispatch {
        return subs
            .iter()
            .fold([1, 1, 1], |m, d| [0, 1, 2].map(|a| m[a].max(d.groups[a])));
    }
    let layout = |(gpu, redesign)| {
        node.dispatch
            .groups_in(size, wg, gpu, redesign)
            .unwrap_or([1, 1, 1])
    };
    [(true, false), (false, false), (true, true)]
        .map(layout)
        .into_iter()
        .fold([1, 1, 1], |m, g| [0, 1, 2].map(|a| m[a].max(g[a])))
}

/// Checks that the device offers the features the lights' techniques need (unorm16 moment
/// storage needs `TEXTURE_FORMAT_16BIT_NORM`; f32 summed-area tables, read with filtered
/// fetches, `FLOAT32_FILTERABLE`).
pub fn check_features(device: &wgpu::Device, lights: &[Light]) -> Result<()> {
    for (i, l) in lights.iter().enumerate() {
        // Only MSM's tables accept unorm16 (`technique::params::MSM_FORMAT`).
        let storage = l.shadow.technique.storage();
        if storage == Some(Storage::Unorm16)
            && !device
                .features()
                .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM)
        {
            return Err(Error::MissingFeature {
                what: format!("light[{i}].shadow.format = \"unorm16\""),
                feature: "TEXTURE_FORMAT_16BIT_NORM",
            });
        }
        if l.shadow.technique.sat_filtered()
            && !device
                .features()
                .contains(wgpu::Features::FLOAT32_FILTERABLE)
        {
            return Err(Error::MissingFeature {
                what: format!("light[{i}].shadow.sat_sums = \"float\""),
                feature: "FLOAT32_FILTERABLE",
            });
        }
    }
    Ok(())
}
