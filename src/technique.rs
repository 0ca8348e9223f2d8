//! What each shadow technique needs: the graph nodes that build its maps, the maps the shading
//! pass reads, the WGSL visibility call, and the GPU mirror of a light.

use std::fmt::Write;

use crate::filter::{BlurMode, add_filter};
pub use crate::gpu_data::{
    CSM_OUTPUTS, CsmParams, ExpParams, LightGpu, LinearizeParams, MSM_HAUSDORFF, MSM_QUANTIZED,
    MsmParams, VsmParams,
};
use crate::gpu_data::{
    TECHNIQUE_CSM, TECHNIQUE_CSSM, TECHNIQUE_ESM, TECHNIQUE_EVSM, TECHNIQUE_HARD, TECHNIQUE_MSM,
    TECHNIQUE_MSM_SOFT, TECHNIQUE_PCF, TECHNIQUE_PCSS, TECHNIQUE_VSM, TECHNIQUE_VSSM,
};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
pub use crate::model::mip_levels;
use crate::model::{Filter, Light, LightKind, PcfKernel, Prefilter, Soft, Storage, Technique};
use crate::sat::{SatCoding, SatVariant, add_sat, lookup_area};

impl LightGpu {
    /// The GPU description of `light`.
    pub fn new(light: &Light) -> Self {
        let view = light.view();
        let (technique, radius, kernel, blocker_samples, filter_samples, max_search) = match light
            .shadow
            .technique
        {
            Technique::Hard => (TECHNIQUE_HARD, 0, 0, 0, 0, 0.0),
            Technique::Pcf { radius, kernel } => {
                let k = match kernel {
                    PcfKernel::Box => 0,
                    PcfKernel::Tent => 1,
                    PcfKernel::Hardware => 2,
                };
                (TECHNIQUE_PCF, radius, k, 0, 0, 0.0)
            }
            Technique::Pcss {
                blocker_samples,
                filter_samples,
                max_search,
            } => (
                TECHNIQUE_PCSS,
                0,
                0,
                blocker_samples,
                filter_samples,
                max_search,
            ),
            Technique::Vsm { .. } => (TECHNIQUE_VSM, 0, 0, 0, 0, 0.0),
            Technique::Evsm { .. } => (TECHNIQUE_EVSM, 0, 0, 0, 0, 0.0),
            Technique::Esm { .. } => (TECHNIQUE_ESM, 0, 0, 0, 0, 0.0),
            Technique::Msm { .. } => (TECHNIQUE_MSM, 0, 0, 0, 0, 0.0),
            Technique::Csm { .. } => (TECHNIQUE_CSM, 0, 0, 0, 0, 0.0),
            Technique::Cssm { soft, .. } => (TECHNIQUE_CSSM, 0, 0, 0, 0, soft.max_search),
            Technique::Vssm { soft, .. } => (TECHNIQUE_VSSM, 0, 0, 0, 0, soft.max_search),
            Technique::MsmSoft { soft, .. } => (TECHNIQUE_MSM_SOFT, 0, 0, 0, 0, soft.max_search),
        };
        let (bleed, min_variance, exp_pos, exp_neg, moments) = match light.shadow.technique {
            Technique::Vsm {
                bleed,
                min_variance,
                ..
            }
            | Technique::Vssm {
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
            Technique::Msm { bleed, .. } | Technique::MsmSoft { bleed, .. } => {
                (bleed, 0.0, 0.0, 0.0, 4)
            }
            _ => (0.0, 0.0, 0.0, 0.0, 0),
        };
        let (moment_bias, msm_flags) = match light.shadow.technique {
            Technique::Msm {
                hausdorff,
                moment_bias,
                ..
            }
            | Technique::MsmSoft {
                hausdorff,
                moment_bias,
                ..
            } => (
                moment_bias,
                msm_flags(hausdorff, msm_quantized(&light.shadow.technique)),
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
            }
            | Technique::Cssm {
                terms,
                attenuation,
                offset,
                scale,
                ..
            } => (terms, attenuation, offset, scale),
            _ => (0, 0.0, 0.0, 1.0),
        };
        let (sharpen, sharpen_falloff) = match light.shadow.technique {
            Technique::Cssm {
                sharpen,
                sharpen_falloff,
                ..
            } => (sharpen, sharpen_falloff),
            _ => (0.0, 0.0),
        };
        let (mip_levels, filter_lod, max_anisotropy) = match light.shadow.technique.filter() {
            Some(Filter::Mips {
                width,
                max_anisotropy,
            }) => (
                mip_levels(light.shadow_map, light.shadow_map),
                width.max(1.0).log2(),
                max_anisotropy,
            ),
            _ => (0, 0.0, 0),
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
            filter_width: 0.0,
            max_anisotropy,
            sat_offset: [0.0; 4],
            sat_scale: [1.0; 4],
            sharpen,
            sharpen_falloff,
            max_width: soft_max_width(light).unwrap_or(0.0),
            _pad1: 0,
        }
        .with_sat(light)
    }

    /// The SAT fields for `light` (left as they are without a summed-area table or when its
    /// coding is invalid, which [`sat_coding`] reports). A soft technique's width is per
    /// receiver: `filter_width` stays 0.
    fn with_sat(mut self, light: &Light) -> Self {
        if let Ok(Some(c)) = sat_coding(light) {
            if let Some(Filter::Sat { width, .. }) = light.shadow.technique.filter() {
                self.filter_width = width;
            }
            self.sat_offset = c.offset;
            self.sat_scale = c.scale;
        }
        self
    }
}

/// The MSM flags of a reconstruction and representation.
fn msm_flags(hausdorff: bool, quantized: bool) -> u32 {
    u32::from(hausdorff) * MSM_HAUSDORFF + u32::from(quantized) * MSM_QUANTIZED
}

/// The largest square a soft technique reads (blocker search or filter), in texels:
/// `2·max_search·map_size`, clamped to `[1, map_size]` (a larger square is clamped to the map
/// by the lookups anyway); `None` for other techniques. Per-receiver widths are clamped to it
/// in `kernels/shared/blocker.wgsl`, and the fixed-point table is coded for it.
pub fn soft_max_width(light: &Light) -> Option<f32> {
    let soft = light.shadow.technique.soft()?;
    Some(soft_width_cap(soft.max_search, light.shadow_map))
}

/// [`soft_max_width`] for a search cap `max_search` (UV) on a `map`² shadow map.
pub fn soft_width_cap(max_search: f32, map: u32) -> f32 {
    let n = map as f32;
    (2.0 * max_search * n).clamp(1.0, n.max(1.0))
}

/// The window area a soft technique's fixed-point table is coded for: [`lookup_area`] of
/// its width cap plus one texel (the rectangle's edges are formed in f32 from a per-receiver
/// width).
pub fn soft_lookup_area(max_search: f32, map: u32) -> u64 {
    let w = soft_width_cap(max_search, map) + 1.0;
    lookup_area(w, w)
}

/// The table variant of `light`'s summed-area table, if its technique reads one (the `sat`
/// filter or a soft technique).
pub fn sat_variant(light: &Light) -> Option<SatVariant> {
    match (
        light.shadow.technique.filter(),
        light.shadow.technique.soft(),
    ) {
        (Some(Filter::Sat { variant, .. }), _) => Some(variant),
        (_, Some(Soft { sums, .. })) => Some(sums),
        _ => None,
    }
}

/// The summed-area-table coding of light `light`'s representation when it is read through a
/// table (the `sat` filter or a soft technique; `None` otherwise): the value range of every
/// channel over linear depths in [0, 1], and the largest window the lookups touch
/// ([`lookup_area`] of the filter width; for a soft technique of [`soft_max_width`] plus one
/// texel, since its rectangle's edges are formed in f32 from a per-receiver width).
///
/// Ranges: VSM and raw MSM moments [0, 1]; EVSM `±exp(±c z')` and their squares over
/// z' ∈ [−1, 1] as `±max |v|` (offset 0); ESM (stored linearly for the table)
/// `exp(c (z − 1)) ∈ [e^{−c}, 1]` as ±1; CSM's sines and cosines and CSSM's CSM-Z basis
/// (z, z·sin, z·cos) [−1, 1]; quantized MSM moments the range of the quantization over the
/// moment curve, sampled at 4097 depths and widened by 10⁻³ of the range (the curve is a
/// quartic: sampling misses its extremes by far less).
pub fn sat_coding(light: &Light) -> crate::error::Result<Option<SatCoding>> {
    let area = match (light.shadow.technique.filter(), soft_max_width(light)) {
        (Some(Filter::Sat { width, .. }), _) => lookup_area(width, width),
        (_, Some(_)) => match light.shadow.technique.soft() {
            Some(soft) => soft_lookup_area(soft.max_search, light.shadow_map),
            None => return Ok(None),
        },
        _ => return Ok(None),
    };
    let Some(variant) = sat_variant(light) else {
        return Ok(None);
    };
    let (lo, hi) = value_range(&light.shadow.technique);
    Ok(Some(match variant {
        SatVariant::Fixed => SatCoding::fixed(area, lo, hi)?,
        SatVariant::Float => SatCoding::float(lo, hi)?,
    }))
}

/// Per channel, the range of the values a technique's table sums (see [`sat_coding`]).
fn value_range(technique: &Technique) -> ([f32; 4], [f32; 4]) {
    match *technique {
        // Exponential moments span orders of magnitude, most of them close to 0: coded about 0
        // (range ±max|v|) every value keeps f32's relative precision through the lookups'
        // weighting, where a centred offset would leave the small ones an absolute error of
        // 2⁻²⁴ of the largest.
        Technique::Evsm {
            exp_pos, exp_neg, ..
        } => {
            let (p, n) = (exp_pos, exp_neg);
            let hi = [p.exp(), (2.0 * p).exp(), n.exp(), (2.0 * n).exp()];
            (hi.map(|v| -v), hi)
        }
        Technique::Esm { .. } => ([-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]),
        Technique::Msm { .. } | Technique::MsmSoft { .. } if msm_quantized(technique) => {
            quantized_msm_range()
        }
        Technique::Csm { .. } | Technique::Cssm { .. } => ([-1.0; 4], [1.0; 4]),
        _ => ([0.0; 4], [1.0; 4]),
    }
}

/// The range of MSM's optimized quantization over the moment curve (see [`sat_coding`]),
/// computed once (every frame builds each light's `LightGpu`, which asks for it).
fn quantized_msm_range() -> ([f32; 4], [f32; 4]) {
    static RANGE: std::sync::OnceLock<([f32; 4], [f32; 4])> = std::sync::OnceLock::new();
    *RANGE.get_or_init(|| {
        let (mut lo, mut hi) = ([f64::MAX; 4], [f64::MIN; 4]);
        for k in 0..=4096 {
            let z = f64::from(k) / 4096.0;
            let q = crate::msm_quantize::quantize([z, z * z, z.powi(3), z.powi(4)]);
            for c in 0..4 {
                lo[c] = lo[c].min(q[c]);
                hi[c] = hi[c].max(q[c]);
            }
        }
        let pad = |c: usize| 1e-3 * (hi[c] - lo[c]);
        (
            std::array::from_fn(|c| (lo[c] - pad(c)) as f32),
            std::array::from_fn(|c| (hi[c] + pad(c)) as f32),
        )
    })
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
/// reads. The raw depth map and the linear map are always declared; the planner drops what
/// nothing reads: the encodings linearize the depth themselves, so `linearize` runs only for
/// the techniques that shade from the linear depth (hard, PCF but the hardware comparison
/// sampler, PCSS) or when a caller asks for [`linear_name`] (diagnostics).
pub fn add_light_nodes(graph: &mut Graph, i: usize, light: &Light) -> ShadeInput {
    let depth = graph.import(
        depth_name(i),
        wgpu::TextureFormat::Depth32Float,
        light.shadow_map,
        light.shadow_map,
        Some(i),
    );
    let lin = LinearizeParams::new(light);
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
        params: bytemuck::bytes_of(&lin).to_vec(),
        dispatch: Dispatch::Texels(linear.clone()),
        light: Some(i),
    });
    let float = map_type(light);
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
        Technique::Vsm {
            prefilter: Prefilter { storage, .. },
            ..
        }
        | Technique::Vssm {
            soft: Soft { storage, .. },
            ..
        } => {
            let format = moments_format(storage, 2);
            let params = bytemuck::bytes_of(&VsmParams { depth: lin }).to_vec();
            let moments = encode(graph, i, "vsm", "vsm", &depth, format, params);
            one(filtered(graph, i, light, &moments, BlurMode::Linear), float)
        }
        Technique::Evsm {
            prefilter,
            four,
            exp_pos,
            exp_neg,
            ..
        } => {
            let format = moments_format(prefilter.storage, if four { 4 } else { 2 });
            let params = ExpParams {
                depth: lin,
                ..ExpParams::new(exp_pos, exp_neg)
            };
            let params = bytemuck::bytes_of(&params).to_vec();
            let moments = encode(graph, i, "evsm", "evsm", &depth, format, params);
            one(filtered(graph, i, light, &moments, BlurMode::Linear), float)
        }
        Technique::Esm { filter, exponent } => {
            let mut params = ExpParams::new(exponent, 0.0);
            params.depth = lin;
            params.linear = u32::from(matches!(filter, Filter::Sat { .. }));
            let params = bytemuck::bytes_of(&params).to_vec();
            let format = wgpu::TextureFormat::R32Float;
            let log_moment = encode(graph, i, "esm", "esm", &depth, format, params);
            one(
                filtered(graph, i, light, &log_moment, BlurMode::LogSumExp),
                float,
            )
        }
        Technique::Msm {
            prefilter: Prefilter { storage, .. },
            ..
        }
        | Technique::MsmSoft {
            soft: Soft { storage, .. },
            ..
        } => {
            let format = moments_format(storage, 4);
            let params = bytemuck::bytes_of(&MsmParams {
                depth: lin,
                quantized: u32::from(msm_quantized(&light.shadow.technique)),
                _pad: [0; 3],
            })
            .to_vec();
            let moments = encode(graph, i, "msm", "msm", &depth, format, params);
            one(filtered(graph, i, light, &moments, BlurMode::Linear), float)
        }
        Technique::Csm {
            prefilter: Prefilter { storage, .. },
            terms,
            ..
        } => ShadeInput {
            maps: csm_nodes(graph, i, light, &depth, storage, terms),
            wgsl_type: float,
        },
        Technique::Cssm {
            soft: Soft { storage, .. },
            terms,
            ..
        } => ShadeInput {
            maps: csm_nodes(graph, i, light, &depth, storage, terms),
            wgsl_type: float,
        },
    }
}

