//! The device limits the stage needs, checked before any pipeline is made so that a device
//! which cannot run it gets a named [`Error::Limit`] rather than a pipeline error. The kernels'
//! needs come from [`crate::limits`], shared with the renderer.

use crate::error::{Error, Result, StageError};
use crate::graph::Plan;

/// Checks the map size, every planned kernel and dispatch, and the plan's memory with the
/// stage's `other_bytes` (its other lights' textures) against the device's limits and the
/// memory budget ([`crate::limits::memory_budget`]).
pub(super) fn check(device: &wgpu::Device, plan: &Plan, size: u32, other_bytes: u64) -> Result<()> {
    let l = device.limits();
    // A device without compute shaders gets one message that says what to request, not the
    // first kernel's workgroup width against a limit of 0.
    let compute = [
        (
            "max_compute_workgroup_size_x",
            l.max_compute_workgroup_size_x,
        ),
        (
            "max_compute_invocations_per_workgroup",
            l.max_compute_invocations_per_workgroup,
        ),
        (
            "max_compute_workgroups_per_dimension",
            l.max_compute_workgroups_per_dimension,
        ),
    ];
    if let Some(&(limit, _)) = compute.iter().find(|(_, v)| *v == 0) {
        return Err(StageError::NoCompute { limit }.into());
    }
    let over = |what: String, requested: u64, limit: u64| {
        if requested > limit {
            Err(Error::Limit {
                what,
                requested,
                limit,
            })
        } else {
            Ok(())
        }
    };
    over(
        "map size (max_texture_dimension_2d)".into(),
        size.into(),
        l.max_texture_dimension_2d.into(),
    )?;
    if let Some(o) = crate::limits::plan_over(plan, &l)? {
        let what = if o.dispatch {
            format!("{} at map size {size}", o.what)
        } else {
            o.what
        };
        over(what, o.requested, o.limit)?;
    }
    over(
        format!(
            "the stage's textures at map size {size}, all its lights, in bytes (the memory \
             budget, {})",
            crate::limits::MEMORY_BUDGET_ENV
        ),
        plan.slot_bytes().saturating_add(other_bytes),
        crate::limits::memory_budget()?,
    )
}
