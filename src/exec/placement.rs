//! Where each slot of a plan lives: a texture, or, in a layout that keeps never-filtered
//! intermediates in storage buffers ([`KernelLayout::buffers_intermediates`]), a row-major
//! storage buffer that every kernel binding it reads and writes through `exec::buffers`'
//! rewrite of its texture calls.

use crate::error::Result;
use crate::graph::{Dispatch, Node, Plan, texture_format};
use crate::kernels::{self, Reflection, Replacements};

use super::KernelLayout;

/// Whether `plan`'s slot `slot` may be a storage buffer in `layout` on a device of `limits`:
/// where the layout keeps intermediates in buffers, every resource of the slot is
/// [`crate::graph::Resource::unfiltered`] and, unless `outputs` (a caller whose readers of the
/// outputs take buffers: the renderer's shading pass, [`super::Executor::set_output_buffers`]),
/// no requested output (which a host binds as a texture), the slot has one level, its format is
/// held bit for bit (`exec::buffers`), and its bytes fit one storage binding (else it stays a
/// texture). [`buffer_slots`] also asks the kernels that bind it.
pub fn slot_in_buffer(
    plan: &Plan,
    slot: usize,
    layout: KernelLayout,
    limits: &wgpu::Limits,
    outputs: bool,
) -> bool {
    let Some(s) = plan.slots.get(slot) else {
        return false;
    };
    let format = texture_format(s.format);
    let bytes = u64::from(s.width) * u64::from(s.height) * crate::graph::texel_bytes(format);
    layout.buffers_intermediates()
        && s.mips == 1
        && super::buffers::holds(format)
        && bytes
            <= limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size)
        && plan
            .resources
            .iter()
            .filter(|r| r.slot == Some(slot))
            .all(|r| r.resource.unfiltered && (outputs || !plan.outputs.contains(&r.resource.name)))
}

/// Per slot of `plan`, whether the executor holds it in a storage buffer in `layout` on a
/// device of `limits` (requested outputs too where `outputs`), each node's kernel the file
/// the layout compiles ([`KernelLayout::kernel_source`]) resolved with `sources` (replaced
/// kernels and the layout's redesigned modules): a slot of [`slot_in_buffer`] that every
/// kernel binding it uses only through `textureLoad`, `textureStore` and
/// `textureDimensions`, directly or in functions it passes the texture to (what
/// `exec::monomorph` and `exec::buffers` rewrite), and that no node binds by mip level
/// ([`Dispatch::Several`]).
pub fn buffer_slots(
    plan: &Plan,
    layout: KernelLayout,
    limits: &wgpu::Limits,
    sources: Option<&Replacements>,
    outputs: bool,
) -> Result<Vec<bool>> {
    let mut held: Vec<bool> = (0..plan.slots.len())
        .map(|i| slot_in_buffer(plan, i, layout, limits, outputs))
        .collect();
    if !held.contains(&true) {
        return Ok(held);
    }
    for step in &plan.steps {
        let node = &step.node;
        let file = layout.kernel_source(node.kernel.name());
        let wgsl = kernels::resolve_in(file, None, sources)?;
        let (_, reflection) = kernels::reflect(file, &wgsl)?;
        for (binding, resource) in bound(node, &reflection) {
            let Some(p) = plan.resource(resource) else {
                continue;
            };
            let Some(slot) = p.slot.filter(|&s| held.get(s).copied().unwrap_or(false)) else {
                continue;
            };
            let rewrites = !matches!(node.dispatch, Dispatch::Several(_))
                && reflection.binding(&binding).is_some_and(|b| {
                    let format = texture_format(p.resource.format);
                    super::pipelines::rewrites_to_buffer(
                        &wgsl,
                        &binding,
                        b.ty,
                        format,
                        [p.width, p.height],
                    )
                });
            if !rewrites {
                held[slot] = false;
            }
        }
    }
    Ok(held)
}

/// `(binding, resource)` of every binding `node` binds with the kernel `reflection` describes:
/// its inputs and outputs by name, and every write-only storage texture it leaves unnamed,
/// which the executor binds to its last output (`record::fill_outputs`).
fn bound<'n>(node: &'n Node, reflection: &Reflection) -> Vec<(String, &'n str)> {
    let mut out: Vec<(String, &str)> = node
        .inputs
        .iter()
        .chain(&node.outputs)
        .map(|(b, r)| (b.clone(), r.as_str()))
        .collect();
    if let Some((_, last)) = node.outputs.last() {
        for b in reflection.bindings.iter().filter(|b| b.group == 0) {
            let write_only = matches!(
                b.ty,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    ..
                }
            );
            if write_only && !out.iter().any(|(n, _)| *n == b.name) {
                out.push((b.name.clone(), last.as_str()));
            }
        }
    }
    out
}
