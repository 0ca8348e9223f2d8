//! The frame: per light a depth-only raster pass, the planned kernels, the camera G-buffer and
//! the generated shading kernel ([`Renderer`]). Also [`visibility_at`], which evaluates
//! visibility at given points on given maps (how tests compare the GPU to the f64 references).

mod cache;
mod cascade;
mod renderer;
mod targets;
mod visibility_at;

use bytemuck::Zeroable;

pub use self::cascade::{DrawnLights, cascade_camera, drawn_lights, view_range};
pub use self::renderer::{Renderer, ShadowRaster};
pub use self::visibility_at::{MapData, visibility_at};
use crate::error::{Error, Result};
use crate::exec::Outputs;
use crate::gpu::read_texture;
use crate::graph::{Graph, Plan, plan};
use crate::technique;
use crate::{model::Light, scene::Scene};

use crate::model::CameraRays;
use crate::wgsl_mirrors::FrameGpu;

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

/// A point light whose technique its faces cannot bound (`technique::reach`), or whose
/// guard band leaves less than half a face, is refused: scene files are checked when they
/// load, this catches a light built or changed in code.
pub(crate) fn check_point(i: usize, light: &Light) -> Result<()> {
    if light.kind != crate::model::LightKind::Point {
        return Ok(());
    }
    light
        .point_layout()
        .map(|_| ())
        .map_err(|why| Error::Invalid(format!("light[{i}]: {why}")))
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
/// for), and with `opts.dump` every map any node writes.
pub fn plan_lights_for(lights: &[Light], opts: &RenderOptions) -> Result<ScenePlan> {
    let mut graph = Graph::default();
    let mut shade_inputs = Vec::new();
    for (i, l) in lights.iter().enumerate() {
        check_point(i, l)?;
        technique::sat_coding(l).map_err(|e| Error::Invalid(format!("light[{i}]: {e}")))?;
        shade_inputs.push(technique::add_light_nodes(&mut graph, i, l));
    }
    let linear: Vec<String> = (0..lights.len()).map(technique::linear_name).collect();
    // The dump also asks for every map a node writes: the unfused encodings beside the fused
    // encode-and-blur kernels' outputs (`light{i}.vsm` beside `light{i}.vsm.blur`).
    let written: Vec<&str> = graph
        .nodes
        .iter()
        .flat_map(|n| n.outputs.iter().map(|(_, r)| r.as_str()))
        .filter(|_| opts.dump)
        .collect();
    let diagnostics = linear
        .iter()
        .filter(|_| opts.aux || opts.dump)
        .map(String::as_str)
        .chain(written);
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
    let drawn = drawn_lights(scene)?;
    let mut sp = plan_lights_for(&drawn.lights, opts)?;
    if cache::caches(scene) && !opts.dump {
        // What the renderer runs: cached lights' maps in textures of their own.
        sp.plan = cache::dedicate_outputs(sp.plan);
    }
    // A cascaded scene is checked as the lights it draws (its visibility buffer counted for
    // every cascade: an over-estimate).
    let expanded;
    let checked = if drawn.groups.is_empty() {
        scene
    } else {
        expanded = Scene {
            lights: drawn.lights.clone(),
            ..scene.clone()
        };
        &expanded
    };
    crate::limits::check_scene(
        checked,
        &sp,
        &device.limits(),
        device.features(),
        opts,
        crate::limits::memory_budget()?,
        &(0..drawn.lights.len())
            .map(|k| drawn.owner(k).0)
            .collect::<Vec<_>>(),
    )
}

/// Most frames a command's `--repeat` may ask for. Timings keep one row per frame, and on lavapipe (Mesa
/// 22.3.6) every dispatch of the shading kernel keeps about 235 KB that the driver does not
/// return (traced in docs/SCENES.md), so 1000 frames bound that to about 240 MB.
pub const MAX_REPEAT: u32 = 1000;

/// Most frames one [`Renderer::render`] call may run: [`MAX_REPEAT`] timed frames and as many
/// warm-up frames (`evaluate` and `bench` add theirs to the timed ones).
pub const MAX_FRAMES: u32 = 2 * MAX_REPEAT;

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
    /// The plan's resource (texture) it was read from: its own name, or for a table
    /// interleaved with others in one texture ([`crate::graph::Graph::interleaved`]) that
    /// texture's.
    pub texture: String,
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
    /// Per frame, the passes it recorded, by name, in order: each redrawn light's raster
    /// (`light<i>.shadow_raster`, and `light<i>.shadow_peel` where it peels) and plan steps,
    /// then `gbuffer` and `shade`. A light whose map was kept (its `update` rate) has none.
    pub recorded: Vec<Vec<String>>,
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

    /// Reads `texture` (mip 0), the texture of graph resource `resource` of `format`, back.
    pub fn read(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        resource: &str,
        texture: &wgpu::Texture,
        format: wgpu::TextureFormat,
    ) -> Result<Self> {
        Self::read_level(device, queue, resource, texture, format, 0)
    }

    /// Reads mip `level` of `texture` back ([`crate::gpu::read_resource_texture`]).
    pub fn read_level(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        resource: &str,
        texture: &wgpu::Texture,
        format: wgpu::TextureFormat,
        level: u32,
    ) -> Result<Self> {
        let (channels, data) =
            crate::gpu::read_resource_texture(device, queue, texture, level, format)?;
        Ok(Self {
            resource: resource.to_string(),
            width: (texture.width() >> level).max(1),
            height: (texture.height() >> level).max(1),
            channels,
            data,
        })
    }
}

