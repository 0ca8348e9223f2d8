//! `cssm`: convolution soft shadow maps (Annen et al. 2008): the CSM and CSM-Z bases through
//! summed-area tables, the blocker depth over the search square, CSM at the penumbra width,
//! then (`resolve = "two_depth"`, the default) away from contact the series inverted for the
//! share of blockers at their depth (over the filter square with the moment search), or the
//! paper's selective sharpening `v^p`,
//! `p = 1 + A·exp(−B (d − z_avg))` alone.

use super::csm::{basis_sequence, series_values};
use super::csm_sat::TableRef;
use super::encoding::CSM_MAPS;
use super::no_encoding;
use super::params::{CSM, FLOAT_FORMAT, SOFT, choice, float, soft, soft_values};
use super::sweep_plan::{SweepPlan, SweepVariant};
use super::{TechniqueDef, no_clamp};
use crate::model::{
    CssmResolve, CssmSearch, DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, ParamSpec, ParamValue,
    ParamValues, Technique, default_soft_moment_bias,
};
use crate::wgsl_mirrors::{MSM_QUANTIZED, TECHNIQUE_CSSM};
use std::fmt::Write;

use super::csm::{csm_gpu, csm_maps, csm_nodes};
use super::nodes::map_type;
use super::shade::{ShadeInput, VisibilityBody, table_args, table_suffix};
use crate::model::{Light, SatVariant};

const SHARPEN: &[ParamSpec] = &[
    float(
        "sharpen",
        0.0,
        100.0,
        DEFAULT_SHARPEN,
        "sharpening strength A (0: none)",
    ),
    float(
        "sharpen_falloff",
        0.0,
        1e4,
        DEFAULT_SHARPEN_FALLOFF,
        "sharpening falloff B per linear depth unit of d − z_avg",
    ),
    choice(
        "blocker_search",
        &["moments", "csm_z"],
        "moments",
        "blocker search: MSM's four moments in one table (msm_soft's estimate) or the paper's \
         CSM-Z basis",
    ),
    choice(
        "resolve",
        &["two_depth", "two_depth_search", "sharpen"],
        "two_depth",
        "the filtered series' visibility: away from contact, inverted for the share of texels at \
         the blockers' depth against the receiver plane's, that depth over the filter square \
         from the moments' table (two_depth; the search's z_avg with blocker_search = \"csm_z\") \
         or the search's z_avg (two_depth_search), or the paper's clamp and sharpening alone",
    ),
];

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Cssm {
        soft,
        terms,
        attenuation,
        offset,
        scale,
        sharpen,
        sharpen_falloff,
        search,
        resolve,
    } = t
    {
        soft_values(soft, &mut out);
        series_values(*terms, *attenuation, *offset, *scale, &mut out);
        out.set("sharpen", ParamValue::Float(*sharpen));
        out.set("sharpen_falloff", ParamValue::Float(*sharpen_falloff));
        out.set("blocker_search", ParamValue::Choice(search.name()));
        out.set("resolve", ParamValue::Choice(resolve.name()));
    }
    out
}

