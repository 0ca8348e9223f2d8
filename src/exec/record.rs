//! Binding and recording: a step's pipeline and its dispatches (a bind group and workgroups
//! each) made once, then recorded as one compute pass per node. Nothing here knows a kernel,
//! a technique or a filter: a node binds its slots by name, or gives its dispatches as data
//! ([`Dispatch::Several`]).

use std::ops::Range;
use std::sync::Arc;

use super::pipelines::{ComputeKernel, KernelCache, no_layout};
use super::pool::{Outputs, STATS_STRIDE};
use super::{ExecError, Prepared};
use crate::error::{Error, Result};
use crate::gpu::scoped;
use crate::gpu_objects;
use crate::graph::{Dispatch, Node, Plan};
use crate::timer::GpuTimer;

/// One node's pipeline and its dispatches in one pass, each a bind group and workgroups.
pub(super) struct PreparedStep {
    pub(super) kernel: Arc<ComputeKernel>,
    pub(super) dispatches: Vec<(wgpu::BindGroup, [u32; 3])>,
}

/// What one dispatch of a node binds, before the textures are known.
struct Spec<'n> {
    /// `(binding, resource, mip level)`: one level, or the whole texture for `None`.
    views: Vec<(String, &'n str, Option<u32>)>,
    /// Workgroups, when the node gives them (else counted from the bound sizes).
    groups: Option<[u32; 3]>,
}

/// The parameter bytes of each dispatch of `node`: all of them for one dispatch, each
/// [`Dispatch::Several`]'s own.
pub(super) fn param_ranges(node: &Node) -> Vec<Range<usize>> {
    match &node.dispatch {
        Dispatch::Several(subs) => subs.iter().map(|d| d.params.clone()).collect(),
        #[expect(
            clippy::single_range_in_vec_init,
            reason = "one dispatch: a list of one range of bytes"
        )]
        _ => vec![0..node.params.len()],
    }
}

/// The dispatches `node` records with `kernel`: one binding the node's slots by name, or each
/// of its [`Dispatch::Several`] with the levels it names.
fn specs<'n>(kernel: &ComputeKernel, node: &'n Node) -> Result<Vec<Spec<'n>>> {
    let Dispatch::Several(subs) = &node.dispatch else {
        let slots = node.inputs.iter().chain(&node.outputs);
        let mut views: Vec<_> = slots.map(|(s, r)| (s.clone(), r.as_str(), None)).collect();
        let last = node.outputs.last().map(|(_, r)| (r.as_str(), None));
        fill_outputs(kernel, &mut views, last);
        return Ok(vec![Spec {
            views,
            groups: None,
        }]);
    };
    subs.iter()
        .map(|d| {
            let mut views = Vec::new();
            for v in &d.levels {
                let r = node
                    .slot_resource(&v.slot)
                    .ok_or_else(|| ExecError::Unbound {
                        node: node.name.clone(),
                        binding: v.slot.clone(),
                    })?;
                views.push((v.binding.clone(), r, Some(v.level)));
            }
            let last = views.last().map(|(_, r, l)| (*r, *l));
            fill_outputs(kernel, &mut views, last);
            Ok(Spec {
                views,
                groups: Some(d.groups),
            })
        })
        .collect()
}

/// Binds every write-only storage binding of `kernel` that `views` leaves unbound to `last`
/// (the node's last output, or a dispatch's last level): a kernel may declare more outputs than
/// a dispatch writes (`kernels/csm.wgsl` writes up to four maps from one read of the depth, a
/// mip-chain dispatch up to six levels); it does not store through those, and the cost model
/// does not count them.
fn fill_outputs<'n>(
    kernel: &ComputeKernel,
    views: &mut Vec<(String, &'n str, Option<u32>)>,
    last: Option<(&'n str, Option<u32>)>,
) {
    let Some((resource, level)) = last else {
        return;
    };
    for b in kernel.reflection.bindings.iter().filter(|b| b.group == 0) {
        let write_only = matches!(
            b.ty,
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                ..
            }
        );
        if write_only && !views.iter().any(|(s, ..)| *s == b.name) {
            views.push((b.name.clone(), resource, level));
        }
    }
}

