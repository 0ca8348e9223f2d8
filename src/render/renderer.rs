//! The renderer: per light a depth-only raster pass, the planned kernels, the camera G-buffer
//! and the generated shading kernel, recorded into one encoder per frame. Pipelines are made
//! once (the shading kernel's looked up by [`technique::shade_key`]); textures, buffers and
//! bind groups once per scene shape ([`super::targets`]); the executor keeps its plan's; the
//! timer's readbacks are read a frame later. A frame after the first creates nothing.

use std::collections::HashMap;
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::gpu::{scoped, submit_and_wait};
use crate::gpu_objects;
use crate::technique;
use crate::{
    exec::{ComputeKernel, Executor, Outputs},
    timer::GpuTimer,
};
use crate::{model::Light, scene::Scene};

mod maps;
mod raster;

pub(super) use maps::ShadeMap;
pub use raster::ShadowRaster;
pub(super) use raster::VIEW_BYTES;
pub(super) use raster::depth_only_view;
use raster::{clear_depth, raster_pass};

use super::cache::{LightCache, caches, dedicate_outputs};
use super::cascade::{DrawnLights, drawn_lights};
use super::targets::{TargetKey, Targets};
use super::{Frame, RenderOptions, ScenePlan, check_render, plan_lights_for};

/// Renders scenes; holds pipelines, pooled textures and a frame's resources across frames.
pub struct Renderer {
    /// The graph executor (kernel pipelines, texture pool).
    pub executor: Executor,
    /// Raster pipelines by slope-scaled bias (pipeline state), with their layout.
    shadow: HashMap<u32, (wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    /// Peel pipelines (second depth) by slope-scaled bias, with their layout.
    peel: HashMap<u32, (wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    gbuffer: Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    cmp_sampler: wgpu::Sampler,
    /// Linear, clamped to the edge: f32 tables' filtered corner fetches.
    sat_sampler: wgpu::Sampler,
    /// The last scene shape's resources.
    targets: Option<Targets>,
    /// The shading pass's bind groups for the last kernel and maps.
    binding: Option<ShadeBinding>,
    timer: Option<GpuTimer>,
    /// Which lights' maps are kept from earlier frames ([`super::cache`]).
    cache: LightCache,
}

/// The shading pass's bind groups, valid for one kernel, one set of map textures and the
/// targets they were made with.
struct ShadeBinding {
    kernel: Arc<ComputeKernel>,
    maps: Vec<ShadeMap>,
    groups: [wgpu::BindGroup; 2],
}

/// What one frame records from: the plan, the kept resources, the drawn lights, the shading
/// kernel and which lights it redraws.
struct FrameInputs<'a> {
    sp: &'a ScenePlan,
    targets: &'a Targets,
    lights: &'a [Light],
    kernel: &'a Arc<ComputeKernel>,
    redraw: &'a [bool],
}

/// The shading pass's group-0 inputs and outputs (the sampler is the renderer's).
pub(super) struct ShadeInputs<'a> {
    pub gpos: &'a wgpu::TextureView,
    pub gnorm: &'a wgpu::TextureView,
    pub materials: &'a wgpu::Buffer,
    pub lights: &'a wgpu::Buffer,
    pub frame: &'a wgpu::Buffer,
    pub color: &'a wgpu::TextureView,
    pub visibility: &'a wgpu::Buffer,
}

