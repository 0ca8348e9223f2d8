//! `msm_soft`: moment soft shadow maps (after Peters et al. 2016): the blocker depth from the
//! four moments over the search square, then MSM at the penumbra width.

use super::encoding::MSM_MAPS;
use super::msm::{moment_bias, msm_values};
use super::msm::{moments, msm_gpu, value_range};
use super::no_encoding;
use super::no_variant;
use super::params::{MSM, MSM_FORMAT, SOFT, soft, soft_values, storage};
use super::shade::soft_call;
use super::sweep_plan::{SweepPlan, SweepVariant};
use super::{TechniqueDef, no_clamp};
use crate::model::{ParamSpec, ParamValue, ParamValues, Technique, default_soft_moment_bias};
use crate::wgsl_mirrors::TECHNIQUE_MSM_SOFT;

const BIAS: &[ParamSpec] = &[moment_bias(|v| {
    ParamValue::Float(default_soft_moment_bias(storage(v.choice("format"))))
})];

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::MsmSoft {
        soft,
        hausdorff,
        moment_bias,
        bleed,
    } = t
    {
        soft_values(soft, &mut out);
        msm_values(*hausdorff, *moment_bias, *bleed, &mut out);
    }
    out
}

/// `msm_soft`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "msm_soft",
    id: TECHNIQUE_MSM_SOFT,
    doc: "moment soft shadow maps: blocker depth from the moments, MSM at the penumbra width",
    params: &[MSM_FORMAT, SOFT, MSM, BIAS],
    build: |v| Technique::MsmSoft {
        soft: soft(v),
        hausdorff: v.choice("reconstruction") == "hausdorff",
        moment_bias: v.float("moment_bias"),
        bleed: v.float("bleed_reduction"),
    },
    values,
    gpu: msm_gpu,
    nodes: moments,
    visibility: |light, maps| soft_call(light, maps, "shared/vis_msm_soft", "vis_msm_soft"),
    variant: no_variant,
    value_range,
    clamp: no_clamp,
    area_light: true,
    reach: super::reach::searched,
    texels_past_radius: Some(2.0),
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[MSM_MAPS],
    example: "scenes/techniques/msm_soft.toml",
    colour: [0x8b, 0x00, 0x00],
    sweep: SweepPlan::Variants {
        full: &[
            SweepVariant {
                label: "msm_soft f32",
                values: &[],
                storage: None,
            },
            SweepVariant {
                label: "msm_soft f16",
                values: &[],
                storage: Some(crate::model::Storage::F16),
            },
            SweepVariant {
                label: "msm_soft f32 float",
                values: &[("sat_sums", ParamValue::Choice("float"))],
                storage: None,
            },
        ],
        quick: 1,
    },
};
