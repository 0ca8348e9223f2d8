//! The planner: prune to what the outputs need, order deterministically, assign lifetimes and
//! reuse textures whose last use has passed.

use std::collections::{BTreeSet, HashMap, HashSet};

use super::{Graph, GraphError, Node, Resource, SizeRule, block_count, texel_bytes};

/// One step of a plan: a node to run, in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// The node.
    pub node: Node,
}

/// A resource as the plan sees it: concrete size, lifetime and the texture slot it lives in.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedResource {
    /// The declared resource.
    pub resource: Resource,
    /// Concrete width.
    pub width: u32,
    /// Concrete height.
    pub height: u32,
    /// Bytes over all mip levels.
    pub bytes: u64,
    /// Step that writes it (`None` for imports).
    pub producer: Option<usize>,
    /// Last step that reads it; `steps.len()` for requested outputs (live to the end).
    pub last_use: usize,
    /// Texture slot (`None` for imports).
    pub slot: Option<usize>,
}

/// A physical texture shared by resources whose lifetimes do not overlap.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Slot {
    /// Texel format.
    pub format: wgpu::TextureFormat,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Mip levels.
    pub mips: u32,
}

/// An ordered, pruned graph with lifetimes and texture assignment.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Nodes in execution order.
    pub steps: Vec<Step>,
    /// Every resource the steps or outputs touch, in first-use order.
    pub resources: Vec<PlannedResource>,
    /// Physical textures the executor allocates.
    pub slots: Vec<Slot>,
    /// The requested outputs.
    pub outputs: Vec<String>,
}

impl Plan {
    /// The planned resource named `name`.
    pub fn resource(&self, name: &str) -> Option<&PlannedResource> {
        self.resources.iter().find(|r| r.resource.name == name)
    }

    /// The same plan with a texture of its own for every resource, so that every resource is
    /// still intact when the frame ends (for dumps; the planner otherwise reuses a texture once
    /// its resource's last reader ran).
    pub fn unaliased(mut self) -> Plan {
        self.slots.clear();
        for r in self.resources.iter_mut().filter(|r| r.slot.is_some()) {
            self.slots.push(Slot {
                format: r.resource.format,
                width: r.width,
                height: r.height,
                mips: r.resource.mips,
            });
            r.slot = Some(self.slots.len() - 1);
        }
        self
    }

    /// Bytes of all slots: the texture memory the executor allocates for this plan.
    pub fn slot_bytes(&self) -> u64 {
        self.slots.iter().map(slot_bytes).sum()
    }

    /// Largest sum of bytes of resources alive at once (imports excluded).
    pub fn peak_live_bytes(&self) -> u64 {
        (0..=self.steps.len())
            .map(|t| {
                self.resources
                    .iter()
                    .filter(|r| r.slot.is_some())
                    .filter(|r| r.producer.is_some_and(|p| p <= t) && r.last_use >= t)
                    .map(|r| r.bytes)
                    .sum::<u64>()
            })
            .max()
            .unwrap_or(0)
    }
}

fn slot_bytes(s: &Slot) -> u64 {
    (0..s.mips)
        .map(|m| u64::from((s.width >> m).max(1)) * u64::from((s.height >> m).max(1)))
        .sum::<u64>()
        * texel_bytes(s.format)
}

/// Plans `graph` for the requested `outputs`: keeps only nodes those outputs need, orders them
/// (dependencies first, ties broken by declaration order), and assigns texture slots.
pub fn plan(graph: &Graph, outputs: &[&str]) -> Result<Plan, GraphError> {
    let index = check_names(graph)?;
    let producers = producers(graph, &index)?;
    let needed = needed_nodes(graph, outputs, &index, &producers)?;
    let order = order(graph, &needed, &producers)?;
    let steps: Vec<Step> = order
        .iter()
        .map(|&n| Step {
            node: graph.nodes[n].clone(),
        })
        .collect();
    let resources = lifetimes(graph, &steps, outputs, &index)?;
    let (resources, slots) = assign_slots(resources, steps.len());
    Ok(Plan {
        steps,
        resources,
        slots,
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
    })
}

fn check_names(graph: &Graph) -> Result<HashMap<&str, usize>, GraphError> {
    let mut index = HashMap::new();
    for (i, r) in graph.resources.iter().enumerate() {
        if index.insert(r.name.as_str(), i).is_some() {
            return Err(GraphError::DuplicateName(r.name.clone()));
        }
    }
    let mut nodes = HashSet::new();
    for n in &graph.nodes {
        if !nodes.insert(n.name.as_str()) {
            return Err(GraphError::DuplicateName(n.name.clone()));
        }
        for (_, r) in n.inputs.iter().chain(&n.outputs) {
            if !index.contains_key(r.as_str()) {
                return Err(GraphError::UnknownResource {
                    node: n.name.clone(),
                    resource: r.clone(),
                });
            }
        }
    }
    Ok(index)
}

