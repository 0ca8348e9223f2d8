//! `msm`: moment shadow maps (Peters & Klein 2015), (z, z², z³, z⁴) raw in f32 or through the
//! optimized 16-bit quantization; Hamburger or Hausdorff reconstruction.

use super::params::{FILTER, MSM, MSM_FORMAT, prefilter, prefilter_values, storage};
use super::{TechniqueDef, no_clamp};
use crate::gpu_data::TECHNIQUE_MSM;
use crate::model::{
    ParamDefault, ParamKind, ParamSpec, ParamValue, ParamValues, Technique, default_moment_bias,
};

/// `moment_bias` with a default per storage (`rule`).
pub(super) const fn moment_bias(rule: fn(&ParamValues) -> ParamValue) -> ParamSpec {
    ParamSpec {
        key: "moment_bias",
        kind: ParamKind::Float { lo: 0.0, hi: 0.5 },
        default: ParamDefault::Rule(rule),
        needs: &[],
        doc: "moment bias α toward a fixed three-point distribution (default per storage)",
    }
}

const BIAS: &[ParamSpec] = &[moment_bias(|v| {
    ParamValue::Float(default_moment_bias(storage(v.choice("format"))))
})];

/// The [`MSM`] values and the bias.
pub(super) fn msm_values(hausdorff: bool, bias: f32, bleed: f32, out: &mut ParamValues) {
    let name = if hausdorff { "hausdorff" } else { "hamburger" };
    out.set("reconstruction", ParamValue::Choice(name));
    out.set("moment_bias", ParamValue::Float(bias));
    out.set("bleed_reduction", ParamValue::Float(bleed));
}

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Msm {
        prefilter,
        hausdorff,
        moment_bias,
        bleed,
    } = t
    {
        prefilter_values(prefilter, &mut out);
        msm_values(*hausdorff, *moment_bias, *bleed, &mut out);
    }
    out
}

/// `msm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "msm",
    id: TECHNIQUE_MSM,
    doc: "moment shadow maps: four moments, Hamburger or Hausdorff reconstruction",
    params: &[MSM_FORMAT, FILTER, MSM, BIAS],
    build: |v| Technique::Msm {
        prefilter: prefilter(v),
        hausdorff: v.choice("reconstruction") == "hausdorff",
        moment_bias: v.float("moment_bias"),
        bleed: v.float("bleed_reduction"),
    },
    values,
    clamp: no_clamp,
    area_light: false,
    example: "scenes/techniques/msm.toml",
};
