//! `pcf`: percentage-closer filtering over a `2r + 1` window, or the hardware 2×2 comparison.

use super::params::{choice, int};
use super::shade::{ShadeInput, VisibilityBody, call, first};
use super::sweep_plan::SweepPlan;
use super::unit_range;
use super::{TechniqueDef, no_clamp, no_encoding};
use crate::model::Light;
use crate::model::{Needs, ParamSpec, ParamValue, ParamValues, PcfKernel, Technique};
use crate::wgsl_mirrors::LightGpu;
use crate::wgsl_mirrors::TECHNIQUE_PCF;

const KERNELS: &[(&str, PcfKernel)] = &[
    ("box", PcfKernel::Box),
    ("tent", PcfKernel::Tent),
    ("hardware", PcfKernel::Hardware),
];

const PARAMS: &[ParamSpec] = &[
    choice(
        "kernel",
        &["box", "tent", "hardware"],
        "box",
        "window weights, or the hardware 2×2 comparison",
    ),
    ParamSpec {
        needs: &[Needs {
            key: "kernel",
            one_of: &["box", "tent"],
            why: "does not apply to the hardware 2×2 kernel",
        }],
        ..int("radius", 0, 32, 1, "window radius in texels")
    },
];

/// The receiver-plane bias keys ([`super::params::RECEIVER_PLANE`]) for the box and tent
/// windows; the hardware kernel compares four texels against one reference.
const RECEIVER_PLANE: &[ParamSpec] = &[
    ParamSpec {
        needs: &[Needs {
            key: "kernel",
            one_of: &["box", "tent"],
            why: "does not apply to the hardware 2×2 kernel (one reference depth for four texels)",
        }],
        ..super::params::RECEIVER_PLANE[0]
    },
    super::params::RECEIVER_PLANE[1],
];

fn build(v: &ParamValues) -> Technique {
    let kernel = KERNELS
        .iter()
        .find(|(n, _)| *n == v.choice("kernel"))
        .map_or(PcfKernel::Box, |&(_, k)| k);
    Technique::Pcf {
        // The hardware kernel reads no radius; it keeps the default.
        radius: match v.get("radius") {
            Some(ParamValue::Int(r)) => r,
            _ => 1,
        },
        kernel,
    }
}

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Pcf { radius, kernel } = *t {
        let name = KERNELS
            .iter()
            .find(|(_, k)| *k == kernel)
            .map_or("box", |(n, _)| n);
        out.set("kernel", ParamValue::Choice(name));
        if kernel != PcfKernel::Hardware {
            out.set("radius", ParamValue::Int(radius));
        }
    }
    out
}

fn hardware(t: &Technique) -> bool {
    matches!(
        t,
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        }
    )
}

/// The radius and the kernel's index (`LightGpu::kernel`: 0 box, 1 tent, 2 hardware).
fn gpu(t: &Technique, g: &mut LightGpu) {
    if let Technique::Pcf { radius, kernel } = *t {
        g.radius = radius;
        g.kernel = KERNELS.iter().position(|(_, k)| *k == kernel).unwrap_or(0) as u32;
    }
}

fn visibility(light: &Light, maps: &[String]) -> VisibilityBody {
    if hardware(&light.shadow.technique) {
        let body = format!(
            "return vis_pcf_hardware({}, cmp_sampler, l, s);",
            first(maps)
        );
        return VisibilityBody::simple(vec!["shared/vis_pcf"], body);
    }
    call("shared/vis_pcf", "vis_pcf", maps)
}

/// PCF's reach: the window's radius and the bilinear tap (the hardware kernel's 2 × 2 taps: one
/// texel).
fn pcf_reach(t: &Technique, _: u32) -> Result<f32, String> {
    Ok(match *t {
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        } => 1.0,
        Technique::Pcf { radius, .. } => radius as f32 + 1.0,
        _ => 1.0,
    })
}

/// `pcf`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "pcf",
    id: TECHNIQUE_PCF,
    doc: "percentage-closer filtering",
    params: &[PARAMS, RECEIVER_PLANE],
    build,
    values,
    gpu,
    nodes: |n| match n.light.shadow.technique {
        // The hardware comparison sampler reads the depth itself.
        Technique::Pcf {
            kernel: PcfKernel::Hardware,
            ..
        } => ShadeInput {
            maps: vec![n.depth.clone()],
            wgsl_type: "texture_depth_2d",
        },
        _ => {
            let linear = n.linear.clone();
            n.one(linear)
        }
    },
    visibility,
    variant: |t| u8::from(hardware(t)).to_string(),
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    reach: pcf_reach,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[],
    example: "scenes/bunny.toml",
    colour: [0x1f, 0x77, 0xb4],
    sweep: SweepPlan::Radii {
        full: &[1, 2, 4],
        quick: &[2],
        every_size: 2,
    },
};
