//! The frame: per light a depth-only raster pass, the planned kernels, the camera G-buffer and
//! the generated shading kernel. Also [`probe`], which evaluates visibility at given points
//! on given maps (how tests compare the GPU to the f64 references).

use std::collections::HashMap;

use bytemuck::Zeroable;
use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::error::{Error, Result};
use crate::exec::{Executor, GpuTimer};
use crate::gpu::{read_buffer, read_texture, scoped, submit_and_wait, write_texture};
use crate::graph::{Graph, Plan, plan};
use crate::kernels;
use crate::scene::{Light, Scene};
use crate::technique::{self, LightGpu};

/// Frame constants of `kernels/shade.wgsl` (mirrors its `Frame`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameGpu {
    /// Image size.
    pub size: [u32; 2],
    /// Number of lights.
    pub light_count: u32,
    /// 1 when the ray fields hold the camera (pixel footprints), 0 for the probe.
    pub has_camera: u32,
    /// Ambient colour.
    pub ambient: [f32; 3],
    /// Padding.
    pub _pad1: f32,
    /// Background colour.
    pub background: [f32; 3],
    /// Padding.
    pub _pad2: f32,
    /// Eye position.
    pub camera: [f32; 3],
    /// Padding.
    pub _pad3: f32,
    /// Unnormalized view ray through pixel corner (0, 0).
    pub ray00: [f32; 3],
    /// Padding.
    pub _pad4: f32,
    /// Ray change per pixel in x: pixel (x, y)'s ray is `ray00 + (x + ½)·ray_dx + (y + ½)·ray_dy`.
    pub ray_dx: [f32; 3],
    /// Padding.
    pub _pad5: f32,
    /// Ray change per pixel in y.
    pub ray_dy: [f32; 3],
    /// Padding.
    pub _pad6: f32,
}

impl FrameGpu {
    /// Frame constants for `scene` rendered at `width × height`, with the camera's rays.
    pub fn new(scene: &Scene, width: u32, height: u32) -> Self {
        let rays = CameraRays::new(&scene.camera, width, height);
        Self {
            size: [width, height],
            light_count: scene.lights.len() as u32,
            has_camera: 1,
            ambient: scene.ambient.to_array(),
            background: scene.background.to_array(),
            camera: scene.camera.position.to_array(),
            ray00: rays.ray00.to_array(),
            ray_dx: rays.ray_dx.to_array(),
            ray_dy: rays.ray_dy.to_array(),
            ..Self::zeroed()
        }
    }
}

/// A pinhole camera's unnormalized view rays as `glam`'s `look_at_rh` and `perspective_rh`
/// (the G-buffer's projection) make them: forward `f`, right `s = f × up`, up `u = s × f`,
/// `t = tan(fov_y / 2)`; pixel (x, y) of a `w × h` image sees along
/// `ray00 + (x + ½)·ray_dx + (y + ½)·ray_dy` with `ray00 = f − t·aspect·s + t·u`,
/// `ray_dx = 2t·aspect/w · s`, `ray_dy = −2t/h · u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRays {
    /// Ray through pixel corner (0, 0).
    pub ray00: glam::Vec3,
    /// Per pixel in x.
    pub ray_dx: glam::Vec3,
    /// Per pixel in y.
    pub ray_dy: glam::Vec3,
}

impl CameraRays {
    /// The rays of `camera` for a `width × height` image.
    pub fn new(camera: &crate::scene::Camera, width: u32, height: u32) -> Self {
        let f = (camera.target - camera.position).normalize();
        let s = f.cross(camera.up).normalize();
        let u = s.cross(f);
        let t = (0.5 * camera.fov_y_degrees.to_radians()).tan();
        let aspect = width as f32 / height as f32;
        Self {
            ray00: f - t * aspect * s + t * u,
            ray_dx: (2.0 * t * aspect / width as f32) * s,
            ray_dy: (-2.0 * t / height as f32) * u,
        }
    }
}

/// The graph of a scene, its plan, and what the shading pass reads per light.
pub struct ScenePlan {
    /// Every node the scene's lights could use.
    pub graph: Graph,
    /// The pruned, ordered plan.
    pub plan: Plan,
    /// Per light, the resources the shading pass binds.
    pub shade_inputs: Vec<technique::ShadeInput>,
}

/// Plans `lights` (no GPU needed): the kernels their techniques need and nothing else.
pub fn plan_lights(lights: &[Light]) -> Result<ScenePlan> {
    plan_lights_for(lights, &RenderOptions::default())
}

