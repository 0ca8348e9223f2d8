//! `vsm`: variance shadow maps (Donnelly & Lauritzen 2006), moments (z, z²), filtered.

use super::csm_sat::{Moments, moment_table_nodes};
use super::encoding::{Encoding, VSM_MAPS};
use super::nodes::{LightNodes, moments_format};
use super::params::{FILTER, FLOAT_FORMAT, float, prefilter, prefilter_values};
use super::shade::{ShadeInput, prefiltered};
use super::sweep_plan::{SweepPlan, SweptStorages};
use super::{TechniqueDef, no_clamp};
use super::{no_variant, unit_range};
use crate::filter::BlurMode;
use crate::kernels::KernelId;
use crate::model::Storage;
use crate::model::{ParamSpec, ParamValue, ParamValues, Technique};
use crate::wgsl_mirrors::TECHNIQUE_VSM;
use crate::wgsl_mirrors::{LightGpu, VsmParams};

/// The Chebyshev bound's keys (`vsm`, `vssm`).
pub(super) const VARIANCE: &[ParamSpec] = &[
    float(
        "bleed_reduction",
        0.0,
        0.99,
        0.2,
        "light-bleeding reduction linstep(amount, 1, p)",
    ),
    float(
        "min_variance",
        0.0,
        1.0,
        1e-5,
        "variance floor, depth units²",
    ),
];

/// The [`VARIANCE`] values.
pub(super) fn variance_values(bleed: f32, min_variance: f32, out: &mut ParamValues) {
    out.set("bleed_reduction", ParamValue::Float(bleed));
    out.set("min_variance", ParamValue::Float(min_variance));
}

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Vsm {
        prefilter,
        bleed,
        min_variance,
    } = t
    {
        prefilter_values(prefilter, &mut out);
        variance_values(*bleed, *min_variance, &mut out);
    }
    out
}

/// The Chebyshev bound's GPU fields (`vsm`, `vssm`): two moments.
pub(super) fn variance_gpu(bleed: f32, min_variance: f32, g: &mut LightGpu) {
    g.bleed = bleed;
    g.min_variance = min_variance;
    g.moments = 2;
}

/// The moments (z, z²) at `storage` precision, filtered (`vsm`, `vssm`); through a summed-area
/// table (`filter = "sat"`, `vssm`) computed in the table's own tile passes from the depth,
/// never stored ([`super::add_moment_table`]).
pub(super) fn moments(n: &mut LightNodes, storage: Storage) -> ShadeInput {
    if let Some(table) = moment_table_nodes(n, Moments::Vsm, [0.0; 2], storage) {
        return table;
    }
    let params = VsmParams { depth: n.lin };
    let format = moments_format(storage, 2);
    n.encoded(
        KernelId::Vsm,
        format,
        bytemuck::bytes_of(&params),
        BlurMode::Linear,
    )
}

/// `vsm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "vsm",
    id: TECHNIQUE_VSM,
    doc: "variance shadow maps: two moments, filtered, Chebyshev bound",
    params: &[FLOAT_FORMAT, FILTER, VARIANCE],
    build: |v| Technique::Vsm {
        prefilter: prefilter(v),
        bleed: v.float("bleed_reduction"),
        min_variance: v.float("min_variance"),
    },
    values,
    gpu: |t, g| {
        if let Technique::Vsm {
            bleed,
            min_variance,
            ..
        } = *t
        {
            variance_gpu(bleed, min_variance, g);
        }
    },
    nodes: |n| match n.light.shadow.technique {
        Technique::Vsm { prefilter, .. } => moments(n, prefilter.storage),
        _ => n.one(n.depth.clone()),
    },
    visibility: |light, maps| prefiltered(light, maps, "shared/vis_vsm", "vis_vsm", "vis_vsm_of"),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    reach: super::reach::filtered,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: |_| Some(Encoding::Vsm),
    maps: &[VSM_MAPS],
    example: "scenes/techniques/vsm.toml",
    colour: [0x2c, 0xa0, 0x2c],
    sweep: SweepPlan::Prefiltered {
        storages: SweptStorages::Standard,
        terms: None,
    },
};
