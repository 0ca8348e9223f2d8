//! `hard`: one comparison at the nearest texel.

use super::{TechniqueDef, no_clamp};
use crate::gpu_data::TECHNIQUE_HARD;
use crate::model::{ParamValues, Technique};

/// `hard`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "hard",
    id: TECHNIQUE_HARD,
    doc: "one comparison at the nearest texel",
    params: &[],
    build: |_| Technique::Hard,
    values: |_| ParamValues::default(),
    clamp: no_clamp,
    area_light: false,
    example: "scenes/grazing.toml",
};
