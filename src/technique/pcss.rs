//! `pcss`: percentage-closer soft shadows (Fernando 2005).

use super::no_encoding;
use super::params::{float, int};
use super::shade::call;
use super::sweep_plan::SweepPlan;
use super::{TechniqueDef, no_clamp};
use super::{no_variant, unit_range};
use crate::model::{DEFAULT_MAX_SEARCH, ParamSpec, ParamValue, ParamValues, Technique};
use crate::wgsl_mirrors::TECHNIQUE_PCSS;

const PARAMS: &[ParamSpec] = &[
    int("blocker_samples", 1, 256, 16, "blocker-search taps"),
    int("filter_samples", 1, 1024, 32, "filter taps"),
    float(
        "max_search",
        1e-4,
        1.0,
        DEFAULT_MAX_SEARCH,
        "cap on the blocker-search radius, shadow-map UV (and on the filter's on a point light and in cascades, where it is of the light's one map, 2·extent wide)",
    ),
];

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Pcss {
        blocker_samples,
        filter_samples,
        max_search,
    } = *t
    {
        out.set("blocker_samples", ParamValue::Int(blocker_samples));
        out.set("filter_samples", ParamValue::Int(filter_samples));
        out.set("max_search", ParamValue::Float(max_search));
    }
    out
}

/// `pcss`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "pcss",
    id: TECHNIQUE_PCSS,
    doc: "percentage-closer soft shadows: blocker search, penumbra width, PCF",
    params: &[PARAMS, super::params::RECEIVER_PLANE],
    build: |v| Technique::Pcss {
        blocker_samples: v.int("blocker_samples"),
        filter_samples: v.int("filter_samples"),
        max_search: v.float("max_search"),
    },
    values,
    gpu: |t, g| {
        if let Technique::Pcss {
            blocker_samples,
            filter_samples,
            max_search,
        } = *t
        {
            g.blocker_samples = blocker_samples;
            g.filter_samples = filter_samples;
            g.max_search = max_search;
        }
    },
    nodes: |n| {
        let linear = n.linear.clone();
        n.one(linear)
    },
    visibility: |_, maps| call("shared/vis_pcss", "vis_pcss", maps),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: true,
    reach: super::reach::searched,
    texels_past_radius: Some(1.0),
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[],
    example: "scenes/colonnade.toml",
    colour: [0x17, 0xbe, 0xcf],
    // PCSS as engines ship it, at several tap counts (blocker search + filter).
    sweep: SweepPlan::Taps(&[(8, 16), (16, 32), (32, 64), (64, 64)]),
};