/// The filtered maps of light `i`'s convolution basis: the CSM basis maps
/// (`light{i}.csm<chunk>`, two terms each), then for CSSM the CSM-Z maps
/// (`light{i}.csm_z<chunk>`, four channels of the sequence `[z, z·sin c₁z, z·cos c₁z, …]`
/// each), the complementary basis its blocker search filters. `kernels/csm.wgsl` writes up
/// to [`CSM_OUTPUTS`] of them from one read of the depth (nodes `light{i}.csm.<g>`).
fn csm_nodes(
    graph: &mut Graph,
    i: usize,
    light: &Light,
    depth: &str,
    storage: Storage,
    terms: u32,
) -> Vec<String> {
    let z_maps = match light.shadow.technique {
        Technique::Cssm { .. } => csm_z_maps(terms),
        _ => 0,
    };
    let z_channels = csm_z_channels(terms);
    let maps: Vec<(String, wgpu::TextureFormat)> = (0..csm_maps(terms))
        .map(|chunk| {
            let pairs = (terms - 2 * chunk).min(2);
            (format!("csm{chunk}"), moments_format(storage, 2 * pairs))
        })
        .chain((0..z_maps).map(|chunk| {
            let channels = (z_channels - 4 * chunk).min(4);
            (format!("csm_z{chunk}"), moments_format(storage, channels))
        }))
        .collect();
    let mut out = Vec::new();
    for (g, group) in maps.chunks(CSM_OUTPUTS as usize).enumerate() {
        let outputs: Vec<(String, String)> = group
            .iter()
            .enumerate()
            .map(|(j, (name, format))| {
                let r = graph.resource(
                    format!("light{i}.{name}"),
                    *format,
                    SizeRule::Reduced {
                        of: depth.to_string(),
                        shift: 0,
                    },
                    Some(i),
                );
                (format!("dst{j}"), r)
            })
            .collect();
        let params = CsmParams {
            depth: LinearizeParams::new(light),
            first_map: g as u32 * CSM_OUTPUTS,
            maps: group.len() as u32,
            terms,
            _pad: 0,
        };
        let written: Vec<String> = outputs.iter().map(|(_, r)| r.clone()).collect();
        graph.node(Node {
            name: format!("light{i}.csm.{g}"),
            kernel: "csm".into(),
            inputs: vec![("src".into(), depth.to_string())],
            dispatch: Dispatch::Texels(outputs[0].1.clone()),
            outputs,
            params: bytemuck::bytes_of(&params).to_vec(),
            light: Some(i),
        });
        // Filtered before the next group is written (the planner orders by declaration), so
        // at most one group's unfiltered maps are alive at a time.
        out.extend(
            written
                .iter()
                .map(|m| filtered(graph, i, light, m, BlurMode::Linear)),
        );
    }
    out
}

