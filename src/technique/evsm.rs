//! `evsm2`, `evsm4`: exponential variance shadow maps (Lauritzen): depth warped to [−1, 1],
//! then `exp(c⁺ z')` and its square, plus (EVSM4) `−exp(−c⁻ z')` and its square.

use super::TechniqueDef;
use super::csm_sat::{Moments, moment_table_nodes};
use super::encoding::{ChannelNaming, Encoding, MapChannels};
use super::no_variant;
use super::nodes::moments_format;
use super::params::{
    Clamp, ClampReason, FILTER, FLOAT_FORMAT, clamp, float, prefilter, prefilter_values,
    sat_exponent_limit,
};
use super::shade::{ShadeInput, prefiltered};
use super::sweep_plan::{SweepPlan, SweptStorages};
use crate::filter::BlurMode;
use crate::kernels::KernelId;
use crate::model::{ParamSpec, ParamValue, ParamValues, Technique, exponent_limit};
use crate::wgsl_mirrors::TECHNIQUE_EVSM;
use crate::wgsl_mirrors::{ExpParams, LightGpu};

/// c⁻ of EVSM2, which stores no negative moments (EVSM4's default).
const DEFAULT_EXP_NEG: f32 = 5.0;

const COMMON: &[ParamSpec] = &[
    float(
        "bleed_reduction",
        0.0,
        0.99,
        0.0,
        "light-bleeding reduction",
    ),
    float(
        "min_variance",
        0.0,
        1.0,
        1e-4,
        "variance floor in depth units², through the warp's derivative",
    ),
    float(
        "exponent_pos",
        0.01,
        1e4,
        40.0,
        "positive exponent c⁺ (clamped to the storage's safe limit)",
    ),
];

const NEG: &[ParamSpec] = &[float(
    "exponent_neg",
    0.01,
    1e4,
    DEFAULT_EXP_NEG,
    "negative exponent c⁻ (clamped likewise)",
)];

fn build(v: &ParamValues, four: bool) -> Technique {
    Technique::Evsm {
        prefilter: prefilter(v),
        four,
        exp_pos: v.float("exponent_pos"),
        exp_neg: match v.get("exponent_neg") {
            Some(ParamValue::Float(c)) => c,
            _ => DEFAULT_EXP_NEG,
        },
        bleed: v.float("bleed_reduction"),
        min_variance: v.float("min_variance"),
    }
}

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Evsm {
        prefilter,
        four,
        exp_pos,
        exp_neg,
        bleed,
        min_variance,
    } = t
    {
        prefilter_values(prefilter, &mut out);
        out.set("bleed_reduction", ParamValue::Float(*bleed));
        out.set("min_variance", ParamValue::Float(*min_variance));
        out.set("exponent_pos", ParamValue::Float(*exp_pos));
        if *four {
            out.set("exponent_neg", ParamValue::Float(*exp_neg));
        }
    }
    out
}

/// The exponents clamped to the storage's safe limit, then to what a summed-area table keeps
/// accurate.
fn clamp_exponents(t: &mut Technique, out: &mut Vec<Clamp>) {
    if let Technique::Evsm {
        prefilter,
        exp_pos,
        exp_neg,
        ..
    } = t
    {
        let limit = Some(exponent_limit(prefilter.storage));
        let sat = sat_exponent_limit(&prefilter.filter, false);
        for (key, c) in [("exponent_pos", exp_pos), ("exponent_neg", exp_neg)] {
            let storage = clamp(key, *c, limit, ClampReason::Storage(prefilter.storage), out);
            *c = clamp(key, storage, sat, ClampReason::Sat, out);
        }
    }
}

fn gpu(t: &Technique, g: &mut LightGpu) {
    if let Technique::Evsm {
        four,
        exp_pos,
        exp_neg,
        bleed,
        min_variance,
        ..
    } = *t
    {
        g.bleed = bleed;
        g.min_variance = min_variance;
        g.exp_pos = exp_pos;
        g.exp_neg = exp_neg;
        g.moments = if four { 4 } else { 2 };
    }
}

