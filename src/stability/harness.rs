//! Running kernels for the suite: upload, plan, run with outputs poisoned (so unwritten texels
//! show), read back whole textures or single texels, and the light and receivers the shading
//! probes use.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use crate::cpu::{self, Texels};
use crate::error::{Error, Result};
use crate::exec::{Executor, Outputs};
use crate::gpu::{Gpu, read_buffer, submit_and_wait, write_texture_level};
use crate::graph::{Graph, Plan, plan, texel_bytes};
use crate::model::{Light, LightKind, Shadow, Technique};
use crate::model::{ParamValue, ParamValues};
use crate::render::{MapData, Renderer, visibility_at};
use crate::{
    technique::{self, params},
    wgsl_mirrors::LightGpu,
};

/// A sampled, copyable texture holding `bytes` (tightly packed level 0).
pub(crate) fn upload(
    gpu: &Gpu,
    (w, h): (u32, u32),
    format: wgpu::TextureFormat,
    bytes: &[u8],
) -> wgpu::Texture {
    let t = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("shadowgraph.stability.input"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    write_texture_level(&gpu.queue, &t, 0, bytes);
    t
}

/// A finished run: the plan, its textures and the kernels' replaced-texel count.
pub(crate) struct Ran {
    /// What ran.
    pub plan: Plan,
    /// Every planned resource's texture.
    pub outputs: Outputs,
    /// Non-finite depth texels replaced (by `linearize` or an encoding reading the depth): the
    /// most any one step counted.
    pub replaced: u32,
}

/// What [`run_graph`] fills with all-ones bytes (NaN for floats) before the kernels run, so
/// texels the kernels fail to write show.
pub(crate) enum Poison<'a> {
    /// Every level of every planned texture.
    All,
    /// Only these texels of level 0 of this resource (a table of hundreds of MiB is not rewritten whole).
    Texels(&'a str, &'a [(u32, u32)]),
}

/// Plans `outputs` of `graph` (every resource in its own texture when `keep_all`, so
/// intermediates stay readable), records it with `imports`, poisons, submits and waits.
pub(crate) fn run_graph(
    gpu: &Gpu,
    exec: &mut Executor,
    graph: &Graph,
    outputs: &[&str],
    imports: HashMap<String, wgpu::Texture>,
    keep_all: bool,
    poison: Poison,
) -> Result<Ran> {
    let mut plan = plan(graph, outputs)?;
    if keep_all {
        plan = plan.unaliased();
    }
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    let out = exec.record(&gpu.device, &mut enc, &plan, &imports, None)?;
    // Queue writes land before the command buffers submitted after them.
    match poison {
        Poison::All => {
            for r in plan.resources.iter().filter(|r| r.slot.is_some()) {
                if let Some(b) = out.buffers.get(&r.resource.name) {
                    gpu.queue
                        .write_buffer(&b.buffer, 0, &vec![0xFF; b.buffer.size() as usize]);
                    continue;
                }
                let t = &out.textures[&r.resource.name];
                for level in 0..t.mip_level_count() {
                    let (w, h) = ((t.width() >> level).max(1), (t.height() >> level).max(1));
                    let bytes = texel_bytes(t.format()) as usize * (w * h) as usize;
                    write_texture_level(&gpu.queue, t, level, &vec![0xFF; bytes]);
                }
            }
        }
        Poison::Texels(name, coords) => {
            let t = out
                .textures
                .get(name)
                .ok_or_else(|| Error::Invalid(format!("the plan has no resource `{name}`")))?;
            poison_texels(gpu, t, coords);
        }
    }
    out.copy_stats(&mut enc);
    submit_and_wait(&gpu.device, &gpu.queue, enc, "stability")?;
    // Every step that reads the depth (linearize, a fused encoding, each basis dispatch)
    // counts the same texels: the most any one counted is the number replaced.
    let replaced = out
        .read_stats(&gpu.device)?
        .iter()
        .map(|&(_, n)| n)
        .max()
        .unwrap_or(0);
    Ok(Ran {
        plan,
        outputs: out,
        replaced,
    })
}