/// [`plan_lights`] for a render with `opts`: with `opts.aux` or `opts.dump`, each light's
/// linear depth map ([`technique::linear_name`]) is an output too ([`Frame::linear_maps`],
/// the dump; the encodings linearize the depth themselves, so it is planned only when asked
/// for).
pub fn plan_lights_for(lights: &[Light], opts: &RenderOptions) -> Result<ScenePlan> {
    let mut graph = Graph::default();
    let mut shade_inputs = Vec::new();
    for (i, l) in lights.iter().enumerate() {
        technique::sat_coding(l).map_err(|e| Error::Invalid(format!("light[{i}]: {e}")))?;
        shade_inputs.push(technique::add_light_nodes(&mut graph, i, l));
    }
    let linear: Vec<String> = (0..lights.len()).map(technique::linear_name).collect();
    let diagnostics = linear
        .iter()
        .filter(|_| opts.aux || opts.dump)
        .map(String::as_str);
    let outputs: Vec<&str> = shade_inputs
        .iter()
        .flat_map(|s| s.maps.iter().map(String::as_str))
        .chain(diagnostics)
        .collect();
    let plan = plan(&graph, &outputs)?;
    Ok(ScenePlan {
        graph,
        plan,
        shade_inputs,
    })
}

/// Checks `scene` against the device's limits, features and the memory budget
/// ([`crate::limits::memory_budget`]) for a default render, before anything is created;
/// errors name the scene key that would fix them, with its line.
pub fn check_limits(device: &wgpu::Device, scene: &Scene) -> Result<()> {
    check_render(device, scene, &RenderOptions::default())
}

/// [`check_limits`] for a render with `opts` (read-backs of `aux` and `dump` count too), and
/// `opts.repeat` at most [`MAX_FRAMES`].
pub fn check_render(device: &wgpu::Device, scene: &Scene, opts: &RenderOptions) -> Result<()> {
    if opts.repeat > MAX_FRAMES {
        return Err(Error::Invalid(format!(
            "repeat = {} is more than {MAX_FRAMES} frames",
            opts.repeat
        )));
    }
    let sp = plan_lights_for(&scene.lights, opts)?;
    crate::limits::check_scene(
        scene,
        &sp,
        &device.limits(),
        device.features(),
        opts,
        crate::limits::memory_budget()?,
    )
}

/// Most frames a command's `--repeat` may ask for. Timings keep one row per frame, and on lavapipe (Mesa
/// 22.3.6) every dispatch of the shading kernel keeps about 235 KB that the driver does not
/// return (traced in the README), so 1000 frames bound that to about 240 MB.
pub const MAX_REPEAT: u32 = 1000;

/// Most frames one [`Renderer::render`] call may run: [`MAX_REPEAT`] timed frames and as many
/// warm-up frames (`evaluate` and `bench` add theirs to the timed ones).
pub const MAX_FRAMES: u32 = 2 * MAX_REPEAT;

/// Checks that the device offers the features the lights' techniques need.
pub fn check_features(device: &wgpu::Device, lights: &[Light]) -> Result<()> {
    use crate::scene::{Storage, Technique};
    for (i, l) in lights.iter().enumerate() {
        let storage = match l.shadow.technique {
            Technique::Msm { prefilter, .. } => Some(prefilter.storage),
            Technique::MsmSoft { soft, .. } => Some(soft.storage),
            _ => None,
        };
        if let Some(storage) = storage {
            if storage == Storage::Unorm16
                && !device
                    .features()
                    .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM)
            {
                return Err(Error::MissingFeature {
                    what: format!("light[{i}].shadow.format = \"unorm16\""),
                    feature: "TEXTURE_FORMAT_16BIT_NORM",
                });
            }
        }
    }
    Ok(())
}

/// What `render` asks for besides the image.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderOptions {
    /// Read back world position, normal and per-light visibility.
    pub aux: bool,
    /// Frames to render; timings are per frame (the caller takes medians).
    pub repeat: u32,
    /// Read back every resource of the executed plan (for `shadowgraph dump`).
    pub dump: bool,
}

/// A resource of the executed plan, read back for inspection.
#[derive(Clone, Debug)]
pub struct DumpedResource {
    /// Its data (mip 0 in `levels[0]`, then each further mip level).
    pub levels: Vec<FloatMap>,
    /// The light it belongs to.
    pub light: Option<usize>,
    /// The kernel of the node that wrote it (`None` for imports: the rasterized map).
    pub producer: Option<String>,
    /// Texel format.
    pub format: wgpu::TextureFormat,
}

