//! `smrt`: shadow-map ray tracing, after Unreal Engine 5's virtual shadow maps and Blender
//! EEVEE-Next: rays toward fixed stratified points on the emitter, each marched through the one
//! linear depth map (`kernels/shared/vis_smrt.wgsl`).

use super::no_encoding;
use super::params::{float, int};
use super::shade::call;
use super::sweep_plan::{SweepPlan, SweepVariant};
use super::{TechniqueDef, no_clamp};
use super::{no_variant, unit_range};
use crate::model::{ParamSpec, ParamValue, ParamValues, Technique};
use crate::wgsl_mirrors::TECHNIQUE_SMRT;

const PARAMS: &[ParamSpec] = &[
    int(
        "rays",
        1,
        64,
        7,
        "rays per receiver, toward fixed points on the emitter (UE5: 7)",
    ),
    int("steps", 1, 64, 8, "depth-map samples per ray (UE5: 8)"),
    float(
        "max_slope",
        0.0,
        100.0,
        1.0,
        "cap on how fast the surface extrapolated behind an occluder recedes, per the ray's own depth rate",
    ),
];

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Smrt {
        rays,
        steps,
        max_slope,
    } = *t
    {
        out.set("rays", ParamValue::Int(rays));
        out.set("steps", ParamValue::Int(steps));
        out.set("max_slope", ParamValue::Float(max_slope));
    }
    out
}

/// A ray and step count over the defaults.
const fn counts(
    label: &'static str,
    values: &'static [(&'static str, ParamValue)],
) -> SweepVariant {
    SweepVariant {
        label,
        values,
        storage: None,
    }
}

/// SMRT cannot be bounded to a point light's face.
fn smrt_reach(_: &Technique, _: u32) -> Result<f32, String> {
    Err("point lights do not support \"smrt\": its rays march across the map toward the emitter's far side, which a face's guard band does not bound".into())
}

/// `smrt`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "smrt",
    id: TECHNIQUE_SMRT,
    doc: "shadow-map ray tracing: rays toward points on the emitter, marched through the depth map",
    params: &[PARAMS],
    build: |v| Technique::Smrt {
        rays: v.int("rays"),
        steps: v.int("steps"),
        max_slope: v.float("max_slope"),
    },
    values,
    gpu: |t, g| {
        if let Technique::Smrt {
            rays,
            steps,
            max_slope,
        } = *t
        {
            g.smrt_rays = rays;
            g.smrt_steps = steps;
            g.smrt_max_slope = max_slope;
        }
    },
    nodes: |n| {
        let linear = n.linear.clone();
        n.one(linear)
    },
    visibility: |_, maps| call("shared/vis_smrt", "vis_smrt", maps),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: true,
    reach: smrt_reach,
    texels_past_radius: None,
    cascades: Err(
        "its rays march across the map toward the emitter's far side, which a cascade's guard band does not bound; use pcss, vssm, msm_soft or cssm",
    ),
    encoding: no_encoding,
    maps: &[],
    example: "scenes/techniques/smrt.toml",
    colour: [0xbc, 0xbd, 0x22],
    // UE5's default first (at every map size), then fewer and more rays and steps.
    sweep: SweepPlan::Variants {
        full: &[
            counts("smrt 7x8", &[]),
            counts(
                "smrt 4x4",
                &[("rays", ParamValue::Int(4)), ("steps", ParamValue::Int(4))],
            ),
            counts(
                "smrt 16x8",
                &[("rays", ParamValue::Int(16)), ("steps", ParamValue::Int(8))],
            ),
            counts(
                "smrt 16x16",
                &[
                    ("rays", ParamValue::Int(16)),
                    ("steps", ParamValue::Int(16)),
                ],
            ),
            counts(
                "smrt 32x16",
                &[
                    ("rays", ParamValue::Int(32)),
                    ("steps", ParamValue::Int(16)),
                ],
            ),
        ],
        quick: 3,
    },
};