/// The filter of light `light`'s representation applied to `input`: the summed-area table of
/// [`add_sat`] coded by [`sat_coding`] (the `sat` filter and the soft techniques; its errors
/// `render::plan_lights` reports before any graph is built), else the blur or mip chain of
/// [`add_filter`].
fn filtered(graph: &mut Graph, i: usize, light: &Light, input: &str, mode: BlurMode) -> String {
    if sat_variant(light).is_some() {
        return match sat_coding(light) {
            Ok(Some(coding)) => add_sat(graph, i, input, &coding),
            _ => input.to_string(),
        };
    }
    match light.shadow.technique.filter() {
        Some(filter) => add_filter(graph, i, input, &filter, mode),
        None => input.to_string(),
    }
}

/// Channels of the representation behind each map the shading binds for `light` (for a
/// summed-area table, those of the table's input: the table itself always has four).
pub fn map_channels(light: &Light) -> Vec<usize> {
    let mut graph = Graph::default();
    let input = add_light_nodes(&mut graph, 0, light);
    input
        .maps
        .iter()
        .map(|m| {
            let source = m
                .strip_suffix(".sat")
                .filter(|_| sat_coding(light).ok().flatten().is_some());
            graph
                .find(source.unwrap_or(m))
                .map_or(4, |r| crate::sat::format_channels(r.format) as usize)
        })
        .collect()
}

