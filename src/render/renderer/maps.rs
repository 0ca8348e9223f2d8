//! The maps the shading pass binds: each a texture, or a storage buffer where the kernel layout
//! keeps a never-filtered output in one (a fixed-point summed-area table,
//! [`crate::exec::KernelLayout::buffers_intermediates`]), which the shading kernel then reads
//! through `exec::buffers`' rewrite of its loads.

use std::sync::Arc;

use super::{Renderer, ShadeBinding, ShadeInputs};
use crate::error::{Error, Result};
use crate::exec::{ComputeKernel, Outputs};
use crate::graph::texture_format;
use crate::render::ScenePlan;
use crate::render::cascade::DrawnLights;
use crate::render::targets::Targets;
use crate::technique;

/// One map the shading pass binds.
#[derive(Clone, PartialEq)]
pub(crate) enum ShadeMap {
    /// A texture (bound through a depth-only view where it is a depth texture).
    Texture(wgpu::Texture),
    /// A storage buffer of row-major texels.
    Buffer(wgpu::Buffer),
}

impl ShadeMap {
    /// Plan output `name` of a frame's `outputs`, wherever the executor holds it.
    pub(super) fn of(outputs: &Outputs, name: &str) -> Result<Self> {
        match (outputs.textures.get(name), outputs.buffers.get(name)) {
            (Some(t), _) => Ok(Self::Texture(t.clone())),
            (None, Some(b)) => Ok(Self::Buffer(b.buffer.clone())),
            (None, None) => Err(Error::Invalid(format!("the plan has no map `{name}`"))),
        }
    }

    /// What the shading pass binds for this map: a texture's (depth-only) view, or the
    /// buffer.
    fn bound(&self) -> Bound {
        match self {
            Self::Texture(t) => Bound::View(super::depth_only_view(t)),
            Self::Buffer(b) => Bound::Buffer(b.clone()),
        }
    }
}

/// A map as bound: the view made of its texture, or its buffer.
enum Bound {
    View(wgpu::TextureView),
    Buffer(wgpu::Buffer),
}

impl Bound {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        match self {
            Self::View(v) => wgpu::BindingResource::TextureView(v),
            Self::Buffer(b) => b.as_entire_binding(),
        }
    }
}

impl Renderer {
    /// The shading kernel for a frame of `sp` over the `drawn` lights: where the executor holds
    /// a light's map in a storage buffer ([`crate::exec::Executor::buffer_slots`]), its binding
    /// (`technique::map_binding`) re-declared as one, the kernel cached by the lights' key and
    /// those buffers.
    pub(super) fn frame_shade_kernel(
        &mut self,
        device: &wgpu::Device,
        drawn: &DrawnLights,
        sp: &ScenePlan,
    ) -> Result<Arc<ComputeKernel>> {
        let in_buffer = self.executor.buffer_slots(device, &sp.plan)?;
        let mut formats = Vec::new();
        let mut buffers = Vec::new();
        for (i, input) in sp.shade_inputs.iter().enumerate() {
            for (k, m) in input.maps.iter().enumerate() {
                let Some(p) = sp.plan.resource(m) else {
                    continue;
                };
                if p.slot.is_some_and(|s| in_buffer.get(s) == Some(&true)) {
                    let binding = technique::map_binding(i, k);
                    formats.push((binding.clone(), texture_format(p.resource.format)));
                    buffers.push((binding, [p.width, p.height]));
                }
            }
        }
        let groups = &drawn.groups;
        let key = if groups.is_empty() {
            technique::shade_key(&drawn.lights)
        } else {
            technique::shade_key_cascaded(&drawn.lights, groups)
        };
        let generated = || technique::shading_block_cascaded(&drawn.lights, groups);
        self.executor.kernels.get_keyed_buffers(
            device,
            (&key, "shade"),
            generated,
            &formats,
            &buffers,
        )
    }

    /// The shading pass's bind groups for `kernel` over `maps` (light by light, in binding
    /// order), made when either changed since the last frame.
    pub(super) fn shade_groups(
        &mut self,
        device: &wgpu::Device,
        kernel: &Arc<ComputeKernel>,
        targets: &Targets,
        maps: Vec<ShadeMap>,
    ) -> Result<&[wgpu::BindGroup; 2]> {
        let current = self
            .binding
            .as_ref()
            .is_some_and(|b| Arc::ptr_eq(&b.kernel, kernel) && b.maps == maps);
        if !current {
            let bound: Vec<Bound> = maps.iter().map(ShadeMap::bound).collect();
            let resources: Vec<wgpu::BindingResource> = bound.iter().map(Bound::resource).collect();
            let inputs = ShadeInputs {
                gpos: &targets.gpos_view,
                gnorm: &targets.gnorm_view,
                materials: &targets.materials,
                lights: &targets.light_data,
                frame: &targets.frame,
                color: &targets.color_view,
                visibility: &targets.visibility,
            };
            let groups = self.shade_bind_groups(device, kernel, &inputs, &resources)?;
            self.binding = Some(ShadeBinding {
                kernel: kernel.clone(),
                maps,
                groups,
            });
        }
        self.binding
            .as_ref()
            .map(|b| &b.groups)
            .ok_or_else(|| Error::Invalid("the shading pass is not bound".into()))
    }
}
