//! `vsm`: variance shadow maps (Donnelly & Lauritzen 2006), moments (z, z²), filtered.

use super::params::{FILTER, FLOAT_FORMAT, float, prefilter, prefilter_values};
use super::{TechniqueDef, no_clamp};
use crate::gpu_data::TECHNIQUE_VSM;
use crate::model::{ParamSpec, ParamValue, ParamValues, Technique};

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
    clamp: no_clamp,
    area_light: false,
    example: "scenes/techniques/vsm.toml",
};
