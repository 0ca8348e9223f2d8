//! What each shadow technique needs: the graph nodes that build its maps, the maps the shading
//! pass reads, the WGSL visibility call, and the GPU mirror of a light.

use std::fmt::Write;

use crate::filter::{BlurMode, add_filter};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::scene::{Filter, Light, LightKind, PcfKernel, Storage, Technique};

/// A light as the shading kernel reads it. Mirrors `struct Light` in
/// `kernels/shared/light.wgsl` (a test checks the size against naga's layout).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightGpu {
    /// World → light clip.
    pub view_proj: [[f32; 4]; 4],
    /// World → light view.
    pub view: [[f32; 4]; 4],
    /// Colour × intensity.
    pub radiance: [f32; 3],
    /// 0 directional, 1 spot.
    pub kind: u32,
    /// Light position.
    pub position: [f32; 3],
    /// Near plane.
    pub near: f32,
    /// Unit direction light → target.
    pub direction: [f32; 3],
    /// Far plane.
    pub far: f32,
    /// Shadow-map size in texels.
    pub map_size: [f32; 2],
    /// Map width in world units (directional) or per unit distance (spot).
    pub width_at_unit: f32,
    /// Area-light width.
    pub size: f32,
    /// Constant bias, linear depth units.
    pub bias: f32,
    /// Normal offset, texels.
    pub normal_bias: f32,
    /// Spot: cos(fov/2); directional: −1.
    pub cos_outer: f32,
    /// 0 hard, 1 pcf, 2 pcss, 3 vsm, 4 evsm, 5 esm, 6 msm, 7 csm.
    pub technique: u32,
    /// PCF radius.
    pub radius: u32,
    /// PCF kernel: 0 box, 1 tent, 2 hardware.
    pub kernel: u32,
    /// PCSS blocker taps.
    pub blocker_samples: u32,
    /// PCSS filter taps.
    pub filter_samples: u32,
    /// PCSS search cap (UV).
    pub max_search: f32,
    /// VSM light-bleeding reduction.
    pub bleed: f32,
    /// VSM/EVSM minimum variance (depth units²).
    pub min_variance: f32,
    /// EVSM positive exponent; ESM exponent.
    pub exp_pos: f32,
    /// EVSM negative exponent.
    pub exp_neg: f32,
    /// EVSM: 2 or 4 stored moments.
    pub moments: u32,
    /// MSM moment bias α.
    pub moment_bias: f32,
    /// MSM: bit 0 Hausdorff (else Hamburger), bit 1 quantized storage.
    pub msm_flags: u32,
    /// CSM terms M.
    pub csm_terms: u32,
    /// CSM ringing attenuation α.
    pub csm_attenuation: f32,
    /// CSM receiver-depth offset.
    pub csm_offset: f32,
    /// CSM response scale.
    pub csm_scale: f32,
    /// Mip levels of the filtered map (0 when the filter is not `mips`).
    pub mip_levels: u32,
    /// `log2` of the mip filter width in texels.
    pub filter_lod: f32,
    /// Padding to the WGSL struct's 16-byte alignment.
    pub _pad: [u32; 2],
}

/// MSM flag: Hausdorff reconstruction.
pub const MSM_HAUSDORFF: u32 = 1;
/// MSM flag: moments stored through the optimized quantization.
pub const MSM_QUANTIZED: u32 = 2;