/// A rendered frame read back to the CPU.
pub struct Frame {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// sRGB RGBA8 pixels.
    pub rgba: Vec<u8>,
    /// Visibility per pixel per light: `vis[(y * width + x) * lights + l]`.
    pub visibility: Vec<f32>,
    /// World position + coverage per pixel (`aux` only).
    pub position: Vec<f32>,
    /// Normal + material per pixel (`aux` only).
    pub normal: Vec<f32>,
    /// Per frame, milliseconds per timed pass (empty when the device cannot time): GPU
    /// timestamps at the boundaries between passes, so consecutive passes share their bounds.
    pub timings: Vec<Vec<(String, f64)>>,
    /// Per frame, wall-clock milliseconds from submitting the frame's commands to their
    /// completion (what the passes' times should add up to, less submission overhead).
    pub wall_ms: Vec<f64>,
    /// Steps whose kernels reported replaced texels (non-finite depth), with the count.
    pub sanitized: Vec<(String, u32)>,
    /// Per light, the map its shading reads (level 0): raw depth, linear depth or a filtered
    /// representation; CSM's basis maps side by side as one map of 2M channels (`aux` only).
    pub shade_maps: Vec<FloatMap>,
    /// Per light, the further mip levels of its map (level 1 down to 1×1; empty without the
    /// `mips` filter), channels concatenated like `shade_maps` (`aux` only).
    pub shade_mips: Vec<Vec<FloatMap>>,
    /// Per light, the linear depth map, when the plan made one (`aux` only).
    pub linear_maps: Vec<Option<FloatMap>>,
    /// Every resource of the plan in plan order (`dump` only).
    pub resources: Vec<DumpedResource>,
}

/// A float texture read back: `channels` values per texel, row-major.
#[derive(Clone, Debug)]
pub struct FloatMap {
    /// Graph resource name.
    pub resource: String,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Values per texel.
    pub channels: usize,
    /// The values.
    pub data: Vec<f32>,
}

impl FloatMap {
    /// The maps' channels side by side per texel (CSM's basis maps as one map), named after
    /// the first.
    pub fn concat(maps: Vec<FloatMap>) -> Result<FloatMap> {
        let mut it = maps.into_iter();
        let Some(mut out) = it.next() else {
            return Err(Error::Invalid("no maps to concatenate".into()));
        };
        for m in it {
            if (m.width, m.height) != (out.width, out.height) {
                return Err(Error::Invalid(format!(
                    "`{}` is {}x{}, `{}` {}x{}",
                    m.resource, m.width, m.height, out.resource, out.width, out.height
                )));
            }
            let channels = out.channels + m.channels;
            out.data = out
                .data
                .chunks(out.channels)
                .zip(m.data.chunks(m.channels))
                .flat_map(|(a, b)| a.iter().chain(b).copied())
                .collect();
            out.channels = channels;
        }
        Ok(out)
    }

    /// Reads `texture` (mip 0) back.
    pub fn read(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        resource: &str,
        texture: &wgpu::Texture,
    ) -> Result<Self> {
        Self::read_level(device, queue, resource, texture, 0)
    }

    /// Reads mip `level` of `texture` back.
    pub fn read_level(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        resource: &str,
        texture: &wgpu::Texture,
        level: u32,
    ) -> Result<Self> {
        let (channels, data) = crate::gpu::read_float_texture(device, queue, texture, level)?;
        Ok(Self {
            resource: resource.to_string(),
            width: (texture.width() >> level).max(1),
            height: (texture.height() >> level).max(1),
            channels,
            data,
        })
    }
}

/// Reads summed-area table `name` back as the per-texel representation it sums
/// ([`crate::sat::decode_table`]), `channels` of them (the table's input's).
pub fn read_sat_map(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    name: &str,
    texture: &wgpu::Texture,
    coding: &crate::sat::SatCoding,
    channels: usize,
) -> Result<FloatMap> {
    let raw = crate::gpu::read_texture(device, queue, texture, 0)?;
    let (width, height) = (texture.width(), texture.height());
    let data = crate::sat::decode_table(
        bytemuck::cast_slice(&raw),
        width as usize,
        height as usize,
        coding,
        channels,
    );
    Ok(FloatMap {
        resource: name.to_string(),
        width,
        height,
        channels,
        data,
    })
}

/// Renders scenes; holds pipelines and pooled textures across frames.
pub struct Renderer {
    /// The graph executor (kernel pipelines, texture pool).
    pub executor: Executor,
    shadow: HashMap<u32, wgpu::RenderPipeline>,
    gbuffer: Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    cmp_sampler: wgpu::Sampler,
    /// The shading pass's outputs, kept while the image size and light count stay the same.
    shade_targets: Option<((u32, u32, usize), Shaded)>,
}

