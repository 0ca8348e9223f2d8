//! `vssm`: variance soft shadow maps (Yang et al. 2010) through a summed-area table.

use super::encoding::VSM_MAPS;
use super::no_encoding;
use super::params::{FLOAT_FORMAT, SOFT, soft, soft_values};
use super::shade::soft_call;
use super::sweep_plan::{SweepPlan, SweepVariant};
use super::vsm::{VARIANCE, variance_values};
use super::vsm::{moments, variance_gpu};
use super::{TechniqueDef, no_clamp};
use super::{no_variant, unit_range};
use crate::model::{ParamValue, ParamValues, Technique};
use crate::wgsl_mirrors::TECHNIQUE_VSSM;

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Vssm {
        soft,
        bleed,
        min_variance,
    } = t
    {
        soft_values(soft, &mut out);
        variance_values(*bleed, *min_variance, &mut out);
    }
    out
}

/// `vssm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "vssm",
    id: TECHNIQUE_VSSM,
    doc: "variance soft shadow maps: blocker depth from the moments, VSM at the penumbra width",
    params: &[FLOAT_FORMAT, SOFT, VARIANCE],
    build: |v| Technique::Vssm {
        soft: soft(v),
        bleed: v.float("bleed_reduction"),
        min_variance: v.float("min_variance"),
    },
    values,
    gpu: |t, g| {
        if let Technique::Vssm {
            bleed,
            min_variance,
            ..
        } = *t
        {
            variance_gpu(bleed, min_variance, g);
        }
    },
    nodes: |n| match n.light.shadow.technique {
        Technique::Vssm { soft, .. } => moments(n, soft.storage),
        _ => n.one(n.depth.clone()),
    },
    visibility: |light, maps| soft_call(light, maps, "shared/vis_vssm", "vis_vssm"),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: true,
    reach: super::reach::searched,
    texels_past_radius: Some(2.0),
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[VSM_MAPS],
    example: "scenes/techniques/vssm.toml",
    colour: [0x00, 0x5f, 0x3f],
    sweep: SweepPlan::Variants {
        full: &[
            SweepVariant {
                label: "vssm",
                values: &[],
                storage: None,
            },
            SweepVariant {
                label: "vssm float",
                values: &[("sat_sums", ParamValue::Choice("float"))],
                storage: None,
            },
        ],
        quick: 1,
    },
};