/// The WGSL type of a prefiltered technique's maps: `texture_2d<u32>` for a fixed-point
/// summed-area table, else `texture_2d<f32>`.
pub fn map_type(light: &Light) -> &'static str {
    match sat_variant(light) {
        Some(SatVariant::Fixed) => "texture_2d<u32>",
        _ => "texture_2d<f32>",
    }
}

/// Whether an MSM technique keeps its moments through the optimized quantization: every
/// 16-bit storage does, and so does every summed-area table (`msm_soft`, `filter = "sat"`),
/// whatever the storage. A table rounds each moment on its own to the coding's step (10⁻⁵ of
/// the range for the default soft search cap on a 1024² map); in the raw basis that noise
/// lands in the Hankel matrix's near-null directions, in the quantized basis it does not
/// (docs/STABILITY.md, "MSM moment bias": a 10× smaller error behind a flat occluder at the same bias).
/// Other f32 maps keep the raw powers.
pub fn msm_quantized(technique: &Technique) -> bool {
    match technique {
        Technique::Msm { prefilter, .. } => {
            prefilter.storage != Storage::F32 || matches!(prefilter.filter, Filter::Sat { .. })
        }
        Technique::MsmSoft { .. } => true,
        _ => false,
    }
}

/// Four-channel basis maps CSM with `terms` terms needs (two channels per term).
pub fn csm_maps(terms: u32) -> u32 {
    terms.div_ceil(2)
}

