//! `csm`: convolution shadow maps (Annen et al. 2007), Fourier basis sin(c_k z), cos(c_k z),
//! k = 1..M, in ⌈M/2⌉ four-channel maps.

use super::encoding::{CSM_MAPS, Encoding};
use super::params::{CSM, FILTER, FLOAT_FORMAT, prefilter, prefilter_values};
use super::sweep_plan::{SweepPlan, SweptStorages, SweptTerms};
use super::{TechniqueDef, no_clamp};
use crate::kernels::KernelId;
use crate::model::{CssmSearch, ParamValue, ParamValues, Technique};
use crate::wgsl_mirrors::TECHNIQUE_CSM;
use std::fmt::Write;

use super::nodes::{LightNodes, float_moments_format, map_type};
use super::shade::{ShadeInput, VisibilityBody, sat_sample};
use crate::filter::BlurMode;
use crate::model::{Filter, Light, Storage};
use crate::wgsl_mirrors::{CSM_OUTPUTS, CsmParams, LightGpu};

/// The [`CSM`] values.
pub(super) fn series_values(
    terms: u32,
    attenuation: f32,
    offset: f32,
    scale: f32,
    out: &mut ParamValues,
) {
    out.set("terms", ParamValue::Int(terms));
    out.set("attenuation", ParamValue::Float(attenuation));
    out.set("offset", ParamValue::Float(offset));
    out.set("scale", ParamValue::Float(scale));
}

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Csm {
        prefilter,
        terms,
        attenuation,
        offset,
        scale,
    } = t
    {
        prefilter_values(prefilter, &mut out);
        series_values(*terms, *attenuation, *offset, *scale, &mut out);
    }
    out
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

/// The maps after the CSM basis for CSSM's blocker search, `(name, channels)`: the CSM-Z maps
/// `csm_z<chunk>` (four channels of `[z, z·sin c₁z, z·cos c₁z, …]` each), or the moments'
/// map `csm_moments` (MSM's `(z, z², z³, z⁴)`, quantized).
pub fn search_maps(terms: u32, search: CssmSearch) -> Vec<(String, u32)> {
    match search {
        CssmSearch::CsmZ => {
            let channels = csm_z_channels(terms);
            (0..csm_z_maps(terms))
                .map(|chunk| (format!("csm_z{chunk}"), (channels - 4 * chunk).min(4)))
                .collect()
        }
        CssmSearch::Moments => vec![("csm_moments".to_string(), 4)],
    }
}

/// The light's maps in order, `(name, channels)`: the ⌈M/2⌉ CSM basis maps `csm<chunk>`, then
/// with `search` (CSSM) its [`search_maps`].
pub fn basis_sequence(terms: u32, search: Option<CssmSearch>) -> Vec<(String, u32)> {
    let mut maps: Vec<(String, u32)> = (0..csm_maps(terms))
        .map(|chunk| (format!("csm{chunk}"), 2 * (terms - 2 * chunk).min(2)))
        .collect();
    if let Some(search) = search {
        maps.extend(search_maps(terms, search));
    }
    maps
}

/// The series' GPU fields (`csm`, `cssm`).
pub(super) fn csm_gpu(t: &Technique, g: &mut LightGpu) {
    if let Technique::Csm {
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
    } = *t
    {
        g.csm_terms = terms;
        g.csm_attenuation = attenuation;
        g.csm_offset = offset;
        g.csm_scale = scale;
    }
}

/// The terms M (the number of maps bound and of calls in the visibility body).
pub(super) fn terms(t: &Technique) -> String {
    match *t {
        Technique::Csm { terms, .. } | Technique::Cssm { terms, .. } => terms.to_string(),
        _ => String::new(),
    }
}

/// The sum of each basis map's terms (`csm_chunk`, or through the `sat` filter `csm_chunk_of`
/// its rectangle mean), resolved.
fn visibility(light: &Light, maps: &[String]) -> VisibilityBody {
    let table = match light.shadow.technique.filter() {
        Some(Filter::Sat { variant, .. }) => Some(variant),
        _ => None,
    };
    let mut body = String::from("var sum = 0.0;");
    let chunks = if table.is_some() {
        let terms = match light.shadow.technique {
            Technique::Csm { terms, .. } => terms,
            _ => 0,
        };
        super::csm_sat::basis_refs(light, maps, csm_maps(terms) as usize)
            .into_iter()
            .map(|t| (t.map, t.layer))
            .collect()
    } else {
        maps.iter().map(|m| (m.clone(), None)).collect::<Vec<_>>()
    };
    for (chunk, (m, layer)) in chunks.iter().enumerate() {
        let call = match (table, layer) {
            (Some(_), Some(layer)) => format!(
                "csm_chunk_of(sat_sample_layer({m}, {layer}, l, s.uv, l.filter_width), {chunk}u, \
                 l, s)"
            ),
            (Some(v), None) => format!(
                "csm_chunk_of({}, {chunk}u, l, s)",
                sat_sample(v, m, "l.filter_width")
            ),
            (None, _) => format!("csm_chunk({m}, {chunk}u, l, s)"),
        };
        let _ = write!(body, "\n            sum += {call};");
    }
    body.push_str("\n            return csm_resolve(sum, l);");
    let mut modules = vec!["shared/vis_csm"];
    if table.is_some() {
        modules.push("shared/sat_lookup");
    }
    VisibilityBody::simple(modules, body)
}