impl Ran {
    /// Mip `level` of resource `name` as f64 texels.
    pub(crate) fn texels(&self, gpu: &Gpu, name: &str, level: u32) -> Result<Texels> {
        let format = self
            .plan
            .resource(name)
            .map(|r| r.resource.format)
            .ok_or_else(|| Error::Invalid(format!("the plan has no resource `{name}`")))?;
        let (w, h, channels, data) =
            self.outputs
                .read_level(&gpu.device, &gpu.queue, name, level, format)?;
        Ok(Texels::from_f32(w as usize, h as usize, channels, &data))
    }

    /// Every level of resource `name`.
    pub(crate) fn levels(&self, gpu: &Gpu, name: &str) -> Result<Vec<Texels>> {
        let n = self.outputs.levels(name).max(1);
        (0..n).map(|level| self.texels(gpu, name, level)).collect()
    }
}

/// The 16-byte texels of `texture` (level 0) at `coords`, each copied alone into one buffer:
/// reads a few thousand texels of a large table without copying the table.
pub(crate) fn read_texels(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    coords: &[(u32, u32)],
) -> Result<Vec<[u32; 4]>> {
    let bytes = texel_bytes(texture.format());
    if ![4, 8, 16].contains(&bytes) || coords.is_empty() {
        return Err(Error::Invalid(format!(
            "read_texels reads 4-, 8- or 16-byte texels at one or more places, not {:?}",
            texture.format()
        )));
    }
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("shadowgraph.stability.texels"),
        size: 16 * coords.len() as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    for (i, &(x, y)) in coords.iter().enumerate() {
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 16 * i as u64,
                    bytes_per_row: None,
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
    submit_and_wait(&gpu.device, &gpu.queue, enc, "stability texel readback")?;
    let raw = read_buffer(&gpu.device, &buffer)?;
    // Each texel's words at the start of its 16 bytes; the channels a format lacks read 0.
    let words = (bytes / 4) as usize;
    Ok(bytemuck::cast_slice::<u8, [u32; 4]>(&raw)
        .iter()
        .map(|t| std::array::from_fn(|c| if c < words { t[c] } else { 0 }))
        .collect())
}

/// Fills the texels of `texture` (level 0) at `coords` with all-ones bytes.
pub(crate) fn poison_texels(gpu: &Gpu, texture: &wgpu::Texture, coords: &[(u32, u32)]) {
    let bytes = vec![0xFF; texel_bytes(texture.format()) as usize];
    for &(x, y) in coords {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: None,
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
    }
}

/// A light of `kind` over the origin with `technique`, a `map`-texel square map and constant
/// bias `bias` (no slope bias: the suite's depth buffers are given, not rasterized).
pub(crate) fn light(kind: LightKind, technique: Technique, map: u32, bias: f32) -> Light {
    let (position, near, far) = match kind {
        LightKind::Directional { .. } => (Vec3::new(-3.0, 10.0, 2.0), 2.0, 20.0),
        LightKind::Spot { .. } | LightKind::Point => (Vec3::new(1.0, 8.0, -1.0), 0.5, 20.0),
    };
    Light {
        kind,
        position,
        target: Vec3::ZERO,
        near,
        far,
        size: 0.5,
        radiance: Vec3::ONE,
        shadow_map: map,
        shadow: Shadow {
            technique,
            bias,
            slope_bias: 0.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: crate::model::Cascades::SINGLE,
        },
    }
}

/// The mip-chain filter at `width` texels (the one place that spells its fields).
pub(crate) fn mips(width: f32) -> crate::model::Filter {
    crate::model::Filter::Mips {
        width,
        max_anisotropy: 0,
    }
}

/// Technique `name` of the registry at `storage` (when it has a `format` key) with `filter`
/// and `values` over its defaults, taken as they are: the suite probes exponents past the
/// clamps a scene applies.
pub(crate) fn registered(
    name: &str,
    storage: Option<crate::model::Storage>,
    filter: crate::model::Filter,
    values: &[(&'static str, ParamValue)],
) -> Technique {
    let mut v = ParamValues(values.to_vec());
    if let Some(s) = storage {
        v.set("format", ParamValue::Choice(params::storage_name(s)));
    }
    params::filter_values(&filter, &mut v);
    technique::by_name(name)
        .and_then(|def| technique::build_with(def, &v))
        .expect("the suite names registered techniques and their keys")
}

/// The suite's directional light (orthographic: the raw depth buffer is the linear depth).
pub(crate) const DIRECTIONAL: LightKind = LightKind::Directional { extent: 5.0 };
/// The suite's spot light.
pub(crate) const SPOT: LightKind = LightKind::Spot { fov_degrees: 60.0 };

/// The world point at map `uv` and linear depth `d` of `l`, with a normal toward the light
/// (so the normal offset is zero and the receiver keeps depth `d`, up to f32 roundings).
pub(crate) fn receiver(l: &Light, uv: [f64; 2], d: f64) -> (Vec3, Vec3) {
    let g = LightGpu::new(l);
    let ndc_z = cpu::light::linear_to_ndc(&g, d);
    let inv = (l.projection() * l.view()).as_dmat4().inverse();
    let p = inv.project_point3(DVec3::new(2.0 * uv[0] - 1.0, 1.0 - 2.0 * uv[1], ndc_z));
    let n = cpu::light::to_light(&g, p);
    (p.as_vec3(), n.as_vec3())
}

/// The f64 light sample of a receiver exactly as the GPU gets it (the f32 point).
pub(crate) fn sample(l: &Light, (p, n): (Vec3, Vec3)) -> cpu::light::LightSample {
    cpu::light::sample(&LightGpu::new(l), p.as_dvec3(), n.as_dvec3())
}

/// Runs light `l`'s scene graph (`technique::add_light_nodes`: linearize, encoding, filter) on
/// the raw depth buffer `raw` (`size²` texels, R32Float so that NaN and ±Inf can be stored),
/// every resource kept. Returns the run and the maps the shading reads.
pub(crate) fn run_light(
    gpu: &Gpu,
    exec: &mut Executor,
    l: &Light,
    raw: &[f32],
) -> Result<(Ran, Vec<String>)> {
    let size = l.shadow_map;
    if raw.len() != (size * size) as usize {
        return Err(Error::Invalid(format!(
            "a {size}² depth buffer needs {} texels, got {}",
            size * size,
            raw.len()
        )));
    }
    let mut graph = Graph::default();
    let input = technique::add_light_nodes(&mut graph, 0, l);
    let depth = upload(
        gpu,
        (size, size),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(raw),
    );
    let imports = HashMap::from([(technique::depth_name(0), depth)]);
    // The linear map too: the stages are judged against it (the encodings linearize the depth
    // themselves through the same WGSL function).
    let linear = technique::linear_name(0);
    let mut outputs: Vec<&str> = input.maps.iter().map(String::as_str).collect();
    outputs.push(&linear);
    // And every map a node writes: an encoding fused into its blur is judged against the
    // unfused encoding (the same WGSL function) and, past the one-dispatch radius, its
    // horizontal pass.
    outputs.extend(
        graph
            .nodes
            .iter()
            .flat_map(|n| n.outputs.iter().map(|(_, r)| r.as_str())),
    );
    let ran = run_graph(gpu, exec, &graph, &outputs, imports, true, Poison::All)?;
    Ok((ran, input.maps))
}

/// Visibility of `l` at `points` with the real shading kernel on `maps` (every level of each
/// map the light binds, as read back: `visibility_at` uploads them as 32-bit floats). Reuse one
/// `renderer` per technique: it keeps the compiled shading kernel.
pub(crate) fn shade(
    gpu: &Gpu,
    renderer: &mut Renderer,
    l: &Light,
    maps: &[Vec<Texels>],
    points: &[(Vec3, Vec3)],
) -> Result<Vec<f32>> {
    let data: Vec<(wgpu::TextureFormat, Vec<f32>)> = maps
        .iter()
        .map(|levels| {
            let channels = levels[0].channels;
            let format = match channels {
                1 => wgpu::TextureFormat::R32Float,
                2 => wgpu::TextureFormat::Rg32Float,
                _ => wgpu::TextureFormat::Rgba32Float,
            };
            let v = levels
                .iter()
                .flat_map(|t| t.data.iter().map(|&x| x as f32))
                .collect();
            (format, v)
        })
        .collect();
    let map_data: Vec<MapData> = maps
        .iter()
        .zip(&data)
        .map(|(levels, (format, v))| MapData {
            size: levels[0].width as u32,
            format: *format,
            mips: levels.len() as u32,
            data: v,
        })
        .collect();
    visibility_at(
        renderer,
        &gpu.device,
        &gpu.queue,
        std::slice::from_ref(l),
        &map_data,
        points,
    )
}