const VERTEX_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32];

fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<crate::scene::Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRS,
    }
}

fn uniform(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytes,
        usage: wgpu::BufferUsages::UNIFORM,
    })
}

fn texture(
    device: &wgpu::Device,
    label: &str,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Usage of textures the renderer writes and later reads back or samples.
const TARGET: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);

impl Renderer {
    /// A renderer for `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            executor: Executor::new(),
            shadow: HashMap::new(),
            gbuffer: None,
            shade_targets: None,
            cmp_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadowgraph.cmp_sampler"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            }),
        }
    }

    fn raster_pipeline(
        device: &wgpu::Device,
        name: &str,
        fragment: Option<&[Option<wgpu::ColorTargetState>]>,
        bias: wgpu::DepthBiasState,
    ) -> Result<(wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
        let wgsl = kernels::resolve(name, None)?;
        let (_, refl) = kernels::reflect(name, &wgsl)?;
        let label = format!("shadowgraph.{name}");
        scoped(
            device,
            || {
                let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(&label),
                    source: wgpu::ShaderSource::Wgsl(wgsl.as_str().into()),
                });
                let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(&label),
                    entries: &refl.layout_entries(0),
                });
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(&label),
                    bind_group_layouts: &[Some(&bgl)],
                    immediate_size: 0,
                });
                let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(&label),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[Some(vertex_layout())],
                    },
                    // Two-sided: planes and open meshes cast and receive from both sides.
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: wgpu::TextureFormat::Depth32Float,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias,
                    }),
                    multisample: Default::default(),
                    fragment: fragment.map(|targets| wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets,
                    }),
                    multiview_mask: None,
                    cache: None,
                });
                (pipeline, bgl)
            },
            |message| Error::Pipeline {
                kernel: name.to_string(),
                message,
            },
        )
    }

    fn shadow_pipeline(
        &mut self,
        device: &wgpu::Device,
        slope: f32,
    ) -> Result<&wgpu::RenderPipeline> {
        // Slope-scaled bias is pipeline state: one pipeline per distinct value, made once.
        match self.shadow.entry(slope.to_bits()) {
            std::collections::hash_map::Entry::Occupied(e) => Ok(e.into_mut()),
            std::collections::hash_map::Entry::Vacant(e) => {
                let bias = wgpu::DepthBiasState {
                    constant: 0,
                    slope_scale: slope,
                    clamp: 0.0,
                };
                let (p, _) = Self::raster_pipeline(device, "shadow_depth", None, bias)?;
                Ok(e.insert(p))
            }
        }
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
        let mut sp = plan_lights_for(&scene.lights, &opts)?;
        if opts.dump {
            // Everything is read back after the frame: no resource may share a texture.
            sp.plan = sp.plan.unaliased();
        }
        let verts = scene.vertices();
        let vbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadowgraph.vertices"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let materials: Vec<[f32; 4]> = scene
            .objects
            .iter()
            .map(|o| o.color.extend(1.0).to_array())
            .collect();
        let size = (scene.width, scene.height);
        let gpos = texture(
            device,
            "shadowgraph.g_position",
            size,
            wgpu::TextureFormat::Rgba32Float,
            TARGET,
        );
        let gnorm = texture(
            device,
            "shadowgraph.g_normal",
            size,
            wgpu::TextureFormat::Rgba32Float,
            TARGET,
        );
        let cam_depth = texture(
            device,
            "shadowgraph.camera_depth",
            size,
            wgpu::TextureFormat::Depth32Float,
            TARGET,
        );
        let depths: Vec<wgpu::Texture> = scene
            .lights
            .iter()
            .map(|l| {
                texture(
                    device,
                    "shadowgraph.shadow_map",
                    (l.shadow_map, l.shadow_map),
                    wgpu::TextureFormat::Depth32Float,
                    TARGET,
                )
            })
            .collect();
        let imports: HashMap<String, wgpu::Texture> = depths
            .iter()
            .enumerate()
            .map(|(i, t)| (technique::depth_name(i), t.clone()))
            .collect();
        let spans = scene.lights.len() as u32 + sp.plan.steps.len() as u32 + 2;
        let mut timer = GpuTimer::new(device, queue, spans);
        let repeat = opts.repeat.max(1);
        let mut timings = Vec::new();
        let mut wall_ms = Vec::new();
        let mut last = None;
        for _ in 0..repeat {
            if let Some(t) = timer.as_mut() {
                t.reset();
            }
            let mut enc = device.create_command_encoder(&Default::default());
            for (i, (l, depth)) in scene.lights.iter().zip(&depths).enumerate() {
                self.shadow_pass(
                    device,
                    &mut enc,
                    i,
                    l,
                    &vbuf,
                    verts.len() as u32,
                    depth,
                    timer.as_mut(),
                )?;
            }
            let outputs =
                self.executor
                    .record(device, &mut enc, &sp.plan, &imports, timer.as_mut())?;
            self.gbuffer_pass(
                device,
                &mut enc,
                scene,
                &vbuf,
                verts.len() as u32,
                &gpos,
                &gnorm,
                &cam_depth,
                timer.as_mut(),
            )?;
            let maps: Vec<wgpu::TextureView> = sp
                .shade_inputs
                .iter()
                .flat_map(|s| &s.maps)
                .map(|m| depth_only_view(&outputs.textures[m]))
                .collect();
            let frame = FrameGpu::new(scene, size.0, size.1);
            let shaded = self.shade(
                device,
                &mut enc,
                &scene.lights,
                &frame,
                &gpos,
                &gnorm,
                &materials,
                &maps,
                timer.as_mut(),
            )?;
            if let Some(t) = timer.as_mut() {
                t.resolve(&mut enc);
            }
            outputs.copy_stats(&mut enc);
            let submitted = std::time::Instant::now();
            submit_and_wait(device, queue, enc, "render")?;
            wall_ms.push(submitted.elapsed().as_secs_f64() * 1e3);
            if let Some(t) = timer.as_ref() {
                timings.push(t.read(device)?);
            }
            last = Some((outputs, shaded));
        }
        let Some((outputs, shaded)) = last else {
            return Err(Error::Invalid("no frame rendered".into()));
        };
        let sanitized = outputs.read_stats(device)?;
        for (step, n) in &sanitized {
            log::warn!("{step}: replaced {n} non-finite depth texel(s) with 1.0 (no occluder)");
        }
        let rgba = read_texture(device, queue, &shaded.color, 0)?;
        let visibility = shaded.read_visibility(device, queue)?;
        let mut frame = Frame {
            width: size.0,
            height: size.1,
            rgba,
            visibility,
            position: Vec::new(),
            normal: Vec::new(),
            timings,
            wall_ms,
            sanitized,
            shade_maps: Vec::new(),
            shade_mips: Vec::new(),
            linear_maps: Vec::new(),
            resources: Vec::new(),
        };
        if opts.dump {
            frame.resources = dump_resources(device, queue, &sp.plan, &outputs)?;
        }
        if opts.aux {
            frame.position = bytemuck::cast_slice(&read_texture(device, queue, &gpos, 0)?).to_vec();
            frame.normal = bytemuck::cast_slice(&read_texture(device, queue, &gnorm, 0)?).to_vec();
            for (i, input) in sp.shade_inputs.iter().enumerate() {
                let coding = technique::sat_coding(&scene.lights[i])?;
                let channels = technique::map_channels(&scene.lights[i]);
                let maps = input
                    .maps
                    .iter()
                    .zip(channels)
                    .map(|(m, n)| match &coding {
                        Some(c) => read_sat_map(device, queue, m, &outputs.textures[m], c, n),
                        None => FloatMap::read(device, queue, m, &outputs.textures[m]),
                    })
                    .collect::<Result<Vec<_>>>()?;
                frame.shade_maps.push(FloatMap::concat(maps)?);
                let levels = input
                    .maps
                    .first()
                    .map_or(1, |m| outputs.textures[m].mip_level_count());
                let mut mips = Vec::new();
                for level in 1..levels {
                    let maps = input
                        .maps
                        .iter()
                        .map(|m| {
                            FloatMap::read_level(device, queue, m, &outputs.textures[m], level)
                        })
                        .collect::<Result<Vec<_>>>()?;
                    mips.push(FloatMap::concat(maps)?);
                }
                frame.shade_mips.push(mips);
                let linear = technique::linear_name(i);
                frame.linear_maps.push(match outputs.textures.get(&linear) {
                    Some(t) => Some(FloatMap::read(device, queue, &linear, t)?),
                    None => None,
                });
            }
        }
        Ok(frame)
    }

    #[expect(clippy::too_many_arguments, reason = "one raster pass's inputs")]
    fn shadow_pass(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        i: usize,
        light: &Light,
        vbuf: &wgpu::Buffer,
        count: u32,
        depth: &wgpu::Texture,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let vp = (light.projection() * light.view()).to_cols_array();
        let label = format!("light{i}.shadow_raster");
        let raster = ShadowRaster {
            label: &label,
            view_proj: vp,
            slope_bias: light.shadow.slope_bias,
        };
        self.shadow_raster(device, enc, &raster, vbuf, count, depth, timer)
    }

    /// Records a depth-only raster pass of the scene's vertices `vbuf` (`count` vertices) into
    /// `depth` (Depth32Float) with an explicit world → clip matrix: the pipeline and bias the
    /// renderer's own shadow maps use (`truth` rasterizes its emitter samples with it).
    #[expect(clippy::too_many_arguments, reason = "one raster pass's inputs")]
    pub fn shadow_raster(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        raster: &ShadowRaster,
        vbuf: &wgpu::Buffer,
        count: u32,
        depth: &wgpu::Texture,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let pipeline = self.shadow_pipeline(device, raster.slope_bias)?.clone();
        let ubuf = uniform(
            device,
            "shadowgraph.light_view",
            bytemuck::cast_slice(&raster.view_proj),
        );
        let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadowgraph.shadow_depth"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: ubuf.as_entire_binding(),
            }],
        });
        let view = depth.create_view(&Default::default());
        if let Some(t) = timer {
            t.begin(enc, raster.label);
        }
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(raster.label),
            color_attachments: &[],
            depth_stencil_attachment: Some(clear_depth(&view)),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.set_vertex_buffer(0, vbuf.slice(..));
        pass.draw(0..count, 0..1);
        Ok(())
    }

    #[expect(clippy::too_many_arguments, reason = "one raster pass's inputs")]
    fn gbuffer_pass(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        scene: &Scene,
        vbuf: &wgpu::Buffer,
        count: u32,
        gpos: &wgpu::Texture,
        gnorm: &wgpu::Texture,
        cam_depth: &wgpu::Texture,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        if self.gbuffer.is_none() {
            let t = Some(wgpu::ColorTargetState {
                format: wgpu::TextureFormat::Rgba32Float,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            });
            self.gbuffer = Some(Self::raster_pipeline(
                device,
                "gbuffer",
                Some(&[t.clone(), t]),
                Default::default(),
            )?);
        }
        let Some((pipeline, bgl)) = &self.gbuffer else {
            return Err(Error::Invalid("G-buffer pipeline missing".into()));
        };
        let vp = scene
            .camera
            .view_proj(scene.width as f32 / scene.height as f32)
            .to_cols_array();
        let ubuf = uniform(device, "shadowgraph.camera", bytemuck::cast_slice(&vp));
        let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadowgraph.gbuffer"),
            layout: bgl,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: ubuf.as_entire_binding(),
            }],
        });
        let (pv, nv, dv) = (
            gpos.create_view(&Default::default()),
            gnorm.create_view(&Default::default()),
            cam_depth.create_view(&Default::default()),
        );
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
            color_attachments: &[clear(&pv), clear(&nv)],
            depth_stencil_attachment: Some(clear_depth(&dv)),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.set_vertex_buffer(0, vbuf.slice(..));
        pass.draw(0..count, 0..1);
        Ok(())
    }

    /// Records the shading kernel for `lights` over a G-buffer; `maps[i]` is light i's input.
    #[expect(clippy::too_many_arguments, reason = "the shading pass's bindings")]
    pub fn shade(
        &mut self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        lights: &[Light],
        frame: &FrameGpu,
        gpos: &wgpu::Texture,
        gnorm: &wgpu::Texture,
        materials: &[[f32; 4]],
        maps: &[wgpu::TextureView],
        timer: Option<&mut GpuTimer>,
    ) -> Result<Shaded> {
        let block = technique::shading_block(lights);
        let kernel = self
            .executor
            .kernels
            .get_generated(device, "shade", Some(&block))?;
        let (w, h) = (frame.size[0], frame.size[1]);
        let key = (w, h, lights.len());
        let targets = match &self.shade_targets {
            Some((k, t)) if *k == key => t.clone(),
            _ => {
                let t = Shaded::new(device, key);
                self.shade_targets = Some((key, t.clone()));
                t
            }
        };
        let Shaded { color, visibility } = targets;
        let gpu_lights: Vec<LightGpu> = lights.iter().map(LightGpu::new).collect();
        let storage = |label, bytes: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let mat_buf = storage("shadowgraph.materials", bytemuck::cast_slice(materials));
        let light_buf = storage("shadowgraph.lights", bytemuck::cast_slice(&gpu_lights));
        let frame_buf = uniform(device, "shadowgraph.frame", bytemuck::bytes_of(frame));
        let views = [
            gpos.create_view(&Default::default()),
            gnorm.create_view(&Default::default()),
            color.create_view(&Default::default()),
        ];
        let err = |message: String| Error::Pipeline {
            kernel: "shade".into(),
            message,
        };
        let bg0 = scoped(
            device,
            || {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadowgraph.shade"),
                    layout: &kernel.layouts[0],
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(&views[0]),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&views[1]),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: mat_buf.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: light_buf.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: frame_buf.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 5,
                            resource: wgpu::BindingResource::TextureView(&views[2]),
                        },
                        wgpu::BindGroupEntry {
                            binding: 6,
                            resource: visibility.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 7,
                            resource: wgpu::BindingResource::Sampler(&self.cmp_sampler),
                        },
                    ],
                })
            },
            err,
        )?;
        let entries: Vec<wgpu::BindGroupEntry> = maps
            .iter()
            .enumerate()
            .map(|(i, v)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: wgpu::BindingResource::TextureView(v),
            })
            .collect();
        let bg1 = scoped(
            device,
            || {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadowgraph.shade.maps"),
                    layout: &kernel.layouts[1],
                    entries: &entries,
                })
            },
            err,
        )?;
        let groups = kernel.groups_for(w, h);
        if let Some(t) = timer {
            t.begin(enc, "shade");
        }
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("shade"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, &bg0, &[]);
        pass.set_bind_group(1, &bg1, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], 1);
        drop(pass);
        Ok(Shaded { color, visibility })
    }
}