/// The storage formats a node's first dispatch binds, by binding: what its pipeline is
/// specialized for ([`KernelCache::get_specialized`]).
fn bound_formats(
    specs: &[Spec<'_>],
    format: impl Fn(&str) -> Option<wgpu::TextureFormat>,
) -> Vec<(String, wgpu::TextureFormat)> {
    specs
        .first()
        .map(|s| {
            s.views
                .iter()
                .filter_map(|(b, r, _)| format(r).map(|f| (b.clone(), f)))
                .collect()
        })
        .unwrap_or_default()
}

/// The bindings of a node's first dispatch bound to resources held in storage buffers, with
/// their maps' `[width, height]`: what its pipeline is specialized for (`exec::buffers`).
fn bound_buffers(
    specs: &[Spec<'_>],
    size: impl Fn(&str) -> Option<[u32; 2]>,
) -> Vec<(String, [u32; 2])> {
    specs
        .first()
        .map(|s| {
            s.views
                .iter()
                .filter_map(|(b, r, _)| size(r).map(|wh| (b.clone(), wh)))
                .collect()
        })
        .unwrap_or_default()
}

/// Compiles `node`'s pipeline for the formats `plan` binds, and the storage buffers it binds
/// (`in_buffer`: per slot, [`super::buffer_slots`]): what [`bind_step`] will ask for.
pub(super) fn compile(
    kernels: &mut KernelCache,
    device: &wgpu::Device,
    plan: &Plan,
    in_buffer: &[bool],
    node: &Node,
) -> Result<()> {
    let base = kernels.get(device, node.kernel.name())?;
    let specs = specs(&base, node)?;
    let formats = bound_formats(&specs, |r| {
        plan.resource(r)
            .map(|p| crate::graph::texture_format(p.resource.format))
    });
    let buffers = bound_buffers(&specs, |r| {
        let p = plan.resource(r)?;
        let slot = p.slot?;
        in_buffer
            .get(slot)
            .copied()
            .unwrap_or(false)
            .then_some([p.width, p.height])
    });
    let overrides = kernels.node_constants(node.kernel.name(), &node.name, &node.params)?;
    kernels.get_for_node(device, node.kernel.name(), &formats, &buffers, &overrides)?;
    Ok(())
}

/// The buffers a step's bind groups point into: the run's parameters (`at`: each dispatch's
/// `(offset, size)` there) and its counters (`step`: the step's index).
pub(super) struct StepBuffers<'a> {
    pub(super) params: &'a wgpu::Buffer,
    pub(super) at: &'a [(u64, u64)],
    pub(super) outputs: &'a Outputs,
    pub(super) step: usize,
}

/// A node's pipeline and its dispatches, bound to the run's textures and buffers.
pub(super) fn bind_step(
    kernels: &mut KernelCache,
    device: &wgpu::Device,
    node: &Node,
    buffers: &StepBuffers<'_>,
) -> Result<PreparedStep> {
    let outputs = buffers.outputs;
    let base = kernels.get(device, node.kernel.name())?;
    let specs = specs(&base, node)?;
    let formats = bound_formats(&specs, |r| match outputs.textures.get(r) {
        Some(t) => Some(t.format()),
        None => outputs
            .buffers
            .get(r)
            .map(|b| crate::graph::texture_format(b.format)),
    });
    let in_buffers = bound_buffers(&specs, |r| {
        outputs.buffers.get(r).map(|b| [b.width, b.height])
    });
    let overrides = kernels.node_constants(node.kernel.name(), &node.name, &node.params)?;
    let kernel = kernels.get_for_node(
        device,
        node.kernel.name(),
        &formats,
        &in_buffers,
        &overrides,
    )?;
    // A node dispatched by texels covers `TEXELS_X` texels an invocation (its workgroups'
    // footprint); any other dispatch follows the node's geometry, which does not read it: a
    // kernel (a `SHADOWGRAPH_KERNEL_DIR` variant) declaring it there would cover the wrong texels.
    let by_texels = matches!(node.dispatch, crate::graph::Dispatch::Texels(_));
    if kernel.reflection.texels_x != 1 && !by_texels {
        return Err(Error::Kernel {
            kernel: node.kernel.name().to_string(),
            message: format!(
                "declares `{}`, which only the shading kernel's dispatch and nodes dispatched \
                 by texels read",
                crate::kernels::TEXELS_X_CONSTANT
            ),
        });
    }
    let wg = kernel.reflection.workgroup_size.unwrap_or([1, 1, 1]);
    let footprint = kernel.reflection.texel_footprint();
    // A line an invocation: the node counts its lines a workgroup, which must be the kernel's
    // workgroup (a variant with another would leave lines out or run past them).
    if let Some(per_group) = node
        .dispatch
        .lines_per_group_in(kernel.layout.is_redesign())
        && per_group != wg[0]
    {
        return Err(Error::Kernel {
            kernel: node.kernel.name().to_string(),
            message: format!(
                "node `{}` dispatches {per_group} lines a workgroup, but the kernel's workgroup \
                 is {} invocations",
                node.name, wg[0]
            ),
        });
    }
    let size = |r: &str| outputs.size(r);
    let mut dispatches = Vec::new();
    for (k, spec) in specs.iter().enumerate() {
        let at = buffers
            .at
            .get(k)
            .copied()
            .ok_or_else(|| ExecError::Params {
                node: node.name.clone(),
            })?;
        let bind_group = bind_group(device, node, &kernel, spec, buffers, at)?;
        let groups = match spec.groups {
            Some(g) => g,
            None => node
                .dispatch
                .groups_in(
                    size,
                    footprint,
                    kernel.layout.is_gpu(),
                    kernel.layout.is_redesign(),
                )
                .ok_or_else(|| ExecError::DispatchOver {
                    node: node.name.clone(),
                })?,
        };
        dispatches.push((bind_group, groups));
    }
    Ok(PreparedStep { kernel, dispatches })
}

/// The bind group of one dispatch: its views, its parameters at `(offset, size)` and the
/// step's counter.
fn bind_group(
    device: &wgpu::Device,
    node: &Node,
    kernel: &ComputeKernel,
    spec: &Spec<'_>,
    buffers: &StepBuffers<'_>,
    (offset, size): (u64, u64),
) -> Result<wgpu::BindGroup> {
    let mut views: Vec<(u32, wgpu::TextureView)> = Vec::new();
    let mut held: Vec<(u32, &wgpu::Buffer)> = Vec::new();
    for b in kernel.reflection.bindings.iter().filter(|b| b.group == 0) {
        if let Some((_, r, level)) = spec.views.iter().find(|(n, ..)| *n == b.name) {
            if let Some(m) = buffers.outputs.buffers.get(*r) {
                held.push((b.binding, &m.buffer));
                continue;
            }
            let t = buffers
                .outputs
                .textures
                .get(*r)
                .ok_or_else(|| ExecError::NoTexture {
                    node: node.name.clone(),
                    resource: r.to_string(),
                })?;
            let layer = buffers.outputs.layers.get(*r).copied();
            views.push((b.binding, texture_view(node, t, *level, layer)?));
        } else if b.name != "params" && b.name != "stats" {
            return Err(ExecError::Unbound {
                node: node.name.clone(),
                binding: b.name.clone(),
            }
            .into());
        }
    }
    let mut entries: Vec<wgpu::BindGroupEntry> = views
        .iter()
        .map(|(binding, view)| wgpu::BindGroupEntry {
            binding: *binding,
            resource: wgpu::BindingResource::TextureView(view),
        })
        .collect();
    for (binding, buffer) in held {
        entries.push(wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        });
    }
    if let Some(b) = kernel.reflection.binding("params") {
        let size = size.div_ceil(16) * 16;
        entries.push(buffer_entry(b.binding, buffers.params, offset, size));
    }
    if let Some(b) = kernel.reflection.binding("stats") {
        let at = buffers.step as u64 * STATS_STRIDE;
        entries.push(buffer_entry(b.binding, &buffers.outputs.stats, at, 4));
    }
    let layout = kernel
        .layouts
        .first()
        .ok_or_else(|| no_layout(&kernel.name))?;
    let descriptor = wgpu::BindGroupDescriptor {
        label: Some(&node.name),
        layout,
        entries: &entries,
    };
    scoped(
        device,
        || gpu_objects::bind_group(device, &descriptor),
        |message| Error::Pipeline {
            kernel: node.kernel.to_string(),
            message: format!("binding node `{}`: {message}", node.name),
        },
    )
}

