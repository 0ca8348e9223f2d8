//! What the executor relies on in a [`Plan`]: its fields are public, so a plan built or edited
//! by hand is checked before it is recorded, and a malformed one is a [`GraphError::BadPlan`]
//! rather than a panic on an index.

use std::collections::HashSet;

use super::{Dispatch, GraphError, Node, Plan, SubDispatch};

impl Plan {
    /// Checks every index and name the executor follows: resource slots in range and matching
    /// their slot's format and size, slots of a size and format it can allocate, unique
    /// resource names, every node's inputs, outputs and dispatch naming planned resources,
    /// the several dispatches of a node with their parameters and levels, and outputs that exist.
    pub fn check(&self) -> Result<(), GraphError> {
        let bad = |message: String| Err(GraphError::BadPlan(message));
        for (i, s) in self.slots.iter().enumerate() {
            let full = 32 - s.width.max(s.height).max(1).leading_zeros();
            if s.width == 0 || s.height == 0 || s.mips == 0 || s.mips > full {
                return bad(format!(
                    "slot {i} is {}×{} with {} mip level(s)",
                    s.width, s.height, s.mips
                ));
            }
            if crate::exec::wgsl_storage_format(super::texture_format(s.format)).is_err() {
                return bad(format!(
                    "slot {i} has format {:?}, not a storage format",
                    s.format
                ));
            }
        }
        let mut names = HashSet::new();
        for r in &self.resources {
            let name = &r.resource.name;
            if !names.insert(name.as_str()) {
                return bad(format!("resource `{name}` is listed twice"));
            }
            if let Some(s) = r.slot {
                let Some(slot) = self.slots.get(s) else {
                    return bad(format!(
                        "resource `{name}` lives in slot {s}, but the plan has {} slot(s)",
                        self.slots.len()
                    ));
                };
                if (slot.format, slot.width, slot.height, slot.mips)
                    != (r.resource.format, r.width, r.height, r.resource.mips)
                {
                    return bad(format!("resource `{name}` does not match its slot {s}"));
                }
            }
        }
        let known = |r: &str| names.contains(r);
        for (i, step) in self.steps.iter().enumerate() {
            self.check_step(i, &step.node, &known)?;
        }
        if let Some(o) = self.outputs.iter().find(|o| !known(o)) {
            return bad(format!("output `{o}` is not in the plan"));
        }
        Ok(())
    }

    /// Step `i`'s node `n` names only resources that are `known` and dispatches over one.
    fn check_step(
        &self,
        i: usize,
        n: &Node,
        known: &dyn Fn(&str) -> bool,
    ) -> Result<(), GraphError> {
        let bad = |message: String| {
            Err(GraphError::BadPlan(format!(
                "step {i} (`{}`) {message}",
                n.name
            )))
        };
        if let Some((_, r)) = n.inputs.iter().chain(&n.outputs).find(|(_, r)| !known(r)) {
            return bad(format!("uses `{r}`, which is not in the plan"));
        }
        if let Dispatch::Redesigned { shipped, redesign } = &n.dispatch {
            // Each as the node's dispatch.
            for d in [shipped, redesign] {
                if matches!(**d, Dispatch::Several(_) | Dispatch::Redesigned { .. }) {
                    return bad(
                        "has several dispatches, or a redesign in a redesign, in one layout".into(),
                    );
                }
                let one = Node {
                    dispatch: (**d).clone(),
                    ..n.clone()
                };
                self.check_step(i, &one, known)?;
            }
            return Ok(());
        }
        let mut dispatch = &n.dispatch;
        while let Dispatch::Layers { base, layers } | Dispatch::Interleaved { base, layers } =
            dispatch
        {
            if *layers == 0 || matches!(**base, Dispatch::Several(_)) {
                return bad("dispatches 0 layers, or several dispatches a layer".into());
            }
            dispatch = base;
        }
        let of = match dispatch {
            Dispatch::Layers { .. } | Dispatch::Interleaved { .. } => None,
            Dispatch::Redesigned { .. } => {
                return bad("dispatches layers of a dispatch with a redesign".into());
            }
            Dispatch::Texels(r) => Some(r),
            Dispatch::Tiles { x, y, cpu_y, .. } if *x == 0 || *y == 0 || *cpu_y == 0 => {
                return bad("dispatches tiles 0 texels wide or tall".into());
            }
            Dispatch::Blocks { of, .. } | Dispatch::Tiles { of, .. } => Some(of),
            Dispatch::Lines { per_group: 0, .. } => {
                return bad("dispatches lines with 0 per workgroup".into());
            }
            Dispatch::Lines { of, .. } => Some(of),
            Dispatch::Groups(_) => None,
            Dispatch::Several(subs) => {
                self.check_several(n, subs)?;
                None
            }
        };
        match of.filter(|r| !known(r)) {
            Some(r) => bad(format!("dispatches over `{r}`, which is not in the plan")),
            None => Ok(()),
        }
    }

    /// Each of a node's several dispatches reads parameter bytes the node has and binds levels
    /// that exist of resources of the node's slots.
    fn check_several(&self, n: &Node, subs: &[SubDispatch]) -> Result<(), GraphError> {
        let bad = |k: usize, message: String| {
            Err(GraphError::BadPlan(format!(
                "dispatch {k} of node `{}` {message}",
                n.name
            )))
        };
        for (k, d) in subs.iter().enumerate() {
            if d.params.start > d.params.end || n.params.get(d.params.clone()).is_none() {
                return bad(
                    k,
                    format!("reads parameter bytes {:?} of {}", d.params, n.params.len()),
                );
            }
            for v in &d.levels {
                let Some(r) = n.slot_resource(&v.slot) else {
                    return bad(
                        k,
                        format!("binds slot `{}`, which it does not have", v.slot),
                    );
                };
                let mips = self.resource(r).map_or(0, |p| p.resource.mips);
                if v.level >= mips {
                    return bad(
                        k,
                        format!("binds level {} of `{r}` ({mips} levels)", v.level),
                    );
                }
            }
        }
        Ok(())
    }
}