/// Channels of the CSM-Z representation with `terms` terms: z, then z·sin and z·cos per term.
pub fn csm_z_channels(terms: u32) -> u32 {
    2 * terms + 1
}

/// Four-channel CSM-Z maps CSSM with `terms` terms needs.
pub fn csm_z_maps(terms: u32) -> u32 {
    csm_z_channels(terms).div_ceil(4)
}

/// The texel format of a `channels`-channel representation (1–4) at `storage` precision.
pub fn moments_format(storage: Storage, channels: u32) -> wgpu::TextureFormat {
    match (storage, channels) {
        (Storage::F32, 1) => wgpu::TextureFormat::R32Float,
        (Storage::F32, 2) => wgpu::TextureFormat::Rg32Float,
        (Storage::F32, _) => wgpu::TextureFormat::Rgba32Float,
        // rg16float is no core storage format; rgba16float is.
        (Storage::F16, _) => wgpu::TextureFormat::Rgba16Float,
        (Storage::Unorm16, _) => wgpu::TextureFormat::Rgba16Unorm,
    }
}

/// Adds the encoding node `kernel` (raw depth → representation, the kernel linearizing the
/// depth itself) of light `i`, writing `light{i}.{name}`; the output's format picks the
/// kernel's storage variant. `params` start with the depth's [`LinearizeParams`].
fn encode(
    graph: &mut Graph,
    i: usize,
    kernel: &str,
    name: &str,
    depth: &str,
    format: wgpu::TextureFormat,
    params: Vec<u8>,
) -> String {
    let out = graph.resource(
        format!("light{i}.{name}"),
        format,
        SizeRule::Reduced {
            of: depth.to_string(),
            shift: 0,
        },
        Some(i),
    );
    graph.node(Node {
        name: format!("light{i}.{name}"),
        kernel: kernel.into(),
        inputs: vec![("src".into(), depth.to_string())],
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

/// Light `light`'s visibility as the shading kernel and the plug-in's host block call it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VisibilityBody {
    /// The modules it needs (`shared/vis_*` and their helpers).
    pub modules: Vec<&'static str>,
    /// WGSL statements ending in a `return`, with `l: Light`, `s: LightSample` in scope and
    /// the light's maps bound under the names given to [`visibility_body`].
    pub body: String,
    /// The `// #fetches` expression of a function made of `body` when its count cannot be
    /// summed from the body's calls (it loops: CSSM's two passes over its basis tables).
    pub fetches: Option<String>,
}

/// The modules, statements and fetch count of light `light`'s visibility with its maps bound
/// as `maps`.
pub fn visibility_body(light: &Light, maps: &[String]) -> VisibilityBody {
    let simple = |modules: Vec<&'static str>, body: String| VisibilityBody {
        modules,
        body,
        fetches: None,
    };
    if let Some(soft) = light.shadow.technique.soft() {
        let (body, fetches) = soft_visibility_body(light, maps, soft.sums);
        return VisibilityBody {
            modules: vec![soft_module(&light.shadow.technique)],
            body,
            fetches,
        };
    }
    if let Some(Filter::Sat { variant, .. }) = light.shadow.technique.filter() {
        let (module, body) = sat_visibility_body(light, maps, variant);
        return simple(vec![module, "shared/sat_lookup"], body);
    }
    let (module, body) = filtered_visibility_body(light, maps);
    simple(vec![module], body)
}

/// [`visibility_body`] with the `sat` filter: each map's rectangle mean, then the technique's
/// `*_of` function.
fn sat_visibility_body(
    light: &Light,
    maps: &[String],
    variant: SatVariant,
) -> (&'static str, String) {
    let sample = |map: &str| {
        let f = match variant {
            SatVariant::Fixed => "sat_sample_fixed",
            SatVariant::Float => "sat_sample_float",
        };
        format!("{f}({map}, l, s.uv, l.filter_width)")
    };
    let map = maps.first().map_or("", String::as_str);
    let call = |module, f: &str| (module, format!("return {f}({}, l, s);", sample(map)));
    match light.shadow.technique {
        Technique::Evsm { .. } => call("shared/vis_evsm", "vis_evsm_of"),
        Technique::Esm { .. } => call("shared/vis_esm", "vis_esm_of_sat"),
        Technique::Msm { .. } => call("shared/vis_msm", "vis_msm_of"),
        Technique::Csm { .. } => {
            let mut body = String::from("var sum = 0.0;");
            for (chunk, m) in maps.iter().enumerate() {
                let _ = write!(
                    body,
                    "\n            sum += csm_chunk_of({}, {chunk}u, l, s);",
                    sample(m)
                );
            }
            body.push_str("\n            return csm_resolve(sum, l);");
            ("shared/vis_csm", body)
        }
        _ => call("shared/vis_vsm", "vis_vsm_of"),
    }
}

/// The module of a soft technique's visibility (it imports the table lookups and
/// `shared/blocker`).
fn soft_module(technique: &Technique) -> &'static str {
    match technique {
        Technique::Cssm { .. } => "shared/vis_cssm",
        Technique::MsmSoft { .. } => "shared/vis_msm_soft",
        _ => "shared/vis_vssm",
    }
}

