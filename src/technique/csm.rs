//! `csm`: convolution shadow maps (Annen et al. 2007), Fourier basis sin(c_k z), cos(c_k z),
//! k = 1..M, in ⌈M/2⌉ four-channel maps.

use super::params::{CSM, FILTER, FLOAT_FORMAT, prefilter, prefilter_values};
use super::{TechniqueDef, no_clamp};
use crate::gpu_data::TECHNIQUE_CSM;
use crate::model::{ParamValue, ParamValues, Technique};

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
    clamp: no_clamp,
    area_light: false,
    example: "scenes/techniques/csm.toml",
};
