//! `hard`: one comparison at the nearest texel.

use super::no_encoding;
use super::shade::call;
use super::sweep_plan::SweepPlan;
use super::{TechniqueDef, no_clamp};
use super::{no_gpu, no_variant, unit_range};
use crate::model::{ParamValues, Technique};
use crate::wgsl_mirrors::TECHNIQUE_HARD;

/// `hard`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "hard",
    id: TECHNIQUE_HARD,
    doc: "one comparison at the nearest texel",
    params: &[super::params::RECEIVER_PLANE],
    build: |_| Technique::Hard,
    values: |_| ParamValues::default(),
    gpu: no_gpu,
    nodes: |n| {
        let linear = n.linear.clone();
        n.one(linear)
    },
    visibility: |_, maps| call("shared/vis_hard", "vis_hard", maps),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    reach: super::reach::one_texel,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[],
    example: "scenes/grazing.toml",
    colour: [0x44, 0x44, 0x44],
    sweep: SweepPlan::Defaults,
};