/// A view of all of `t` (`level` `None`) or of its one mip level `level`, of its one array
/// layer `layer` (as a 2-D view) where given; the depth aspect for a depth texture.
fn texture_view(
    node: &Node,
    t: &wgpu::Texture,
    level: Option<u32>,
    layer: Option<u32>,
) -> Result<wgpu::TextureView> {
    if let Some(l) = level.filter(|&l| l >= t.mip_level_count()) {
        return Err(ExecError::NoLevel {
            node: node.name.clone(),
            level: l,
            levels: t.mip_level_count(),
        }
        .into());
    }
    Ok(gpu_objects::view(
        t,
        &wgpu::TextureViewDescriptor {
            aspect: if t.format().is_depth_stencil_format() {
                wgpu::TextureAspect::DepthOnly
            } else {
                wgpu::TextureAspect::All
            },
            base_mip_level: level.unwrap_or(0),
            mip_level_count: level.map(|_| 1),
            dimension: layer.map(|_| wgpu::TextureViewDimension::D2),
            base_array_layer: layer.unwrap_or(0),
            array_layer_count: layer.map(|_| 1),
            ..Default::default()
        },
    ))
}

/// A bind group entry of `size` bytes of `buffer` from `offset`.
fn buffer_entry(
    binding: u32,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset,
            size: wgpu::BufferSize::new(size),
        }),
    }
}

