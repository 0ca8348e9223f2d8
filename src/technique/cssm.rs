//! `cssm`: convolution soft shadow maps (Annen et al. 2008): the CSM and CSM-Z bases through
//! summed-area tables, the blocker depth over the search square, CSM at the penumbra width,
//! then the selective sharpening `v^p`, `p = 1 + A·exp(−B (d − z_avg))`.

use super::csm::series_values;
use super::params::{CSM, FLOAT_FORMAT, SOFT, float, soft, soft_values};
use super::{TechniqueDef, no_clamp};
use crate::gpu_data::TECHNIQUE_CSSM;
use crate::model::{
    DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, ParamSpec, ParamValue, ParamValues, Technique,
};

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
    } = t
    {
        soft_values(soft, &mut out);
        series_values(*terms, *attenuation, *offset, *scale, &mut out);
        out.set("sharpen", ParamValue::Float(*sharpen));
        out.set("sharpen_falloff", ParamValue::Float(*sharpen_falloff));
    }
    out
}

/// `cssm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "cssm",
    id: TECHNIQUE_CSSM,
    doc: "convolution soft shadow maps: CSM at the penumbra width, sharpened",
    params: &[FLOAT_FORMAT, SOFT, CSM, SHARPEN],
    build: |v| Technique::Cssm {
        soft: soft(v),
        terms: v.int("terms"),
        attenuation: v.float("attenuation"),
        offset: v.float("offset"),
        scale: v.float("scale"),
        sharpen: v.float("sharpen"),
        sharpen_falloff: v.float("sharpen_falloff"),
    },
    values,
    clamp: no_clamp,
    area_light: true,
    example: "scenes/techniques/cssm.toml",
};