/// [`visibility_body`] of a soft technique and, where it loops, its fetch count: the table
/// means over the blocker-search square, the blocker estimate, and only where that finds
/// blockers the means over the penumbra width (`shared/blocker`'s two passes). VSSM and soft
/// MSM call their module's complete function; CSSM sums its CSM-Z maps (the maps after the
/// first ⌈M/2⌉) over the search square, then runs the two passes over its basis maps here.
fn soft_visibility_body(
    light: &Light,
    maps: &[String],
    variant: SatVariant,
) -> (String, Option<String>) {
    let suffix = match variant {
        SatVariant::Fixed => "fixed",
        SatVariant::Float => "float",
    };
    let map = maps.first().map_or("", String::as_str);
    let Technique::Cssm { terms, .. } = light.shadow.technique else {
        let f = match light.shadow.technique {
            Technique::MsmSoft { .. } => "vis_msm_soft",
            _ => "vis_vssm",
        };
        return (format!("return {f}_{suffix}({map}, l, s);"), None);
    };
    let (basis, z) = maps.split_at((csm_maps(terms) as usize).min(maps.len()));
    let sample = |m: &str, width: &str| format!("sat_sample_{suffix}({m}, l, s.uv, {width})");
    let mut body = String::from(
        "var look = soft_search(l, s);
    var zsum = 0.0;",
    );
    for (chunk, m) in z.iter().enumerate() {
        let _ = write!(
            body,
            "\n    zsum += csm_z_chunk_of({}, {chunk}u, l, s);",
            sample(m, "look.width")
        );
    }
    body.push_str("\n    var sum = 0.0;\n    for (var k = 0u; k < 2u; k++) {\n        sum = 0.0;");
    for (chunk, m) in basis.iter().enumerate() {
        let _ = write!(
            body,
            "\n        sum += csm_chunk_of({}, {chunk}u, l, s);",
            sample(m, "look.width")
        );
    }
    body.push_str(
        "\n        if k == 0u {\n            look = soft_blockers(cssm_blocker(sum, zsum, l, s), l, s);\n            \
         if !look.blockers {\n                return 1.0;\n            }\n        }\n    }\n    \
         return cssm_resolve(sum, look.blocker, l, s);",
    );
    let fetches = format!(
        "{} * sat_sample_{suffix} + 2 * {} * sat_sample_{suffix}",
        z.len(),
        basis.len()
    );
    (body, Some(fetches))
}

