//! `esm`: exponential shadow maps (Annen et al. 2008), `c·z` filtered in log space; always f32
//! (f16 `c·z` would cost percent-level visibility error).

use super::TechniqueDef;
use super::params::{
    Clamp, ClampReason, FILTER, clamp, filter, filter_values, float, sat_exponent_limit,
};
use crate::gpu_data::TECHNIQUE_ESM;
use crate::model::{ParamSpec, ParamValue, ParamValues, Technique};

const PARAMS: &[ParamSpec] = &[float("exponent", 0.01, 1e4, 80.0, "exponent c")];

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Esm { filter, exponent } = t {
        filter_values(filter, &mut out);
        out.set("exponent", ParamValue::Float(*exponent));
    }
    out
}

/// The exponent clamped to what a summed-area table keeps accurate.
fn clamp_exponent(t: &mut Technique, out: &mut Vec<Clamp>) {
    if let Technique::Esm { filter, exponent } = t {
        let sat = sat_exponent_limit(filter, true);
        *exponent = clamp("exponent", *exponent, sat, ClampReason::Sat, out);
    }
}

/// `esm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "esm",
    id: TECHNIQUE_ESM,
    doc: "exponential shadow maps, filtered in log space",
    params: &[FILTER, PARAMS],
    build: |v| Technique::Esm {
        filter: filter(v),
        exponent: v.float("exponent"),
    },
    values,
    clamp: clamp_exponent,
    area_light: false,
    example: "scenes/techniques/esm.toml",
};