impl LightGpu {
    /// The GPU description of `light`.
    pub fn new(light: &Light) -> Self {
        let view = light.view();
        let (technique, radius, kernel, blocker_samples, filter_samples, max_search) =
            match light.shadow.technique {
                Technique::Hard => (0, 0, 0, 0, 0, 0.0),
                Technique::Pcf { radius, kernel } => {
                    let k = match kernel {
                        PcfKernel::Box => 0,
                        PcfKernel::Tent => 1,
                        PcfKernel::Hardware => 2,
                    };
                    (1, radius, k, 0, 0, 0.0)
                }
                Technique::Pcss {
                    blocker_samples,
                    filter_samples,
                    max_search,
                } => (2, 0, 0, blocker_samples, filter_samples, max_search),
                Technique::Vsm { .. } => (3, 0, 0, 0, 0, 0.0),
                Technique::Evsm { .. } => (4, 0, 0, 0, 0, 0.0),
                Technique::Esm { .. } => (5, 0, 0, 0, 0, 0.0),
                Technique::Msm { .. } => (6, 0, 0, 0, 0, 0.0),
                Technique::Csm { .. } => (7, 0, 0, 0, 0, 0.0),
            };
        let (bleed, min_variance, exp_pos, exp_neg, moments) = match light.shadow.technique {
            Technique::Vsm {
                bleed,
                min_variance,
                ..
            } => (bleed, min_variance, 0.0, 0.0, 2),
            Technique::Evsm {
                four,
                exp_pos,
                exp_neg,
                bleed,
                min_variance,
                ..
            } => (
                bleed,
                min_variance,
                exp_pos,
                exp_neg,
                if four { 4 } else { 2 },
            ),
            Technique::Esm { exponent, .. } => (0.0, 0.0, exponent, 0.0, 1),
            Technique::Msm { bleed, .. } => (bleed, 0.0, 0.0, 0.0, 4),
            _ => (0.0, 0.0, 0.0, 0.0, 0),
        };
        let (moment_bias, msm_flags) = match light.shadow.technique {
            Technique::Msm {
                prefilter,
                hausdorff,
                moment_bias,
                ..
            } => (
                moment_bias,
                u32::from(hausdorff) * MSM_HAUSDORFF
                    + u32::from(msm_quantized(prefilter.storage)) * MSM_QUANTIZED,
            ),
            _ => (0.0, 0),
        };
        let (csm_terms, csm_attenuation, csm_offset, csm_scale) = match light.shadow.technique {
            Technique::Csm {
                terms,
                attenuation,
                offset,
                scale,
                ..
            } => (terms, attenuation, offset, scale),
            _ => (0, 0.0, 0.0, 1.0),
        };
        let (mip_levels, filter_lod) = match light.shadow.technique.filter() {
            Some(Filter::Mips { width }) => (
                mip_levels(light.shadow_map, light.shadow_map),
                width.max(1.0).log2(),
            ),
            _ => (0, 0.0),
        };
        let (kind, cos_outer) = match light.kind {
            LightKind::Directional { .. } => (0, -1.0),
            LightKind::Spot { fov_degrees } => (1, (0.5 * fov_degrees.to_radians()).cos()),
        };
        Self {
            view_proj: (light.projection() * view).to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            radiance: light.radiance.to_array(),
            kind,
            position: light.position.to_array(),
            near: light.near,
            direction: light.direction().to_array(),
            far: light.far,
            map_size: [light.shadow_map as f32; 2],
            width_at_unit: light.width_at_unit(),
            size: light.size,
            bias: light.shadow.bias,
            normal_bias: light.shadow.normal_bias,
            cos_outer,
            technique,
            radius,
            kernel,
            blocker_samples,
            filter_samples,
            max_search,
            bleed,
            min_variance,
            exp_pos,
            exp_neg,
            moments,
            moment_bias,
            msm_flags,
            csm_terms,
            csm_attenuation,
            csm_offset,
            csm_scale,
            mip_levels,
            filter_lod,
            _pad: [0; 2],
        }
    }
}

/// Parameters of `kernels/linearize.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LinearizeParams {
    /// 1 for a perspective (spot) depth buffer.
    pub perspective: u32,
    /// Near plane.
    pub near: f32,
    /// Far plane.
    pub far: f32,
    /// Padding.
    pub _pad: u32,
}

impl LinearizeParams {
    /// Parameters for `light`'s depth buffer.
    pub fn new(light: &Light) -> Self {
        Self {
            perspective: u32::from(matches!(light.kind, LightKind::Spot { .. })),
            near: light.near,
            far: light.far,
            _pad: 0,
        }
    }
}

/// Name of light `i`'s rasterized depth map (imported into the graph).
pub fn depth_name(i: usize) -> String {
    format!("light{i}.depth")
}

/// Name of light `i`'s linear depth map.
pub fn linear_name(i: usize) -> String {
    format!("light{i}.linear")
}