/// [`visibility_body`] without the `sat` filter.
fn filtered_visibility_body(light: &Light, maps: &[String]) -> (&'static str, String) {
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
        // Soft techniques are handled by `soft_visibility_body`.
        Technique::Cssm { .. } | Technique::Vssm { .. } | Technique::MsmSoft { .. } => {
            (soft_module(&light.shadow.technique), String::new())
        }
    }
}

/// The key of the shading kernel for `lights`: what [`shading_block`] reads of each light (its
/// technique, the table it reads through, hardware PCF, whether it follows the pixel's
/// footprint, CSM's terms, its maps' count and type), so that a scene of the same techniques
/// finds its kernel without generating the block (`tests/reuse.rs` checks that lights with
/// equal keys get equal blocks).
pub fn shade_key(lights: &[Light]) -> String {
    let mut key = String::from("shade");
    for (i, light) in lights.iter().enumerate() {
        let t = &light.shadow.technique;
        let table = match sat_variant(light) {
            Some(SatVariant::Fixed) => "u32",
            Some(SatVariant::Float) => "f32",
            None => "-",
        };
        let hardware = matches!(
            t,
            Technique::Pcf {
                kernel: PcfKernel::Hardware,
                ..
            }
        );
        let footprint =
            matches!(t.filter(), Some(Filter::Mips { max_anisotropy, .. }) if max_anisotropy > 0);
        let terms = match *t {
            Technique::Csm { terms, .. } | Technique::Cssm { terms, .. } => terms,
            _ => 0,
        };
        let input = add_light_nodes(&mut Graph::default(), i, light);
        let _ = write!(
            key,
            "|{} {table} {} {} {terms} {}x{}",
            t.name(),
            u8::from(hardware),
            u8::from(footprint),
            input.maps.len(),
            input.wgsl_type
        );
    }
    key
}