/// Reads the summed-area tables of texture `name` back as the per-texel representations they
/// sum ([`crate::sat::decode_table`]), side by side: `tables` lists the channels of each (the
/// table's input's), one entry for a table of its own, several for tables interleaved along x
/// ([`crate::graph::Graph::interleaved`], in slot order).
pub fn read_sat_map(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    name: &str,
    texture: &wgpu::Texture,
    coding: &crate::sat::SatCoding,
    tables: &[usize],
) -> Result<FloatMap> {
    let raw = crate::gpu::read_texture(device, queue, texture, 0)?;
    let size = (texture.width(), texture.height());
    sat_map_from_words(name, bytemuck::cast_slice(&raw), size, coding, tables)
}

/// [`read_sat_map`] of the table `name` read back as `words` (its texture's or its storage
/// buffer's: the same row-major words) of a `full_width × height` map.
fn sat_map_from_words(
    name: &str,
    words: &[u32],
    (full_width, height): (u32, u32),
    coding: &crate::sat::SatCoding,
    tables: &[usize],
) -> Result<FloatMap> {
    let n = tables.len().max(1);
    let width = full_width / n as u32;
    let per_texel = words.len() / (full_width as usize * height as usize).max(1);
    let maps = tables
        .iter()
        .enumerate()
        .map(|(k, &channels)| FloatMap {
            resource: name.to_string(),
            width,
            height,
            channels,
            data: crate::sat::decode_table(
                &crate::graph::layer_of(words, per_texel, n, k),
                width as usize,
                height as usize,
                coding,
                channels,
            ),
        })
        .collect();
    FloatMap::concat(maps)
}

/// [`read_sat_map`] of plan output `name`, in a texture or in a storage buffer
/// ([`crate::exec::Outputs::buffers`]).
fn read_sat_output(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    outputs: &Outputs,
    name: &str,
    coding: &crate::sat::SatCoding,
    tables: &[usize],
) -> Result<FloatMap> {
    if let Some(t) = outputs.textures.get(name) {
        return read_sat_map(device, queue, name, t, coding, tables);
    }
    let b = outputs
        .buffers
        .get(name)
        .ok_or_else(|| Error::Invalid(format!("the plan has no map `{name}`")))?;
    let encoder = device.create_command_encoder(&Default::default());
    let raw = crate::gpu::submit_and_read(device, queue, encoder, &b.buffer, "read back")?;
    let words: &[u32] = bytemuck::cast_slice(&raw);
    let size = (b.width, b.height);
    sat_map_from_words(name, words, size, coding, tables)
}