/// One uniform buffer of every dispatch's parameters, each at an offset aligned for binding.
pub(super) struct RunParams {
    /// The buffer.
    pub(super) buffer: wgpu::Buffer,
    /// Per step, per dispatch, its `(offset, size)` in the buffer.
    pub(super) at: Vec<Vec<(u64, u64)>>,
}

/// The parameters of every dispatch of `plan` in one buffer.
pub(super) fn params_buffer(device: &wgpu::Device, plan: &Plan) -> Result<RunParams> {
    let align = u64::from(device.limits().min_uniform_buffer_offset_alignment).max(16);
    let mut bytes = Vec::new();
    let mut at = Vec::new();
    for step in &plan.steps {
        let mut step_at = Vec::new();
        for range in param_ranges(&step.node) {
            let params = step
                .node
                .params
                .get(range)
                .ok_or_else(|| ExecError::Params {
                    node: step.node.name.clone(),
                })?;
            let offset = (bytes.len() as u64).div_ceil(align) * align;
            bytes.resize(offset as usize, 0);
            step_at.push((offset, params.len().max(16) as u64));
            bytes.extend_from_slice(params);
        }
        at.push(step_at);
    }
    // Room for the last binding's size rounded up to 16 bytes.
    bytes.resize(bytes.len().max(16).div_ceil(16) * 16 + 16, 0);
    let buffer = gpu_objects::buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("shadowgraph.params"),
            contents: &bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    Ok(RunParams { buffer, at })
}

/// Records the passes of a prepared plan: one compute pass per node (each node `run` marks,
/// all without it), a span of `timer` each. Returns the dispatches recorded.
pub(super) fn encode(
    encoder: &mut wgpu::CommandEncoder,
    prepared: &Prepared,
    run: Option<&[bool]>,
    mut timer: Option<&mut GpuTimer>,
) -> u64 {
    let mut dispatches = 0;
    encoder.clear_buffer(&prepared.outputs.stats, 0, None);
    for (k, (step, bound)) in prepared.plan.steps.iter().zip(&prepared.steps).enumerate() {
        if run.is_some_and(|r| !r.get(k).copied().unwrap_or(true)) {
            continue;
        }
        let node = &step.node;
        if let Some(t) = timer.as_deref_mut() {
            t.begin(encoder, &node.name);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(&node.name),
            timestamp_writes: None,
        });
        pass.set_pipeline(&bound.kernel.pipeline);
        for (bind_group, g) in &bound.dispatches {
            pass.set_bind_group(0, bind_group, &[]);
            pass.dispatch_workgroups(g[0], g[1], g[2]);
            dispatches += 1;
        }
    }
    dispatches
}
