//! The device limits the stage needs, checked before any pipeline is made so that a device
//! which cannot run it gets a named [`Error::Limit`] rather than a pipeline error. The kernels'
//! needs come from [`crate::limits`], shared with the renderer.

use crate::error::{Error, Result};
use crate::graph::Plan;

/// Checks the map size, every planned kernel and dispatch, and the plan's memory against the
/// device's limits and the memory budget ([`crate::limits::memory_budget`]).
pub(super) fn check(device: &wgpu::Device, plan: &Plan, size: u32) -> Result<()> {
    let l = device.limits();
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
            "the stage's textures at map size {size}, in bytes (the memory budget, {})",
            crate::limits::MEMORY_BUDGET_ENV
        ),
        plan.slot_bytes(),
        crate::limits::memory_budget()?,
    )
}