/// The blocker search over the search square snapped outward to texel edges (the power
/// moments' table, or the CSM-Z tables and the basis tables), the blocker estimate, and only
/// where that finds blockers the basis tables' means over the penumbra width, with the fetch
/// count of the loop.
fn visibility(light: &Light, maps: &[String]) -> VisibilityBody {
    let Technique::Cssm {
        terms,
        soft,
        search: kind,
        resolve,
        ..
    } = light.shadow.technique
    else {
        return VisibilityBody::simple(vec!["shared/vis_cssm"], String::new());
    };
    let suffix = table_suffix(soft.sums);
    let tables = super::csm_sat::basis_refs(light, maps, basis_sequence(terms, Some(kind)).len());
    let (basis, z) = tables.split_at((csm_maps(terms) as usize).min(tables.len()));
    // Fixed-point tables lie interleaved in their textures (`SatLayer`s, read by the
    // `sat_layer_*` lookups); f32 tables have a texture each.
    let search = |t: &TableRef| match &t.layer {
        Some(layer) => format!("sat_search_layer({}, {layer}, l, s.uv, width)", t.map),
        None => format!("sat_search_float({}, l, s.uv, width)", t.map),
    };
    let search_fn = if soft.sums == SatVariant::Fixed {
        "sat_search_layer".to_string()
    } else {
        format!("sat_search_{suffix}")
    };
    // Fixed-point tables, all of the map's size, share the filter square's integer window
    // (`fwin`, computed once in the loop); f32 tables take their fractional corners each.
    let fixed = soft.sums == SatVariant::Fixed;
    let filter_fn = if fixed {
        "sat_layer_window".to_string()
    } else {
        format!("sat_filter_{suffix}")
    };
    let sample = |t: &TableRef| match &t.layer {
        Some(layer) => format!(
            "sat_layer_window({}, {layer}, fwin, l.sat_offset, l.sat_scale)",
            t.map
        ),
        None => format!(
            "sat_filter_{suffix}({}, l, s.uv, look.width)",
            table_args(soft.sums, &t.map)
        ),
    };
    // The search reads its tables over the square snapped outward to texel edges (4 loads
    // each); the filter reads the basis tables over the penumbra square with its edges
    // rounded to the nearest texel edges (4 loads each), in a loop of 0 or 1 trips
    // (`soft_filter_trips`).
    let mut body = String::from("let width = blocker_search_width(l, s);");
    let searched = match kind {
        CssmSearch::Moments => {
            if let Some(m) = z.first() {
                let _ = write!(
                    body,
                    "\n    let look = soft_blockers(cssm_blocker_moments({}, l, s), l, s);",
                    search(m)
                );
            }
            z.len()
        }
        CssmSearch::CsmZ => {
            body.push_str("\n    var zsum = 0.0;");
            for (chunk, m) in z.iter().enumerate() {
                let _ = write!(
                    body,
                    "\n    zsum += csm_z_chunk_of({}, {chunk}u, l, s);",
                    search(m)
                );
            }
            body.push_str("\n    var below = 0.0;");
            for (chunk, m) in basis.iter().enumerate() {
                let _ = write!(
                    body,
                    "\n    below += csm_chunk_of({}, {chunk}u, l, s);",
                    search(m)
                );
            }
            body.push_str("\n    let look = soft_blockers(cssm_blocker(below, zsum, l, s), l, s);");
            z.len() + basis.len()
        }
    };
    // The filter sums every term in order: the receiver's factors advance term by term
    // (csm_terms_chunk).
    // With `resolve_flag` 2 the same loop reads the moments' table over the filter square
    // for the blockers' depth there (4 loads).
    let refine = (resolve_flag(resolve, kind) == 2)
        .then(|| z.first())
        .flatten();
    body.push_str(
        "\n    var sum = 0.0;\n    var z_b = look.blocker.x;\n    \
         for (var k = 0u; k < soft_filter_trips(look); k++) {\n        \
         var terms = csm_terms_start(s.depth - l.bias - l.csm_offset, l);",
    );
    if let Some(TableRef {
        map,
        layer: Some(layer),
    }) = basis.first()
    {
        let _ = write!(
            body,
            "\n        let fwin = sat_filter_window(l, s.uv, look.width, sat_layer_size({map}, {layer}));"
        );
    }
    for m in basis {
        let _ = write!(
            body,
            "\n        sum += csm_terms_chunk({}, &terms, l);",
            sample(m)
        );
    }
    if let Some(m) = refine {
        let _ = write!(
            body,
            "\n        z_b = cssm_filter_blockers({}, look, l, s);",
            sample(m)
        );
    }
    body.push_str(
        "\n    }\n    if !look.blockers {\n        return 1.0;\n    }\n    \
         return cssm_resolve(sum, look, z_b, l, s);",
    );
    let fetches = format!(
        "{searched} * {search_fn} + {} * {filter_fn}",
        basis.len() + usize::from(refine.is_some())
    );
    VisibilityBody {
        modules: vec!["shared/vis_cssm"],
        body,
        fetches: Some(fetches),
    }
}

/// `LightGpu::cssm_two_depth` for a resolve and search: the filter square's blocker depth
/// needs the moments' table.
fn resolve_flag(resolve: CssmResolve, search: CssmSearch) -> u32 {
    match (resolve, search) {
        (CssmResolve::Sharpen, _) => 0,
        (CssmResolve::TwoDepth, CssmSearch::Moments) => 2,
        _ => 1,
    }
}

