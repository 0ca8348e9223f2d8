//! The cost model, computed from a plan without a GPU: what each node moves, how many
//! dispatches it takes, and what the shading pass fetches per pixel ([`fetches`]).
//!
//! A node's traffic is what its workgroups load and store, summed over its dispatches: for
//! each binding, the texels its kernel declares (`// #traffic`, see [`declare`]) times the
//! texel size of the bound format. Reuse inside a workgroup (a stencil's neighbours, a texel
//! read twice) is free; a halo that neighbouring workgroups both load counts for each, and a
//! texture that another dispatch reads again (a scan's second pass, a mip level the next
//! dispatch reduces) counts again. This is the traffic between a workgroup and the memory
//! behind its own cache; it is what a kernel's bandwidth is measured against
//! (`shadowgraph bench`) and what `shadowgraph plan` prints per texel of the light's map.

pub mod declare;
pub mod expr;
pub mod fetches;

use std::collections::HashMap;

use self::declare::Pattern;
use super::{Dispatch, Node, Plan, texel_bytes};
use crate::error::{Error, Result};
use crate::kernels::{self, Reflection};

/// What one node moves.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Traffic {
    /// Dispatches the node records.
    pub dispatches: u32,
    /// Bytes read, all dispatches.
    pub read: f64,
    /// Bytes written, all dispatches.
    pub written: f64,
}

impl Traffic {
    /// Bytes read and written.
    pub fn bytes(&self) -> f64 {
        self.read + self.written
    }
}

/// A texture as one dispatch binds it: the bound level's size and the format.
#[derive(Clone, Copy, Debug)]
struct Bound {
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
}

/// One dispatch: its workgroup count, its parameters and, per binding it names, the texture
/// bound (a binding it does not name is not counted).
struct Dispatched<'a> {
    groups: [u32; 3],
    params: &'a [u8],
    bound: HashMap<String, Bound>,
}

/// Whether a binding moves data the model counts (textures and storage buffers; uniforms and
/// samplers do not).
fn moves_data(ty: &wgpu::BindingType) -> bool {
    use wgpu::BindingType as B;
    match ty {
        B::Texture { .. } | B::StorageTexture { .. } => true,
        B::Buffer { ty, .. } => matches!(ty, wgpu::BufferBindingType::Storage { .. }),
        _ => false,
    }
}

/// (reads, writes) of a binding.
fn access(ty: &wgpu::BindingType) -> (bool, bool) {
    use wgpu::{BindingType as B, StorageTextureAccess as A};
    match ty {
        B::StorageTexture { access, .. } => match access {
            A::WriteOnly => (false, true),
            A::ReadOnly => (true, false),
            _ => (true, true),
        },
        B::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            ..
        } => (true, !read_only),
        _ => (true, false),
    }
}

/// Checks that the `// #traffic` lines of `kernel` (its own file's `text`; `reflection` from
/// its resolved WGSL) declare every group-0 texture and storage buffer and nothing else.
pub fn check_declarations(
    kernel: &str,
    text: &str,
    reflection: &Reflection,
) -> Result<HashMap<String, Pattern>> {
    let decls = declare::traffic(kernel, text)?;
    let bindings: Vec<&str> = reflection
        .bindings
        .iter()
        .filter(|b| b.group == 0 && moves_data(&b.ty))
        .map(|b| b.name.as_str())
        .collect();
    let err = |message: String| Error::Kernel {
        kernel: kernel.to_string(),
        message,
    };
    if let Some(b) = bindings.iter().find(|b| !decls.contains_key(**b)) {
        return Err(err(format!(
            "binding `{b}` has no `// #traffic {b}: all | none | <expression> per group` line \
             (the cost model needs what every binding moves)"
        )));
    }
    if let Some(d) = decls.keys().find(|d| !bindings.contains(&d.as_str())) {
        return Err(err(format!(
            "`// #traffic {d}` names no texture or storage-buffer binding"
        )));
    }
    for (d, p) in &decls {
        if let Pattern::PerTexelOf(_, of) = p {
            if !bindings.contains(&of.as_str()) {
                return Err(err(format!(
                    "`// #traffic {d}` counts per texel of unknown `{of}`"
                )));
            }
        }
    }
    Ok(decls)
}