/// The `// #generated` block of `kernels/shade.wgsl` for these lights: imports of the
/// techniques used, one group-1 binding per map (light by light, in [`ShadeInput::maps`]
/// order), one visibility function per light and `light_visibility`, which dispatches on the
/// light index. A receiver that faces away from a light reads 0 and one outside its map 1,
/// without a lookup (`light_faces`, `LightSample::inside`).
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
        let vis = visibility_body(light, &maps);
        for module in vis.modules {
            if !imports.contains(&module) {
                imports.push(module);
            }
        }
        for map in &maps {
            let _ = writeln!(
                bindings,
                "@group(1) @binding({binding}) var {map}: {};",
                input.wgsl_type
            );
            binding += 1;
        }
        if let Some(fetches) = &vis.fetches {
            let _ = writeln!(functions, "// #fetches light{i}_visibility: {fetches}");
        }
        let _ = writeln!(
            functions,
            "fn light{i}_visibility(l: Light, s: LightSample) -> f32 {{\n    {}\n}}",
            vis.body
        );
        // Only anisotropic mip lookups read the footprint (two more projections per pixel).
        let footprint = match light.shadow.technique.filter() {
            Some(Filter::Mips { max_anisotropy, .. }) if max_anisotropy > 0 => {
                "\n            s.footprint = light_footprint(l, s, p, n, dpdx, dpdy);"
            }
            _ => "",
        };
        let _ = writeln!(
            cases,
            "        case {i}u: {{\n            let l = lights[{i}];\n            \
             if !light_faces(l, p, n) {{\n                return 0.0;\n            }}\n            \
             var s = light_sample(l, p, n);\n            \
             if !s.inside {{\n                return 1.0;\n            }}{footprint}\n            \
             return light{i}_visibility(l, s);\n        }}"
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
        "fn light_visibility(i: u32, p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>) -> f32 {{\n    switch i {{\n{cases}        default: {{ return 1.0; }}\n    }}\n}}\n"
    );
    s
}

/// The largest exponent a summed-area table keeps accurate (`None` without the `sat` filter).
///
/// Window sums are linear, so a table's error is absolute: the fixed-point coding's step per
/// mean is `½ / scale ≈ range · A / 2³²` for windows of `A` texels (src/sat.rs), the f32
/// coding's no better. EVSM's squared moment spans `e^{−2c}..e^{2c}`; its step at the centre
/// of the depth range (moment 1) stays below 2⁻¹⁰ while `e^{2c} · A / 2³² ≤ 2⁻¹⁰`, so
/// `c ≤ ½ ln(2²² / A)`. ESM's `exp(c (z − 1)) ∈ [e^{−c}, 1]` has visibility
/// `mean · e^{c (1 − d)}`, whose error at mid depth stays below 2⁻¹⁰ while
/// `e^{c/2} · A / 2³² ≤ 2⁻¹⁰`, so `c ≤ 2 ln(2²² / A)`.
pub fn sat_exponent_limit(filter: &Filter, esm: bool) -> Option<f32> {
    let Filter::Sat { width, .. } = *filter else {
        return None;
    };
    let area = lookup_area(width, width) as f64;
    let c = 0.5 * (f64::from(1u32 << 22) / area).ln().max(0.02);
    Some(if esm { 4.0 * c } else { c } as f32)
}