/// What the visibility code depends on besides the maps (the shading kernel's key): M, the
/// blocker search (the tables' order: with interleaved tables the bindings' count no longer
/// tells), and whether the filter loop reads the moments' table again (`resolve_flag` 2).
fn variant(t: &Technique) -> String {
    match *t {
        Technique::Cssm {
            terms,
            resolve,
            search,
            ..
        } => format!(
            "{terms} {} {}",
            search.name(),
            resolve_flag(resolve, search)
        ),
        _ => String::new(),
    }
}

/// `cssm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "cssm",
    id: TECHNIQUE_CSSM,
    doc: "convolution soft shadow maps: CSM at the penumbra width, resolved for two depths or \
          sharpened",
    params: &[FLOAT_FORMAT, SOFT, CSM, SHARPEN],
    build: |v| Technique::Cssm {
        soft: soft(v),
        terms: v.int("terms"),
        attenuation: v.float("attenuation"),
        offset: v.float("offset"),
        scale: v.float("scale"),
        sharpen: v.float("sharpen"),
        sharpen_falloff: v.float("sharpen_falloff"),
        search: match v.choice("blocker_search") {
            "csm_z" => CssmSearch::CsmZ,
            _ => CssmSearch::Moments,
        },
        resolve: match v.choice("resolve") {
            "sharpen" => CssmResolve::Sharpen,
            "two_depth_search" => CssmResolve::TwoDepthSearch,
            _ => CssmResolve::TwoDepth,
        },
    },
    values,
    gpu: |t, g| {
        csm_gpu(t, g);
        if let Technique::Cssm {
            sharpen,
            sharpen_falloff,
            soft,
            resolve,
            search,
            ..
        } = *t
        {
            g.sharpen = sharpen;
            g.sharpen_falloff = sharpen_falloff;
            g.cssm_two_depth = resolve_flag(resolve, search);
            // The moment search's moments: quantized, biased by msm_soft's default for the
            // storage.
            g.moment_bias = default_soft_moment_bias(soft.storage);
            g.msm_flags = MSM_QUANTIZED;
        }
    },
    nodes: |n| match n.light.shadow.technique {
        Technique::Cssm {
            soft,
            terms,
            search,
            ..
        } => ShadeInput {
            maps: csm_nodes(n, soft.storage, terms, Some(search)),
            wgsl_type: map_type(n.light),
        },
        _ => n.one(n.depth.clone()),
    },
    visibility,
    variant,
    // The CSM basis, the CSM-Z basis (z, z·sin, z·cos) and MSM's quantized moments.
    value_range: |_| ([-1.0; 4], [1.0; 4]),
    clamp: no_clamp,
    area_light: true,
    reach: super::reach::searched,
    texels_past_radius: Some(2.0),
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[CSM_MAPS],
    example: "scenes/techniques/cssm.toml",
    colour: [0xe3, 0x77, 0xc2],
    sweep: SweepPlan::Variants {
        full: &[
            SweepVariant {
                label: "cssm M8",
                values: &[("terms", ParamValue::Int(8))],
                storage: None,
            },
            SweepVariant {
                label: "cssm M4",
                values: &[("terms", ParamValue::Int(4))],
                storage: None,
            },
            SweepVariant {
                label: "cssm M16",
                values: &[("terms", ParamValue::Int(16))],
                storage: None,
            },
            SweepVariant {
                label: "cssm M8 two_depth_search",
                values: &[
                    ("terms", ParamValue::Int(8)),
                    ("resolve", ParamValue::Choice("two_depth_search")),
                ],
                storage: None,
            },
            SweepVariant {
                label: "cssm M8 sharpen",
                values: &[
                    ("terms", ParamValue::Int(8)),
                    ("resolve", ParamValue::Choice("sharpen")),
                ],
                storage: None,
            },
            SweepVariant {
                label: "cssm M8 csm_z",
                values: &[
                    ("terms", ParamValue::Int(8)),
                    ("blocker_search", ParamValue::Choice("csm_z")),
                ],
                storage: None,
            },
        ],
        quick: 1,
    },
};