/// What `node` of `plan` moves, from its kernel's declarations and the plan's sizes.
pub fn node_traffic(plan: &Plan, node: &Node) -> Result<Traffic> {
    let wgsl = kernels::resolve(node.kernel.name(), None)?;
    let (module, reflection) = kernels::reflect(node.kernel.name(), &wgsl)?;
    let decls = check_declarations(node.kernel.name(), node.kernel.source(), &reflection)?;
    let wg = reflection.workgroup_size.unwrap_or([1, 1, 1]);
    let consts = declare::constants(&module);
    let params = declare::global_type(&module, "params");
    let err = |message: String| Error::Kernel {
        kernel: node.kernel.to_string(),
        message: format!("node `{}`: {message}", node.name),
    };
    let dispatched = dispatches(plan, node, wg).map_err(err)?;
    let mut t = Traffic {
        dispatches: dispatched.len() as u32,
        ..Default::default()
    };
    for d in &dispatched {
        let mut name = |n: &str| -> std::result::Result<f64, String> {
            // `<binding>.width` / `.height`: the bound texture's (level's) size.
            if let Some((b, side)) = n.split_once('.').filter(|(b, _)| *b != "params") {
                let bound = d
                    .bound
                    .get(b)
                    .ok_or_else(|| format!("`{n}`: no texture bound to `{b}`"))?;
                return match side {
                    "width" => Ok(f64::from(bound.width)),
                    "height" => Ok(f64::from(bound.height)),
                    _ => Err(format!("`{n}`: a binding has `.width` and `.height`")),
                };
            }
            declare::constant_or_param(n, &consts, &module, params.map(|ty| (ty, d.params)))
        };
        let groups = d.groups.iter().map(|&g| f64::from(g)).product::<f64>();
        for b in reflection.bindings.iter().filter(|b| b.group == 0) {
            // Buffers (a counter) are not resources of the plan.
            let (Some(bound), Some(pattern)) = (d.bound.get(&b.name), decls.get(&b.name)) else {
                continue;
            };
            let texels = match pattern {
                Pattern::All => f64::from(bound.width) * f64::from(bound.height),
                Pattern::None => 0.0,
                Pattern::PerGroup(e) => e.eval(&mut name).map_err(err)? * groups,
                Pattern::PerTexelOf(e, of) => {
                    let Some(other) = d.bound.get(of) else {
                        return Err(err(format!(
                            "`{}` counts per texel of unbound `{of}`",
                            b.name
                        )));
                    };
                    let texels = f64::from(other.width) * f64::from(other.height);
                    e.eval(&mut name).map_err(err)? * texels
                }
            };
            let bytes = texels * texel_bytes(bound.format) as f64;
            let (reads, writes) = access(&b.ty);
            if reads {
                t.read += bytes;
            }
            if writes {
                t.written += bytes;
            }
        }
    }
    Ok(t)
}

/// The dispatches `node` records, with what each binds.
fn dispatches<'n>(
    plan: &Plan,
    node: &'n Node,
    wg: [u32; 3],
) -> std::result::Result<Vec<Dispatched<'n>>, String> {
    let bound = |r: &str, level: u32| -> std::result::Result<Bound, String> {
        let p = plan
            .resource(r)
            .ok_or_else(|| format!("`{r}` is not in the plan"))?;
        Ok(Bound {
            width: (p.width >> level).max(1),
            height: (p.height >> level).max(1),
            format: p.resource.format,
        })
    };
    let size = |r: &str| plan.resource(r).map(|p| (p.width, p.height));
    if let Some(groups) = node.dispatch.groups(size, wg) {
        let mut map = HashMap::new();
        for (slot, r) in node.inputs.iter().chain(&node.outputs) {
            map.insert(slot.clone(), bound(r, 0)?);
        }
        return Ok(vec![Dispatched {
            groups,
            params: &node.params,
            bound: map,
        }]);
    }
    let Dispatch::Several(subs) = &node.dispatch else {
        return Err("dispatches over a resource that is not in the plan".into());
    };
    // As the executor binds them: the levels each names (the bindings it leaves to repeat
    // the last level are not written, and not counted).
    subs.iter()
        .map(|d| {
            let mut map = HashMap::new();
            for v in &d.levels {
                let r = node
                    .slot_resource(&v.slot)
                    .ok_or_else(|| format!("binds nothing to `{}`", v.slot))?;
                map.insert(v.binding.clone(), bound(r, v.level)?);
            }
            Ok(Dispatched {
                groups: d.groups,
                params: node
                    .params
                    .get(d.params.clone())
                    .ok_or("reads parameter bytes it does not have")?,
                bound: map,
            })
        })
        .collect()
}

/// One light's nodes with their traffic, in plan order.
pub fn light_traffic(plan: &Plan, light: usize) -> Result<Vec<(&Node, Traffic)>> {
    plan.steps
        .iter()
        .filter(|s| s.node.light == Some(light))
        .map(|s| Ok((&s.node, node_traffic(plan, &s.node)?)))
        .collect()
}

/// Texels of light `light`'s map: its imported (rasterized) resource's, else its largest.
pub fn map_texels(plan: &Plan, light: usize) -> f64 {
    let (w, h) = map_dims(plan, light);
    f64::from(w) * f64::from(h)
}

/// Width and height of light `light`'s map: its imported (rasterized) resource's, else its
/// largest; (1, 1) if it has none.
pub fn map_dims(plan: &Plan, light: usize) -> (u32, u32) {
    let texels = |r: &&super::PlannedResource| f64::from(r.width) * f64::from(r.height);
    let of_light = || {
        plan.resources
            .iter()
            .filter(|r| r.resource.light == Some(light))
    };
    of_light()
        .find(|r| r.resource.imported)
        .or_else(|| of_light().max_by(|a, b| texels(a).total_cmp(&texels(b))))
        .map_or((1, 1), |r| (r.width, r.height))
}

/// Bytes per texel of light `light`'s map of one read of its rasterized depth and one write
/// of every map the shading reads (all their mip levels): what a single fused kernel would
/// move.
pub fn ideal_bytes(plan: &Plan, light: usize) -> f64 {
    let of_light = plan
        .resources
        .iter()
        .filter(|r| r.resource.light == Some(light));
    let depth: f64 = of_light
        .clone()
        .filter(|r| r.resource.imported)
        .map(|r| r.bytes as f64)
        .sum();
    let results: f64 = of_light
        .filter(|r| plan.outputs.contains(&r.resource.name) && !r.resource.imported)
        .map(|r| r.bytes as f64)
        .sum();
    (depth + results) / map_texels(plan, light)
}