/// One depth-only raster pass for [`Renderer::shadow_raster`].
#[derive(Clone, Copy, Debug)]
pub struct ShadowRaster<'a> {
    /// Pass label (and timer label).
    pub label: &'a str,
    /// World → clip, column-major (wgpu depth convention: 0 at near, 1 at far).
    pub view_proj: [f32; 16],
    /// Slope-scaled depth bias (`DepthBiasState::slope_scale`).
    pub slope_bias: f32,
}

/// The shading pass's outputs.
#[derive(Clone)]
pub struct Shaded {
    /// RGBA8 image (sRGB-encoded values).
    pub color: wgpu::Texture,
    /// Visibility per pixel per light.
    pub visibility: wgpu::Buffer,
}

impl Shaded {
    /// Targets for a `w × h` image and `lights` lights.
    fn new(device: &wgpu::Device, (w, h, lights): (u32, u32, usize)) -> Self {
        let color = texture(
            device,
            "shadowgraph.color",
            (w, h),
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let bytes = (u64::from(w) * u64::from(h) * lights.max(1) as u64 * 4).max(4);
        let visibility = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadowgraph.visibility"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Self { color, visibility }
    }

    /// Copies the visibility buffer back.
    pub fn read_visibility(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<f32>> {
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadowgraph.visibility.readback"),
            size: self.visibility.size(),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&self.visibility, 0, &staging, 0, self.visibility.size());
        submit_and_wait(device, queue, enc, "visibility readback")?;
        Ok(bytemuck::cast_slice(&read_buffer(device, &staging)?).to_vec())
    }
}

/// Reads back every resource of `plan` (all mip levels) with its provenance.
fn dump_resources(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
    outputs: &crate::exec::Outputs,
) -> Result<Vec<DumpedResource>> {
    plan.resources
        .iter()
        .map(|r| {
            let name = &r.resource.name;
            let t = &outputs.textures[name];
            let levels = (0..t.mip_level_count())
                .map(|mip| {
                    let (channels, data) = crate::gpu::read_float_texture(device, queue, t, mip)?;
                    Ok(FloatMap {
                        resource: name.clone(),
                        width: (t.width() >> mip).max(1),
                        height: (t.height() >> mip).max(1),
                        channels,
                        data,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(DumpedResource {
                levels,
                light: r.resource.light,
                producer: r.producer.map(|s| plan.steps[s].node.kernel.clone()),
                format: r.resource.format,
            })
        })
        .collect()
}

/// A depth attachment cleared to the far plane and kept.
fn clear_depth(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

fn depth_only_view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        aspect: if t.format().is_depth_stencil_format() {
            wgpu::TextureAspect::DepthOnly
        } else {
            wgpu::TextureAspect::All
        },
        ..Default::default()
    })
}

/// A map handed to [`probe`]: what the light's technique reads (linear depth as R32Float,
/// moments as Rg32Float, …), never the raw depth of hardware PCF.
pub struct ProbeMap<'a> {
    /// Side length of level 0.
    pub size: u32,
    /// Texel format of `data`: a 32-bit float format, or `Rgba32Uint` for a fixed-point
    /// summed-area table, whose words `data` carries bit for bit (`f32::from_bits`).
    pub format: wgpu::TextureFormat,
    /// Mip levels in `data` (1 for a plain map).
    pub mips: u32,
    /// Every level's texels, row-major, level 0 first (level `m` is `max(1, size >> m)` wide).
    pub data: &'a [f32],
}

impl<'a> ProbeMap<'a> {
    /// A linear depth map.
    pub fn linear(size: u32, data: &'a [f32]) -> Self {
        Self::new(size, wgpu::TextureFormat::R32Float, data)
    }

    /// A one-level map of `format`.
    pub fn new(size: u32, format: wgpu::TextureFormat, data: &'a [f32]) -> Self {
        Self {
            size,
            format,
            mips: 1,
            data,
        }
    }
}

/// Evaluates each light's visibility at `points` (position, unit normal) on the given maps
/// with the real shading kernel. `maps` lists every light's maps in binding order (one per
/// light; CSM: one per two terms). Returns `vis[point * lights + light]`.
pub fn probe(
    renderer: &mut Renderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    lights: &[Light],
    maps: &[ProbeMap],
    points: &[(Vec3, Vec3)],
) -> Result<Vec<f32>> {
    let needed: usize = lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            technique::add_light_nodes(&mut Graph::default(), i, l)
                .maps
                .len()
        })
        .sum();
    if maps.len() != needed || points.is_empty() {
        return Err(Error::Invalid(format!(
            "probe needs {needed} map(s) for these lights and at least one point"
        )));
    }
    let w = (points.len() as u32).min(256);
    let h = (points.len() as u32).div_ceil(w);
    let mut pos = vec![[0.0f32; 4]; (w * h) as usize];
    let mut nor = vec![[0.0f32; 4]; (w * h) as usize];
    for (i, (p, n)) in points.iter().enumerate() {
        pos[i] = p.extend(1.0).to_array();
        nor[i] = n.extend(0.0).to_array();
    }
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    let gpos = texture(
        device,
        "shadowgraph.probe.position",
        (w, h),
        wgpu::TextureFormat::Rgba32Float,
        usage,
    );
    let gnorm = texture(
        device,
        "shadowgraph.probe.normal",
        (w, h),
        wgpu::TextureFormat::Rgba32Float,
        usage,
    );
    write_texture(queue, &gpos, bytemuck::cast_slice(&pos));
    write_texture(queue, &gnorm, bytemuck::cast_slice(&nor));
    let mut views = Vec::new();
    for m in maps {
        let channels = crate::gpu::float_channels(m.format).unwrap_or(0);
        let side = |l: u32| (m.size >> l).max(1) as usize;
        let texels: usize = (0..m.mips).map(|l| side(l) * side(l)).sum();
        let is_f32 = crate::graph::texel_bytes(m.format) == 4 * channels as u64;
        if !is_f32 || channels == 0 || m.mips == 0 || m.data.len() != texels * channels {
            return Err(Error::Invalid(format!(
                "a {0}x{0} {1:?} probe map of {3} level(s) needs {2} f32 values",
                m.size,
                m.format,
                texels * channels.max(1),
                m.mips
            )));
        }
        let t = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadowgraph.probe.map"),
            size: wgpu::Extent3d {
                width: m.size,
                height: m.size,
                depth_or_array_layers: 1,
            },
            mip_level_count: m.mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: m.format,
            usage,
            view_formats: &[],
        });
        let mut at = 0;
        for level in 0..m.mips {
            let n = side(level) * side(level) * channels;
            crate::gpu::write_texture_level(
                queue,
                &t,
                level,
                bytemuck::cast_slice(&m.data[at..at + n]),
            );
            at += n;
        }
        views.push(t.create_view(&Default::default()));
    }
    let frame = FrameGpu {
        size: [w, h],
        light_count: lights.len() as u32,
        ..FrameGpu::zeroed()
    };
    let mut enc = device.create_command_encoder(&Default::default());
    let shaded = renderer.shade(
        device,
        &mut enc,
        lights,
        &frame,
        &gpos,
        &gnorm,
        &[[1.0; 4]],
        &views,
        None,
    )?;
    submit_and_wait(device, queue, enc, "probe")?;
    let mut vis = shaded.read_visibility(device, queue)?;
    vis.truncate(points.len() * lights.len());
    Ok(vis)
}