fn producers<'g>(
    graph: &'g Graph,
    index: &HashMap<&str, usize>,
) -> Result<HashMap<&'g str, usize>, GraphError> {
    let mut producers: HashMap<&str, usize> = HashMap::new();
    for (ni, n) in graph.nodes.iter().enumerate() {
        for (_, r) in &n.outputs {
            if graph.resources[index[r.as_str()]].imported {
                return Err(GraphError::WritesImport {
                    node: n.name.clone(),
                    resource: r.clone(),
                });
            }
            if let Some(&first) = producers.get(r.as_str()) {
                return Err(GraphError::DuplicateProducer {
                    resource: r.clone(),
                    first: graph.nodes[first].name.clone(),
                    second: n.name.clone(),
                });
            }
            producers.insert(r.as_str(), ni);
        }
    }
    Ok(producers)
}

/// Walks back from the outputs; returns the set of needed node indices. Detects cycles.
fn needed_nodes(
    graph: &Graph,
    outputs: &[&str],
    index: &HashMap<&str, usize>,
    producers: &HashMap<&str, usize>,
) -> Result<BTreeSet<usize>, GraphError> {
    let mut walk = Walk {
        graph,
        index,
        producers,
        marks: HashMap::new(),
        stack: Vec::new(),
    };
    for out in outputs {
        if !index.contains_key(out) {
            return Err(GraphError::UnknownOutput(out.to_string()));
        }
        walk.need(out, "the outputs")?;
    }
    Ok(walk.marks.keys().copied().collect())
}

/// A node's state in the depth-first walk of [`needed_nodes`].
#[derive(Clone, Copy, PartialEq)]
enum Mark {
    Active,
    Done,
}

/// The depth-first walk from the outputs to the nodes they need (a node on the stack met
/// again is a cycle).
struct Walk<'a> {
    graph: &'a Graph,
    index: &'a HashMap<&'a str, usize>,
    producers: &'a HashMap<&'a str, usize>,
    marks: HashMap<usize, Mark>,
    stack: Vec<usize>,
}

impl Walk<'_> {
    /// Marks the producer of `resource` (needed by `needed_by`) and everything it needs.
    fn need(&mut self, resource: &str, needed_by: &str) -> Result<(), GraphError> {
        let graph = self.graph;
        if graph.resources[self.index[resource]].imported {
            return Ok(());
        }
        let Some(&node) = self.producers.get(resource) else {
            return Err(GraphError::MissingProducer {
                resource: resource.to_string(),
                needed_by: needed_by.to_string(),
            });
        };
        match self.marks.get(&node) {
            Some(Mark::Done) => return Ok(()),
            Some(Mark::Active) => {
                let start = self.stack.iter().position(|&n| n == node).unwrap_or(0);
                let mut cycle: Vec<String> = self.stack[start..]
                    .iter()
                    .map(|&n| graph.nodes[n].name.clone())
                    .collect();
                cycle.push(graph.nodes[node].name.clone());
                return Err(GraphError::Cycle(cycle));
            }
            None => {}
        }
        self.marks.insert(node, Mark::Active);
        self.stack.push(node);
        let n = &graph.nodes[node];
        for (_, input) in &n.inputs {
            self.need(input, &n.name)?;
        }
        self.stack.pop();
        self.marks.insert(node, Mark::Done);
        Ok(())
    }
}

/// Kahn's algorithm over the needed nodes, always taking the earliest-declared ready node.
fn order(
    graph: &Graph,
    needed: &BTreeSet<usize>,
    producers: &HashMap<&str, usize>,
) -> Result<Vec<usize>, GraphError> {
    let deps = |n: usize| -> BTreeSet<usize> {
        graph.nodes[n]
            .inputs
            .iter()
            .filter_map(|(_, r)| producers.get(r.as_str()).copied())
            .filter(|p| needed.contains(p))
            .collect()
    };
    let mut remaining: HashMap<usize, BTreeSet<usize>> =
        needed.iter().map(|&n| (n, deps(n))).collect();
    let mut order = Vec::with_capacity(needed.len());
    while !remaining.is_empty() {
        let ready = remaining
            .iter()
            .filter(|(_, d)| d.is_empty())
            .map(|(&n, _)| n)
            .min();
        let Some(next) = ready else {
            // Unreachable after needed_nodes' cycle check, kept as a typed error, not a panic.
            let names = remaining
                .keys()
                .map(|&n| graph.nodes[n].name.clone())
                .collect();
            return Err(GraphError::Cycle(names));
        };
        remaining.remove(&next);
        for d in remaining.values_mut() {
            d.remove(&next);
        }
        order.push(next);
    }
    Ok(order)
}

impl Graph {
    /// The size of resource `name` by its size rule, as the planner resolves it (the sizes a
    /// node's dispatches depend on are known while the graph is built).
    pub fn size(&self, name: &str) -> Result<(u32, u32), GraphError> {
        let index: HashMap<&str, usize> = self
            .resources
            .iter()
            .enumerate()
            .map(|(i, r)| (r.name.as_str(), i))
            .collect();
        let r = index.get(name).ok_or_else(|| GraphError::BadSize {
            resource: name.to_string(),
            message: "not declared".into(),
        })?;
        resolve_size(self, &index, &self.resources[*r], 0)
    }
}