/// Adds the nodes light `i`'s technique needs to `graph` and returns what the shading pass
/// reads. The raw depth map and the linear map are always declared; the planner drops what the
/// shading pass does not read (e.g. `linearize` for the hardware comparison sampler).
pub fn add_light_nodes(graph: &mut Graph, i: usize, light: &Light) -> ShadeInput {
    let depth = graph.import(
        depth_name(i),
        wgpu::TextureFormat::Depth32Float,
        light.shadow_map,
        light.shadow_map,
        Some(i),
    );
    let linear = graph.resource(
        linear_name(i),
        wgpu::TextureFormat::R32Float,
        SizeRule::Reduced {
            of: depth.clone(),
            shift: 0,
        },
        Some(i),
    );
    graph.node(Node {
        name: format!("light{i}.linearize"),
        kernel: "linearize".into(),
        inputs: vec![("src".into(), depth.clone())],
        outputs: vec![("dst".into(), linear.clone())],
        params: bytemuck::bytes_of(&LinearizeParams::new(light)).to_vec(),
        dispatch: Dispatch::Texels(linear.clone()),
        light: Some(i),
    });
    let float = "texture_2d<f32>";
    let one = |resource: String, wgsl_type| ShadeInput {
        maps: vec![resource],
        wgsl_type,
    };
    match light.shadow.technique {
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        } => one(depth, "texture_depth_2d"),
        Technique::Hard | Technique::Pcf { .. } | Technique::Pcss { .. } => one(linear, float),
        Technique::Vsm { prefilter, .. } => {
            let format = moments_format(prefilter.storage, 2);
            let moments = encode(graph, i, "vsm", "vsm", &linear, format, Vec::new());
            one(
                add_filter(graph, i, &moments, &prefilter.filter, BlurMode::Linear),
                float,
            )
        }
        Technique::Evsm {
            prefilter,
            four,
            exp_pos,
            exp_neg,
            ..
        } => {
            let format = moments_format(prefilter.storage, if four { 4 } else { 2 });
            let params = bytemuck::bytes_of(&ExpParams::new(exp_pos, exp_neg)).to_vec();
            let moments = encode(graph, i, "evsm", "evsm", &linear, format, params);
            one(
                add_filter(graph, i, &moments, &prefilter.filter, BlurMode::Linear),
                float,
            )
        }
        Technique::Esm { filter, exponent } => {
            let params = bytemuck::bytes_of(&ExpParams::new(exponent, 0.0)).to_vec();
            let format = wgpu::TextureFormat::R32Float;
            let log_moment = encode(graph, i, "esm", "esm", &linear, format, params);
            one(
                add_filter(graph, i, &log_moment, &filter, BlurMode::LogSumExp),
                float,
            )
        }
        Technique::Msm { prefilter, .. } => {
            let format = moments_format(prefilter.storage, 4);
            let params = bytemuck::bytes_of(&MsmParams {
                quantized: u32::from(msm_quantized(prefilter.storage)),
                _pad: [0; 3],
            })
            .to_vec();
            let moments = encode(graph, i, "msm", "msm", &linear, format, params);
            one(
                add_filter(graph, i, &moments, &prefilter.filter, BlurMode::Linear),
                float,
            )
        }
        Technique::Csm {
            prefilter, terms, ..
        } => {
            let maps = (0..csm_maps(terms))
                .map(|chunk| {
                    let pairs = (terms - 2 * chunk).min(2);
                    let format = moments_format(prefilter.storage, 2 * pairs);
                    let params = bytemuck::bytes_of(&CsmParams {
                        first_term: 2 * chunk + 1,
                        terms,
                        _pad: [0; 2],
                    })
                    .to_vec();
                    let name = format!("csm{chunk}");
                    let basis = encode(graph, i, "csm", &name, &linear, format, params);
                    add_filter(graph, i, &basis, &prefilter.filter, BlurMode::Linear)
                })
                .collect();
            ShadeInput {
                maps,
                wgsl_type: float,
            }
        }
    }
}

/// Number of mip levels of a full chain for a `width`×`height` map (down to 1×1).
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// Whether MSM at `storage` keeps its moments through the optimized quantization (every
/// 16-bit storage does; f32 keeps the raw powers).
pub fn msm_quantized(storage: Storage) -> bool {
    storage != Storage::F32
}

/// Four-channel basis maps CSM with `terms` terms needs (two channels per term).
pub fn csm_maps(terms: u32) -> u32 {
    terms.div_ceil(2)
}

/// Parameters of `kernels/msm.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MsmParams {
    /// 1: store the optimized quantization of the moments; 0: the raw powers.
    pub quantized: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// Parameters of `kernels/csm.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CsmParams {
    /// Term k of the map's first pair (channels sin, cos of c_k z, then of c_{k+1} z).
    pub first_term: u32,
    /// Total terms M (a pair past M is written as zeros).
    pub terms: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

/// Parameters of `kernels/evsm.wgsl` and `kernels/esm.wgsl` (mirror their `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ExpParams {
    /// c⁺ (EVSM) or c (ESM).
    pub exp_pos: f32,
    /// c⁻ (EVSM4).
    pub exp_neg: f32,
    /// Padding.
    pub _pad: [f32; 2],
}

impl ExpParams {
    /// Exponents `pos`, `neg`.
    pub fn new(exp_pos: f32, exp_neg: f32) -> Self {
        Self {
            exp_pos,
            exp_neg,
            _pad: [0.0; 2],
        }
    }
}

/// The texel format of a `channels`-moment representation (2 or 4) at `storage` precision.
pub fn moments_format(storage: Storage, channels: u32) -> wgpu::TextureFormat {
    match (storage, channels) {
        (Storage::F32, 2) => wgpu::TextureFormat::Rg32Float,
        (Storage::F32, _) => wgpu::TextureFormat::Rgba32Float,
        // rg16float is no core storage format; rgba16float is.
        (Storage::F16, _) => wgpu::TextureFormat::Rgba16Float,
        (Storage::Unorm16, _) => wgpu::TextureFormat::Rgba16Unorm,
    }
}