impl Renderer {
    /// A renderer for `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        // The shading kernel reads the tables that the layout keeps in buffers from them.
        let mut executor = Executor::new();
        executor.set_output_buffers(true);
        Self {
            executor,
            shadow: HashMap::new(),
            peel: HashMap::new(),
            gbuffer: None,
            targets: None,
            binding: None,
            timer: None,
            cache: LightCache::default(),
            cmp_sampler: gpu_objects::sampler(
                device,
                &wgpu::SamplerDescriptor {
                    label: Some("shadowgraph.cmp_sampler"),
                    mag_filter: wgpu::FilterMode::Linear,
                    min_filter: wgpu::FilterMode::Linear,
                    compare: Some(wgpu::CompareFunction::LessEqual),
                    ..Default::default()
                },
            ),
            sat_sampler: gpu_objects::sampler(device, &crate::prefilter::SAT_SAMPLER_DESCRIPTOR),
        }
    }

    /// The kept resources for `scene` (made anew when its shape changed), taken out of the
    /// renderer for the frame (put back by [`Renderer::render`]).
    fn take_targets(
        &mut self,
        device: &wgpu::Device,
        scene: &Scene,
        drawn: &DrawnLights,
        vertices: usize,
    ) -> Result<Targets> {
        let key = TargetKey::new(scene, drawn, vertices);
        if let Some(t) = self.targets.take().filter(|t| t.key == key) {
            return Ok(t);
        }
        // The shading bind groups refer to the old targets; both go before new ones are made.
        self.binding = None;
        let mut raster_layouts = Vec::new();
        for l in &drawn.lights {
            let first = self.shadow_pipeline(device, l.shadow.slope_bias)?.1.clone();
            let peel = if technique::peels(&l.shadow.technique) {
                Some(self.peel_pipeline(device, l.shadow.slope_bias)?.1.clone())
            } else {
                None
            };
            raster_layouts.push((first, peel));
        }
        let gbuffer_layout = self.gbuffer_pipeline(device)?.1.clone();
        Ok(Targets::new(device, key, &gbuffer_layout, &raster_layouts))
    }

    /// The shading kernel for `lights`, looked up by [`technique::shade_key`]; the block is
    /// generated only to compile a kernel the cache does not hold.
    pub(super) fn shade_kernel(
        &mut self,
        device: &wgpu::Device,
        lights: &[Light],
    ) -> Result<Arc<ComputeKernel>> {
        self.shade_kernel_cascaded(device, lights, &[])
    }

    /// [`Renderer::shade_kernel`] for drawn lights with cascades
    /// ([`technique::shading_block_cascaded`]).
    fn shade_kernel_cascaded(
        &mut self,
        device: &wgpu::Device,
        lights: &[Light],
        groups: &[technique::CascadeGroup],
    ) -> Result<Arc<ComputeKernel>> {
        let key = if groups.is_empty() {
            technique::shade_key(lights)
        } else {
            technique::shade_key_cascaded(lights, groups)
        };
        self.executor.kernels.get_keyed(device, &key, "shade", || {
            technique::shading_block_cascaded(lights, groups)
        })
    }

    /// Makes `wgsl` (the shading kernel rewritten with the same bindings) the kernel
    /// [`Renderer::render`] uses for `lights` from now on, e.g. with every texture fetch
    /// counted (`tests/cost.rs`).
    pub fn insert_shade_kernel(
        &mut self,
        device: &wgpu::Device,
        lights: &[Light],
        wgsl: &str,
    ) -> Result<()> {
        self.executor
            .kernels
            .insert_keyed(device, &technique::shade_key(lights), "shade", wgsl)
    }

    /// On a GPU, renders `scene` untimed (no aux outputs) until its clocks have risen
    /// ([`crate::timer::warm_up`]), before frames whose times matter; on a CPU device nothing.
    pub fn warm_up(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
    ) -> Result<()> {
        let opts = RenderOptions {
            aux: false,
            repeat: 1,
            dump: false,
        };
        crate::timer::warm_up(device, 0, || {
            self.render(device, queue, scene, opts).map(|_| ())
        })?;
        Ok(())
    }

    /// Renders frame `frame` of `scene`'s animation ([`Scene::at_frame`]; frame 0 of a scene
    /// without one is the scene). Frames rendered in turn by one renderer are an animation as a
    /// game draws it: a light whose map is kept (its `update` rate) is redrawn on the frame
    /// the animation moves it or its casters.
    pub fn render_frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        frame: u32,
        opts: RenderOptions,
    ) -> Result<Frame> {
        let at = scene.at_frame(frame)?;
        self.render(device, queue, &at, opts)
    }

    /// Renders `scene` on `device`/`queue` and reads the frame back.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        opts: RenderOptions,
    ) -> Result<Frame> {
        check_render(device, scene, &opts)?;
        let drawn = drawn_lights(scene)?;
        let mut sp = plan_lights_for(&drawn.lights, &opts)?;
        let caching = caches(scene);
        if opts.dump {
            // Everything is read back after the frame: no resource may share a texture.
            sp.plan = sp.plan.unaliased();
        } else if caching {
            sp.plan = dedicate_outputs(sp.plan);
        }
        let vertices = scene.vertices();
        let mut targets = self.take_targets(device, scene, &drawn, vertices.len())?;
        targets.upload(queue, scene, &drawn, &vertices);
        if caching {
            let depths = (0..drawn.lights.len())
                .filter_map(|i| targets.imports.get(&technique::depth_name(i)).cloned())
                .collect();
            let bytes = bytemuck::cast_slice(&vertices);
            self.cache
                .begin(scene, &drawn, &sp.plan, depths, bytes, opts.dump);
        } else {
            self.cache.clear();
        }
        let run = self.frames(device, queue, &sp, &targets, &drawn, opts.repeat.max(1));
        if run.is_err() {
            self.cache.clear();
        }
        let read = run.and_then(|(timings, wall_ms, recorded, outputs)| {
            let (rgba, visibility) = targets.read_back(device, queue)?;
            let sanitized = outputs.read_stats(device)?;
            for (step, n) in &sanitized {
                log::warn!("{step}: replaced {n} non-finite depth texel(s) with 1.0 (no occluder)");
            }
            let frame = Frame {
                width: scene.width,
                height: scene.height,
                rgba,
                visibility,
                position: Vec::new(),
                normal: Vec::new(),
                timings,
                wall_ms,
                recorded,
                sanitized,
                shade_maps: Vec::new(),
                shade_mips: Vec::new(),
                linear_maps: Vec::new(),
                resources: Vec::new(),
            };
            super::read_extras(device, queue, &drawn, &sp, &outputs, &targets, opts, frame)
        });
        self.targets = Some(targets);
        read
    }

    /// Renders `repeat` frames: per frame its pass times (timestamps read a frame later, the
    /// rest after the last), its wall time from submission to completion and the passes it
    /// recorded, and the last frame's plan outputs.
    #[expect(
        clippy::type_complexity,
        reason = "timings, wall times, passes and outputs"
    )]
    fn frames(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        sp: &ScenePlan,
        targets: &Targets,
        drawn: &DrawnLights,
        repeat: u32,
    ) -> Result<(Vec<Vec<(String, f64)>>, Vec<f64>, Vec<Vec<String>>, Outputs)> {
        let kernel = self.frame_shade_kernel(device, drawn, sp)?;
        let peels = targets.lights.iter().filter(|t| t.peel.is_some()).count();
        let spans = (drawn.lights.len() + peels) as u32 + sp.plan.steps.len() as u32 + 2;
        let mut timer = match self.timer.take() {
            Some(t) if t.span_capacity() >= spans => Some(t),
            _ => GpuTimer::new(device, queue, spans),
        };
        let (mut timings, mut wall_ms, mut recorded, mut last) =
            (Vec::new(), Vec::new(), Vec::new(), None);
        for _ in 0..repeat {
            let mut redraw = self.cache.next_frame(drawn.lights.len());
            let (enc, outputs, passes) = loop {
                if let Some(t) = timer.as_mut() {
                    t.reset();
                }
                let mut enc = device.create_command_encoder(&Default::default());
                let frame = FrameInputs {
                    sp,
                    targets,
                    lights: &drawn.lights,
                    kernel: &kernel,
                    redraw: &redraw,
                };
                let (outputs, passes) =
                    self.record_frame(device, &mut enc, &frame, timer.as_mut())?;
                // Kept maps are only valid in the textures they were drawn into: a frame whose
                // plan textures moved (the executor ran another plan meanwhile) redraws all.
                if self.cache.intact(&outputs) || redraw.iter().all(|&r| r) {
                    break (enc, outputs, passes);
                }
                self.cache.redraw_all();
                redraw.fill(true);
            };
            let mut enc = enc;
            if let Some(t) = timer.as_mut() {
                t.resolve(&mut enc);
            }
            outputs.copy_stats(&mut enc);
            let submitted = std::time::Instant::now();
            submit_and_wait(device, queue, enc, "render")?;
            wall_ms.push(submitted.elapsed().as_secs_f64() * 1e3);
            if let Some(t) = timer.as_mut() {
                timings.extend(t.collect(device)?);
            }
            recorded.push(passes);
            last = Some(outputs);
        }
        if let Some(t) = timer.as_mut() {
            timings.extend(t.finish(device)?);
        }
        self.timer = timer;
        let outputs = last.ok_or_else(|| Error::Invalid("no frame rendered".into()))?;
        Ok((timings, wall_ms, recorded, outputs))
    }

    /// Records one frame: the raster passes of the lights it redraws (each light's depth, then
    /// its peeled second depth where its technique reads one), their plan steps, the G-buffer
    /// and the shading pass. Returns the plan's outputs and the passes recorded, by name.
    fn record_frame(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        frame: &FrameInputs,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<(Outputs, Vec<String>)> {
        let mut passes = self.record_rasters(device, enc, frame, timer.as_deref_mut())?;
        let sp = frame.sp;
        let run: Vec<bool> = sp
            .plan
            .steps
            .iter()
            .map(|s| {
                s.node
                    .light
                    .is_none_or(|l| frame.redraw.get(l) != Some(&false))
            })
            .collect();
        let outputs = self.executor.record_steps(
            device,
            enc,
            &sp.plan,
            &frame.targets.imports,
            &run,
            timer.as_deref_mut(),
        )?;
        let steps = sp.plan.steps.iter().zip(&run).filter(|(_, r)| **r);
        passes.extend(steps.map(|(s, _)| s.node.name.clone()));
        self.gbuffer_pass(device, enc, frame.targets, timer.as_deref_mut())?;
        let maps = sp
            .shade_inputs
            .iter()
            .flat_map(|s| &s.maps)
            .map(|m| ShadeMap::of(&outputs, m))
            .collect::<Result<Vec<_>>>()?;
        let groups = self.shade_groups(device, frame.kernel, frame.targets, maps)?;
        record_shade(enc, frame.kernel, groups, frame.targets.key.size, timer);
        passes.extend(["gbuffer".to_string(), "shade".to_string()]);
        Ok((outputs, passes))
    }

    /// Records the raster passes of the lights `frame` redraws; returns their names.
    fn record_rasters(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        frame: &FrameInputs,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<Vec<String>> {
        let targets = frame.targets;
        let mut passes = Vec::new();
        let lights = frame.lights.iter().zip(&targets.lights).zip(frame.redraw);
        for ((l, t), _) in lights.filter(|(_, redraw)| **redraw) {
            let (pipeline, _) = self.shadow_pipeline(device, l.shadow.slope_bias)?;
            raster_pass(
                enc,
                &t.label,
                pipeline,
                &t.bind_group,
                &t.view,
                &targets.vertices,
                targets.vertex_count,
                &t.viewports,
                timer.as_deref_mut(),
            );
            passes.push(t.label.clone());
            if let Some(peel) = &t.peel {
                let (pipeline, _) = self.peel_pipeline(device, l.shadow.slope_bias)?;
                raster_pass(
                    enc,
                    &peel.label,
                    pipeline,
                    &peel.bind_group,
                    &peel.view,
                    &targets.vertices,
                    targets.vertex_count,
                    &t.viewports,
                    timer.as_deref_mut(),
                );
                passes.push(peel.label.clone());
            }
        }
        Ok(passes)
    }

    fn gbuffer_pass(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        targets: &Targets,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let (pipeline, _) = self.gbuffer_pipeline(device)?;
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        if let Some(t) = timer {
            t.begin(enc, "gbuffer");
        }
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &[clear(&targets.gpos_view), clear(&targets.gnorm_view)],
            depth_stencil_attachment: Some(clear_depth(&targets.depth_view)),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &targets.gbuffer_bind_group, &[]);
        pass.set_vertex_buffer(0, targets.vertices.slice(..));
        pass.draw(0..targets.vertex_count, 0..1);
        Ok(())
    }

    /// The shading pass's bind groups: group 0 from `inputs`, group 1 the maps.
    pub(super) fn shade_bind_groups(
        &self,
        device: &wgpu::Device,
        kernel: &ComputeKernel,
        inputs: &ShadeInputs,
        maps: &[wgpu::BindingResource<'_>],
    ) -> Result<[wgpu::BindGroup; 2]> {
        let err = |message: String| Error::Pipeline {
            kernel: "shade".into(),
            message,
        };
        let view = |binding, v| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(v),
        };
        fn buffer(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            }
        }
        let entries = [
            view(0, inputs.gpos),
            view(1, inputs.gnorm),
            buffer(2, inputs.materials),
            buffer(3, inputs.lights),
            buffer(4, inputs.frame),
            view(5, inputs.color),
            buffer(6, inputs.visibility),
            wgpu::BindGroupEntry {
                binding: 7,
                resource: wgpu::BindingResource::Sampler(&self.cmp_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 8,
                resource: wgpu::BindingResource::Sampler(&self.sat_sampler),
            },
        ];
        let map_entries: Vec<wgpu::BindGroupEntry> = maps
            .iter()
            .enumerate()
            .map(|(i, r)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: r.clone(),
            })
            .collect();
        let group = |label, layout, entries: &[wgpu::BindGroupEntry]| {
            scoped(
                device,
                || {
                    gpu_objects::bind_group(
                        device,
                        &wgpu::BindGroupDescriptor {
                            label: Some(label),
                            layout,
                            entries,
                        },
                    )
                },
                err,
            )
        };
        let (Some(l0), Some(l1)) = (kernel.layouts.first(), kernel.layouts.get(1)) else {
            return Err(err("the shading kernel declares no group 0 and 1".into()));
        };
        Ok([
            group("shadowgraph.shade", l0, &entries)?,
            group("shadowgraph.shade.maps", l1, &map_entries)?,
        ])
    }
}

/// Records the shading pass over a `w × h` image.
pub(super) fn record_shade(
    enc: &mut wgpu::CommandEncoder,
    kernel: &ComputeKernel,
    groups: &[wgpu::BindGroup; 2],
    (w, h): (u32, u32),
    timer: Option<&mut GpuTimer>,
) {
    let workgroups = kernel.groups_for(w, h);
    if let Some(t) = timer {
        t.begin(enc, "shade");
    }
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("shade"),
        timestamp_writes: None,
    });
    pass.set_pipeline(&kernel.pipeline);
    pass.set_bind_group(0, &groups[0], &[]);
    pass.set_bind_group(1, &groups[1], &[]);
    pass.dispatch_workgroups(workgroups[0], workgroups[1], 1);
}