fn resolve_size(
    graph: &Graph,
    index: &HashMap<&str, usize>,
    r: &Resource,
    depth: usize,
) -> Result<(u32, u32), GraphError> {
    let bad = |m: &str| GraphError::BadSize {
        resource: r.name.clone(),
        message: m.to_string(),
    };
    if depth > graph.resources.len() {
        return Err(bad("size rules form a cycle"));
    }
    match &r.size {
        SizeRule::Fixed { width, height } => Ok((*width, *height)),
        SizeRule::Reduced { of, shift } => {
            let (w, h) = resolve_base(graph, index, of, depth, &bad)?;
            let reduce = |v: u32| {
                v.div_ceil(1u32.checked_shl(*shift).unwrap_or(u32::MAX))
                    .max(1)
            };
            Ok((reduce(w), reduce(h)))
        }
        SizeRule::Blocks { of, x, y } => {
            let (w, h) = resolve_base(graph, index, of, depth, &bad)?;
            Ok((block_count(w, *x), block_count(h, *y)))
        }
        SizeRule::Stacked {
            of,
            x,
            y,
            across,
            down,
        } => {
            let (w, h) = resolve_base(graph, index, of, depth, &bad)?;
            let times = |n: u32, k: u32| {
                n.checked_mul(k)
                    .filter(|&v| v > 0)
                    .ok_or_else(|| bad(&format!("{n} blocks × {k} copies")))
            };
            Ok((
                times(block_count(w, *x), *across)?,
                times(block_count(h, *y), *down)?,
            ))
        }
    }
}

/// The size of `of`, the resource a size rule follows.
fn resolve_base(
    graph: &Graph,
    index: &HashMap<&str, usize>,
    of: &str,
    depth: usize,
    bad: &dyn Fn(&str) -> GraphError,
) -> Result<(u32, u32), GraphError> {
    let base = index
        .get(of)
        .ok_or_else(|| bad(&format!("follows undeclared resource `{of}`")))?;
    resolve_size(graph, index, &graph.resources[*base], depth + 1)
}

fn lifetimes(
    graph: &Graph,
    steps: &[Step],
    outputs: &[&str],
    index: &HashMap<&str, usize>,
) -> Result<Vec<PlannedResource>, GraphError> {
    let mut planned: Vec<PlannedResource> = Vec::new();
    let mut at: HashMap<String, usize> = HashMap::new();
    let mut touch = |name: &str, step: Option<usize>, writes: bool| -> Result<(), GraphError> {
        let i = match at.get(name) {
            Some(&i) => i,
            None => {
                let mut r = graph.resources[index[name]].clone();
                let (width, height) = resolve_size(graph, index, &r, 0)?;
                if r.mips == 0 {
                    r.mips = 32 - width.max(height).max(1).leading_zeros();
                }
                let slot = Slot {
                    format: r.format,
                    width,
                    height,
                    mips: r.mips,
                };
                planned.push(PlannedResource {
                    resource: r,
                    width,
                    height,
                    bytes: slot_bytes(&slot),
                    producer: None,
                    last_use: 0,
                    slot: None,
                });
                at.insert(name.to_string(), planned.len() - 1);
                planned.len() - 1
            }
        };
        let p = &mut planned[i];
        let s = step.unwrap_or(steps.len());
        if writes {
            p.producer = Some(s);
        }
        p.last_use = p.last_use.max(s);
        Ok(())
    };
    for (s, step) in steps.iter().enumerate() {
        for (_, r) in &step.node.inputs {
            touch(r, Some(s), false)?;
        }
        for (_, r) in &step.node.outputs {
            touch(r, Some(s), true)?;
        }
    }
    for out in outputs {
        touch(out, None, false)?;
    }
    Ok(planned)
}

/// Greedy slot assignment: a resource takes a free slot of identical shape, else a new one.
/// A slot frees after the step of its resource's last use, so a step never reads and writes
/// the same texture.
fn assign_slots(
    mut resources: Vec<PlannedResource>,
    step_count: usize,
) -> (Vec<PlannedResource>, Vec<Slot>) {
    let mut slots: Vec<Slot> = Vec::new();
    let mut free: Vec<usize> = Vec::new();
    for step in 0..step_count {
        for r in resources.iter_mut() {
            if r.producer != Some(step) || r.resource.imported {
                continue;
            }
            let shape = Slot {
                format: r.resource.format,
                width: r.width,
                height: r.height,
                mips: r.resource.mips,
            };
            let reuse = free.iter().position(|&s| slots[s] == shape);
            r.slot = Some(match reuse {
                Some(i) => free.remove(i),
                None => {
                    slots.push(shape);
                    slots.len() - 1
                }
            });
        }
        for r in resources.iter() {
            if r.last_use == step {
                if let Some(s) = r.slot {
                    free.push(s);
                }
            }
        }
    }
    (resources, slots)
}