/// Adds the encoding node `kernel` (linear depth → representation) of light `i`, writing
/// `light{i}.{name}`; the output's format picks the kernel's storage variant.
fn encode(
    graph: &mut Graph,
    i: usize,
    kernel: &str,
    name: &str,
    linear: &str,
    format: wgpu::TextureFormat,
    params: Vec<u8>,
) -> String {
    let out = graph.resource(
        format!("light{i}.{name}"),
        format,
        SizeRule::Reduced {
            of: linear.to_string(),
            shift: 0,
        },
        Some(i),
    );
    graph.node(Node {
        name: format!("light{i}.{name}"),
        kernel: kernel.into(),
        inputs: vec![("src".into(), linear.to_string())],
        outputs: vec![("dst".into(), out.clone())],
        params,
        dispatch: Dispatch::Texels(out.clone()),
        light: Some(i),
    });
    out
}

/// How the shading kernel reads a light's maps.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShadeInput {
    /// Graph resources bound, in binding order (one for every technique but CSM, which binds
    /// one map per two terms).
    pub maps: Vec<String>,
    /// WGSL type of each binding.
    pub wgsl_type: &'static str,
}

/// The module light `light`'s visibility function lives in, and the WGSL statements (ending in
/// a `return`) that evaluate it with `l`, `s` in scope and its maps bound as `maps`.
pub fn visibility_body(light: &Light, maps: &[String]) -> (&'static str, String) {
    let map = maps.first().map_or("", String::as_str);
    let call = |module, f: &str| (module, format!("return {f}({map}, l, s);"));
    match light.shadow.technique {
        Technique::Hard => call("shared/vis_hard", "vis_hard"),
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        } => (
            "shared/vis_pcf",
            format!("return vis_pcf_hardware({map}, cmp_sampler, l, s);"),
        ),
        Technique::Pcf { .. } => call("shared/vis_pcf", "vis_pcf"),
        Technique::Pcss { .. } => call("shared/vis_pcss", "vis_pcss"),
        Technique::Vsm { .. } => call("shared/vis_vsm", "vis_vsm"),
        Technique::Evsm { .. } => call("shared/vis_evsm", "vis_evsm"),
        Technique::Esm { .. } => call("shared/vis_esm", "vis_esm"),
        Technique::Msm { .. } => call("shared/vis_msm", "vis_msm"),
        Technique::Csm { .. } => {
            let mut body = String::from("var sum = 0.0;");
            for (chunk, m) in maps.iter().enumerate() {
                let _ = write!(body, "\n            sum += csm_chunk({m}, {chunk}u, l, s);");
            }
            body.push_str("\n            return csm_resolve(sum, l);");
            ("shared/vis_csm", body)
        }
    }
}

/// The `// #generated` block of `kernels/shade.wgsl` for these lights: imports of the
/// techniques used, one group-1 binding per map (light by light, in [`ShadeInput::maps`]
/// order), one visibility function per light and `light_visibility`, which dispatches on the
/// light index. Every invocation evaluates its lights' visibility, also outside the map (then
/// discarded by a `select`): llvmpipe (lavapipe) mis-fetches explicit mip levels when some
/// invocations of a SIMD group have left the code path, so no path branches before sampling.
pub fn shading_block(lights: &[Light]) -> String {
    let mut imports: Vec<&str> = Vec::new();
    let mut bindings = String::new();
    let mut cases = String::new();
    let mut functions = String::new();
    let mut binding = 0;
    for (i, light) in lights.iter().enumerate() {
        let input = add_light_nodes(&mut Graph::default(), i, light);
        let maps: Vec<String> = (0..input.maps.len())
            .map(|k| format!("light{i}_map{k}"))
            .collect();
        let (module, body) = visibility_body(light, &maps);
        if !imports.contains(&module) {
            imports.push(module);
        }
        for map in &maps {
            let _ = writeln!(
                bindings,
                "@group(1) @binding({binding}) var {map}: {};",
                input.wgsl_type
            );
            binding += 1;
        }
        let _ = writeln!(
            functions,
            "fn light{i}_visibility(l: Light, s: LightSample) -> f32 {{\n    {body}\n}}"
        );
        let _ = writeln!(
            cases,
            "        case {i}u: {{\n            let l = lights[{i}];\n            let s = light_sample(l, p, n);\n            return select(1.0, light{i}_visibility(l, s), s.inside);\n        }}"
        );
    }
    let mut s = String::new();
    for m in imports {
        let _ = writeln!(s, "// #import {m}");
    }
    s.push_str(&bindings);
    s.push_str(&functions);
    let _ = write!(
        s,
        "fn light_visibility(i: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {{\n    switch i {{\n{cases}        default: {{ return 1.0; }}\n    }}\n}}\n"
    );
    s
}