fn nodes(n: &mut super::LightNodes) -> ShadeInput {
    let Technique::Evsm {
        prefilter,
        four,
        exp_pos,
        exp_neg,
        ..
    } = n.light.shadow.technique
    else {
        return n.one(n.depth.clone());
    };
    // Through a summed-area table the moments are computed in the table's own tile passes,
    // never stored.
    let moments = Moments::Evsm { four };
    if let Some(table) = moment_table_nodes(n, moments, [exp_pos, exp_neg], prefilter.storage) {
        return table;
    }
    let format = moments_format(prefilter.storage, if four { 4 } else { 2 });
    let params = ExpParams {
        depth: n.lin,
        ..ExpParams::new(exp_pos, exp_neg)
    };
    n.encoded(
        KernelId::Evsm,
        format,
        bytemuck::bytes_of(&params),
        BlurMode::Linear,
    )
}

/// Exponential moments span orders of magnitude, most of them close to 0: coded about 0
/// (range ±max|v|) every value keeps f32's relative precision through the lookups' weighting,
/// where a centred offset would leave the small ones an absolute error of 2⁻²⁴ of the largest.
/// The moments `±exp(±c z')` and their squares over z' ∈ [−1, 1].
fn value_range(t: &Technique) -> ([f32; 4], [f32; 4]) {
    let Technique::Evsm {
        exp_pos, exp_neg, ..
    } = *t
    else {
        return ([0.0; 4], [1.0; 4]);
    };
    let (p, n) = (exp_pos, exp_neg);
    let hi = [p.exp(), (2.0 * p).exp(), n.exp(), (2.0 * n).exp()];
    (hi.map(|v| -v), hi)
}

/// EVSM's exponents.
fn evsm_encoding(t: &Technique) -> Option<Encoding> {
    match *t {
        Technique::Evsm {
            exp_pos, exp_neg, ..
        } => Some(Encoding::Evsm { exp_pos, exp_neg }),
        _ => None,
    }
}

/// EVSM's map (`light{i}.evsm`): (pos, pos², neg, neg²) of the warped depth; EVSM2's two
/// channels keep the first two.
const EVSM_MAPS: MapChannels = MapChannels {
    kind: "evsm",
    naming: ChannelNaming::Fixed(&["pos", "pos2", "neg", "neg2"]),
};

/// EVSM2's channels under its own name, should it become a resource kind of its own.
const EVSM2_MAPS: MapChannels = MapChannels {
    kind: "evsm2",
    naming: ChannelNaming::Fixed(&["pos", "pos2"]),
};

/// EVSM4's channels under its own name, likewise.
const EVSM4_MAPS: MapChannels = MapChannels {
    kind: "evsm4",
    naming: ChannelNaming::Fixed(&["pos", "pos2", "neg", "neg2"]),
};

/// `evsm2`.
pub(super) static EVSM2: TechniqueDef = TechniqueDef {
    name: "evsm2",
    id: TECHNIQUE_EVSM,
    doc: "exponential variance shadow maps, two moments",
    params: &[FLOAT_FORMAT, FILTER, COMMON],
    build: |v| build(v, false),
    values,
    gpu,
    nodes,
    visibility: |light, maps| {
        prefiltered(light, maps, "shared/vis_evsm", "vis_evsm", "vis_evsm_of")
    },
    variant: no_variant,
    value_range,
    clamp: clamp_exponents,
    area_light: false,
    reach: super::reach::filtered,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: evsm_encoding,
    maps: &[EVSM_MAPS, EVSM2_MAPS],
    example: "scenes/techniques/evsm2.toml",
    colour: [0xbc, 0xbd, 0x22],
    sweep: SweepPlan::Prefiltered {
        storages: SweptStorages::Standard,
        terms: None,
    },
};

/// `evsm4`.
pub(super) static EVSM4: TechniqueDef = TechniqueDef {
    name: "evsm4",
    id: TECHNIQUE_EVSM,
    doc: "exponential variance shadow maps, four moments",
    params: &[FLOAT_FORMAT, FILTER, COMMON, NEG],
    build: |v| build(v, true),
    values,
    gpu,
    nodes,
    visibility: |light, maps| {
        prefiltered(light, maps, "shared/vis_evsm", "vis_evsm", "vis_evsm_of")
    },
    variant: no_variant,
    value_range,
    clamp: clamp_exponents,
    area_light: false,
    reach: super::reach::filtered,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: evsm_encoding,
    maps: &[EVSM_MAPS, EVSM4_MAPS],
    example: "scenes/techniques/evsm4.toml",
    colour: [0x8c, 0x56, 0x4b],
    sweep: SweepPlan::Prefiltered {
        storages: SweptStorages::Standard,
        terms: None,
    },
};