/// Adds to `frame` what `opts` asks for besides the image: every resource of the plan
/// (`dump`), the G-buffer and each light's maps (`aux`).
#[expect(clippy::too_many_arguments, reason = "what a frame's read-backs need")]
fn read_extras(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    drawn: &DrawnLights,
    sp: &ScenePlan,
    outputs: &Outputs,
    targets: &targets::Targets,
    opts: RenderOptions,
    mut frame: Frame,
) -> Result<Frame> {
    if opts.dump {
        frame.resources = dump_resources(device, queue, &sp.plan, outputs)?;
    }
    if !opts.aux {
        return Ok(frame);
    }
    frame.position = bytemuck::cast_slice(&read_texture(device, queue, &targets.gpos, 0)?).to_vec();
    frame.normal = bytemuck::cast_slice(&read_texture(device, queue, &targets.gnorm, 0)?).to_vec();
    let format_of = |m: &str| {
        sp.plan
            .resource(m)
            .map_or(wgpu::TextureFormat::R32Float, |r| r.resource.format)
    };
    for (i, input) in sp.shade_inputs.iter().enumerate() {
        let coding = technique::sat_coding(&drawn.lights[i])?;
        let tables = technique::map_tables(&drawn.lights[i]);
        let maps = input
            .maps
            .iter()
            .zip(tables)
            .map(|(m, n)| match &coding {
                Some(c) => read_sat_output(device, queue, outputs, m, c, &n),
                None => FloatMap::read(device, queue, m, &outputs.textures[m], format_of(m)),
            })
            .collect::<Result<Vec<_>>>()?;
        frame.shade_maps.push(FloatMap::concat(maps)?);
        let levels = input.maps.first().map_or(1, |m| outputs.levels(m));
        let mut mips = Vec::new();
        for level in 1..levels {
            let maps = input
                .maps
                .iter()
                .map(|m| {
                    FloatMap::read_level(
                        device,
                        queue,
                        m,
                        &outputs.textures[m],
                        format_of(m),
                        level,
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            mips.push(FloatMap::concat(maps)?);
        }
        frame.shade_mips.push(mips);
        let linear = technique::linear_name(i);
        frame.linear_maps.push(match outputs.textures.get(&linear) {
            Some(t) => Some(FloatMap::read(device, queue, &linear, t, t.format())?),
            None => None,
        });
    }
    Ok(frame)
}

/// Reads back every resource of `plan` (all mip levels) with its provenance.
fn dump_resources(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    plan: &Plan,
    outputs: &Outputs,
) -> Result<Vec<DumpedResource>> {
    plan.resources
        .iter()
        .map(|r| {
            let name = &r.resource.name;
            let levels = (0..outputs.levels(name))
                .map(|mip| {
                    let (width, height, channels, data) =
                        outputs.read_level(device, queue, name, mip, r.resource.format)?;
                    Ok(FloatMap {
                        resource: name.clone(),
                        width,
                        height,
                        channels,
                        data,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            let producer = r.producer.map(|s| plan.steps[s].node.kernel.to_string());
            // Interleaved tables are read back as the tables they hold.
            Ok(split_layers(&r.resource.layers, levels)
                .into_iter()
                .map(|levels| DumpedResource {
                    levels,
                    light: r.resource.light,
                    producer: producer.clone(),
                    format: r.resource.format,
                    texture: name.clone(),
                })
                .collect::<Vec<_>>())
        })
        .collect::<Result<Vec<_>>>()
        .map(|v| v.into_iter().flatten().collect())
}

/// The levels of a texture holding `layers` interleaved along x ([`Graph::interleaved`]) as
/// each layer's levels, named after it; the levels as they are for a plain texture.
///
/// [`Graph::interleaved`]: crate::graph::Graph::interleaved
fn split_layers(layers: &[String], levels: Vec<FloatMap>) -> Vec<Vec<FloatMap>> {
    if layers.is_empty() {
        return vec![levels];
    }
    let n = layers.len();
    layers
        .iter()
        .enumerate()
        .map(|(k, name)| {
            levels
                .iter()
                .map(|m| FloatMap {
                    resource: name.clone(),
                    width: m.width / n as u32,
                    height: m.height,
                    channels: m.channels,
                    data: crate::graph::layer_of(&m.data, m.channels, n, k),
                })
                .collect()
        })
        .collect()
}