/// The filtered maps of light `i`'s convolution basis: the CSM basis maps
/// (`light{i}.csm<chunk>`, two terms each), then with `search` (CSSM) the maps its blocker
/// search filters ([`search_maps`]: the CSM-Z maps `light{i}.csm_z<chunk>` or MSM's quantized
/// moments `light{i}.csm_moments`). `kernels/csm.wgsl` writes up
/// to [`CSM_OUTPUTS`] of them from one read of the depth (nodes `light{i}.csm.<g>`).
///
/// Through a summed-area table (the `sat` filter, CSSM) the maps are not stored: their tables
/// are built by [`super::csm_sat::csm_sat_nodes`], the basis computed from the depth in the
/// tables' own tile passes.
pub(super) fn csm_nodes(
    n: &mut LightNodes,
    storage: Storage,
    terms: u32,
    search: Option<CssmSearch>,
) -> Vec<String> {
    if let Ok(Some(coding)) = super::light_gpu::sat_coding(n.light) {
        return super::csm_sat::csm_sat_nodes(n, storage, terms, search, coding);
    }
    let maps: Vec<(String, wgpu::TextureFormat)> = basis_sequence(terms, search)
        .into_iter()
        .map(|(name, channels)| (name, float_moments_format(storage, channels)))
        .collect();
    let mut out = Vec::new();
    for (g, group) in maps.chunks(CSM_OUTPUTS as usize).enumerate() {
        let outputs: Vec<(String, String)> = group
            .iter()
            .enumerate()
            .map(|(j, (name, format))| (format!("dst{j}"), n.map(name, *format)))
            .collect();
        let params = CsmParams {
            depth: n.lin,
            first_map: g as u32 * CSM_OUTPUTS,
            maps: group.len() as u32,
            terms,
            moments: u32::from(search == Some(CssmSearch::Moments)),
        };
        let written: Vec<String> = outputs.iter().map(|(_, r)| r.clone()).collect();
        let name = format!("light{}.csm.{g}", n.i);
        n.node(
            name,
            KernelId::Csm,
            outputs,
            bytemuck::bytes_of(&params).to_vec(),
        );
        // Filtered before the next group is written (the planner orders by declaration), so
        // at most one group's unfiltered maps are alive at a time.
        out.extend(written.iter().map(|m| n.filtered(m, BlurMode::Linear)));
    }
    out
}

/// CSM's basis of `terms` terms.
fn csm_encoding(t: &Technique) -> Option<Encoding> {
    match *t {
        Technique::Csm { terms, .. } => Some(Encoding::Csm { terms }),
        _ => None,
    }
}

/// `csm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "csm",
    id: TECHNIQUE_CSM,
    doc: "convolution shadow maps: a Fourier series of the step, filtered",
    params: &[FLOAT_FORMAT, FILTER, CSM],
    build: |v| Technique::Csm {
        prefilter: prefilter(v),
        terms: v.int("terms"),
        attenuation: v.float("attenuation"),
        offset: v.float("offset"),
        scale: v.float("scale"),
    },
    values,
    gpu: csm_gpu,
    nodes: |n| match n.light.shadow.technique {
        Technique::Csm {
            prefilter, terms, ..
        } => ShadeInput {
            maps: csm_nodes(n, prefilter.storage, terms, None),
            wgsl_type: map_type(n.light),
        },
        _ => n.one(n.depth.clone()),
    },
    visibility,
    variant: terms,
    // Sines and cosines.
    value_range: |_| ([-1.0; 4], [1.0; 4]),
    clamp: no_clamp,
    area_light: false,
    reach: super::reach::filtered,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: csm_encoding,
    maps: &[CSM_MAPS],
    example: "scenes/techniques/csm.toml",
    colour: [0xff, 0x7f, 0x0e],
    // The knobs at M = 8 (4 when quick); the other M with the first filter.
    sweep: SweepPlan::Prefiltered {
        storages: SweptStorages::Standard,
        terms: Some(SweptTerms {
            full: 8,
            quick: 4,
            others: &[2, 4, 16],
        }),
    },
};
