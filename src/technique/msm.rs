//! `msm`: moment shadow maps (Peters & Klein 2015), (z, z², z³, z⁴) raw in f32 or through the
//! optimized 16-bit quantization; Hamburger or Hausdorff reconstruction.

use super::csm_sat::{Moments, moment_table_nodes};
use super::encoding::{Encoding, MSM_MAPS};
use super::light_gpu::quantized_msm_range;
use super::nodes::{LightNodes, moments_format};
use super::params::{FILTER, MSM, MSM_FORMAT, prefilter, prefilter_values, storage};
use super::shade::{ShadeInput, prefiltered};
use super::sweep_plan::{SweepPlan, SweptStorages};
use super::{TechniqueDef, no_clamp};
use super::{no_variant, unit_range};
use crate::filter::BlurMode;
use crate::kernels::KernelId;
use crate::model::{Filter, Storage};
use crate::model::{
    ParamDefault, ParamKind, ParamSpec, ParamValue, ParamValues, Technique, default_moment_bias,
};
use crate::wgsl_mirrors::TECHNIQUE_MSM;
use crate::wgsl_mirrors::{LightGpu, MSM_HAUSDORFF, MSM_QUANTIZED, MsmParams};

/// Whether an MSM technique keeps its moments through the optimized quantization: every
/// 16-bit storage does, and so does every summed-area table (`msm_soft`, `filter = "sat"`),
/// whatever the storage. A table rounds each moment on its own to the coding's step (10⁻⁵ of
/// the range for the default soft search cap on a 1024² map); in the raw basis that noise
/// lands in the Hankel matrix's near-null directions, in the quantized basis it does not
/// (docs/STABILITY.md, "MSM moment bias": a 10× smaller error behind a flat occluder at the
/// same bias). Other f32 maps keep the raw powers.
pub fn msm_quantized(technique: &Technique) -> bool {
    match technique {
        Technique::Msm { prefilter, .. } => {
            prefilter.storage != Storage::F32 || matches!(prefilter.filter, Filter::Sat { .. })
        }
        Technique::MsmSoft { .. } => true,
        _ => false,
    }
}

/// The GPU fields of `msm` and `msm_soft`: four moments, the bias, the flags.
pub(super) fn msm_gpu(t: &Technique, g: &mut LightGpu) {
    if let Technique::Msm {
        hausdorff,
        moment_bias,
        bleed,
        ..
    }
    | Technique::MsmSoft {
        hausdorff,
        moment_bias,
        bleed,
        ..
    } = *t
    {
        g.bleed = bleed;
        g.moments = 4;
        g.moment_bias = moment_bias;
        g.msm_flags =
            u32::from(hausdorff) * MSM_HAUSDORFF + u32::from(msm_quantized(t)) * MSM_QUANTIZED;
    }
}

/// The four moments (raw or quantized), filtered as the light asks (`msm`, `msm_soft`):
/// through a summed-area table, the table computed from the depth ([`add_moment_table`]); else the
/// `msm` encoding, then its blur or mips.
pub(super) fn moments(n: &mut LightNodes) -> ShadeInput {
    let t = &n.light.shadow.technique;
    let storage = match *t {
        Technique::Msm { prefilter, .. } => prefilter.storage,
        Technique::MsmSoft { soft, .. } => soft.storage,
        _ => Storage::F32,
    };
    // Through a summed-area table (`filter = "sat"`, `msm_soft`) the moments are computed in
    // the table's own tile passes, never stored.
    if let Some(table) = moment_table_nodes(n, Moments::Msm, [0.0; 2], storage) {
        return table;
    }
    let params = MsmParams {
        depth: n.lin,
        quantized: u32::from(msm_quantized(t)),
        _pad: [0; 3],
    };
    let format = moments_format(storage, 4);
    n.encoded(
        KernelId::Msm,
        format,
        bytemuck::bytes_of(&params),
        BlurMode::Linear,
    )
}

/// Raw moments lie in [0, 1]; quantized ones in the quantization's range over the moment
/// curve.
pub(super) fn value_range(t: &Technique) -> ([f32; 4], [f32; 4]) {
    if msm_quantized(t) {
        quantized_msm_range()
    } else {
        unit_range(t)
    }
}

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
    gpu: msm_gpu,
    nodes: moments,
    visibility: |light, maps| prefiltered(light, maps, "shared/vis_msm", "vis_msm", "vis_msm_of"),
    variant: no_variant,
    value_range,
    clamp: no_clamp,
    area_light: false,
    reach: super::reach::filtered,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: |t| {
        Some(Encoding::Msm {
            quantized: msm_quantized(t),
        })
    },
    maps: &[MSM_MAPS],
    example: "scenes/techniques/msm.toml",
    colour: [0xd6, 0x27, 0x28],
    sweep: SweepPlan::Prefiltered {
        storages: SweptStorages::WithUnorm16,
        terms: None,
    },
};
