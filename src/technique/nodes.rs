//! The graph nodes a light's technique adds: the imported depth, the linear depth, the
//! encoding(s) and the filter or summed-area table over them.

use crate::filter::{BlurMode, add_filter};
use crate::gpu_data::{CSM_OUTPUTS, CsmParams, ExpParams, LinearizeParams, MsmParams, VsmParams};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::model::{Filter, Light, PcfKernel, Prefilter, Soft, Storage, Technique};
use crate::sat::{SatVariant, add_sat};

use super::light_gpu::{sat_coding, sat_variant};
use super::shade::ShadeInput;

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
