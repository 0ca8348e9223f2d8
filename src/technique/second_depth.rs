//! `midpoint` (Woo 1992) and `second_depth` (Wang & Molnar 1994): shadow maps of the midpoint
//! of the first and second surfaces, or of the second surface, seen from the light. A second
//! raster pass peels the first surface off (`kernels/shadow_peel.wgsl`, imported as
//! [`second_depth_name`]); the `second_depth` kernel turns both depths into the one map the
//! shading compares against with `vis_hard` (or `vis_pcf` over a window, `radius` > 0), with no
//! bias: the light's constant `bias` is not read. Where no second surface exists (a lone plane
//! such as the ground, an open mesh's rim, the map's empty texels) a texel holds the far plane
//! in both modes: nothing lies behind its first surface, which is lit.

use super::no_encoding;
use super::params::{choice, int};
use super::shade::{VisibilityBody, call};
use super::sweep_plan::SweepPlan;
use super::{LightNodes, ShadeInput, TechniqueDef, no_clamp, unit_range};
use crate::graph::{Dispatch, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::{Light, ParamSpec, ParamValue, ParamValues, PcfKernel, Technique};
use crate::wgsl_mirrors::{
    LightGpu, SecondDepthParams, TECHNIQUE_MIDPOINT, TECHNIQUE_SECOND_DEPTH,
};

/// PCF over the comparisons with the map (`vis_pcf`'s box and tent windows; the hardware 2×2
/// comparison reads the first depth, not this map).
const PARAMS: &[ParamSpec] = &[
    choice(
        "kernel",
        &["box", "tent"],
        "box",
        "PCF window weights over the comparisons (radius > 0)",
    ),
    int(
        "radius",
        0,
        32,
        0,
        "PCF window radius in texels; 0 compares the nearest texel alone, as `hard`",
    ),
];

/// The PCF window of `t`: (radius, kernel).
fn window(t: &Technique) -> (u32, PcfKernel) {
    match *t {
        Technique::Midpoint { radius, kernel } | Technique::SecondDepth { radius, kernel } => {
            (radius, kernel)
        }
        _ => (0, PcfKernel::Box),
    }
}

/// The window of checked values.
fn build_window(v: &ParamValues) -> (u32, PcfKernel) {
    let kernel = match v.choice("kernel") {
        "tent" => PcfKernel::Tent,
        _ => PcfKernel::Box,
    };
    (v.int("radius"), kernel)
}

fn values(t: &Technique) -> ParamValues {
    let (radius, kernel) = window(t);
    let mut out = ParamValues::default();
    let name = if kernel == PcfKernel::Tent {
        "tent"
    } else {
        "box"
    };
    out.set("kernel", ParamValue::Choice(name));
    out.set("radius", ParamValue::Int(radius));
    out
}

/// The nearest texel's comparison at radius 0, else PCF over the window.
fn visibility(light: &Light, maps: &[String]) -> VisibilityBody {
    match window(&light.shadow.technique).0 {
        0 => call("shared/vis_hard", "vis_hard", maps),
        _ => call("shared/vis_pcf", "vis_pcf", maps),
    }
}

/// Name of light `i`'s second rasterized depth (the peel pass's output, imported into the
/// graph like the first).
pub fn second_depth_name(i: usize) -> String {
    format!("light{i}.depth2")
}

/// Whether technique `t` reads a second, peeled depth map: the renderer then rasterizes it
/// after the first, and the plug-in stage (which takes one depth texture) refuses it.
pub fn peels(t: &Technique) -> bool {
    matches!(
        t,
        Technique::Midpoint { .. } | Technique::SecondDepth { .. }
    )
}

/// The second depth's import and the `second_depth` node (`mode` 0 midpoint, 1 second depth)
/// writing `light{i}.second_depth`, what the shading reads.
fn nodes(n: &mut LightNodes, mode: u32) -> ShadeInput {
    let i = n.i;
    let side = n.light.shadow_map;
    let second = n.graph.import(
        second_depth_name(i),
        wgpu::TextureFormat::Depth32Float,
        side,
        side,
        Some(i),
    );
    let out = n.graph.resource(
        format!("light{i}.second_depth"),
        wgpu::TextureFormat::R32Float,
        SizeRule::Reduced {
            of: n.depth.clone(),
            shift: 0,
        },
        Some(i),
    );
    let params = SecondDepthParams {
        depth: n.lin,
        mode,
        _pad: [0; 3],
    };
    n.graph.node(Node {
        name: format!("light{i}.second_depth"),
        kernel: KernelId::SecondDepth,
        inputs: vec![("src".into(), n.depth.clone()), ("src2".into(), second)],
        outputs: vec![("dst".into(), out.clone())],
        params: bytemuck::bytes_of(&params).to_vec(),
        dispatch: Dispatch::Texels(out.clone()),
        light: Some(i),
    });
    n.one(out)
}

/// The map needs no bias (the far plane where there is no second surface): the shading adds
/// none. The PCF window as `pcf`'s (`LightGpu::kernel`: 0 box, 1 tent).
fn gpu(t: &Technique, g: &mut LightGpu) {
    g.bias = 0.0;
    let (radius, kernel) = window(t);
    g.radius = radius;
    g.kernel = u32::from(kernel == PcfKernel::Tent);
}

/// The peeled techniques cannot draw a point light's six faces.
fn peel_reach(t: &Technique, _: u32) -> Result<f32, String> {
    Err(format!(
        "point lights do not support \"{}\": the peeled second-depth pass draws one map, not six faces",
        t.name()
    ))
}

/// `midpoint`.
pub(super) static MIDPOINT: TechniqueDef = TechniqueDef {
    name: "midpoint",
    id: TECHNIQUE_MIDPOINT,
    doc: "midpoint shadow map (Woo): compares against (z1 + z2)/2 of a second, peeled raster pass, no bias; the far plane where there is no z2",
    params: &[PARAMS],
    build: |v| {
        let (radius, kernel) = build_window(v);
        Technique::Midpoint { radius, kernel }
    },
    values,
    gpu,
    nodes: |n| nodes(n, 0),
    visibility,
    variant: |t| u8::from(window(t).0 > 0).to_string(),
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    reach: peel_reach,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[],
    example: "scenes/techniques/midpoint.toml",
    colour: [0x8c, 0x56, 0x4b],
    sweep: SweepPlan::Defaults,
};

/// `second_depth`.
pub(super) static SECOND_DEPTH: TechniqueDef = TechniqueDef {
    name: "second_depth",
    id: TECHNIQUE_SECOND_DEPTH,
    doc: "second-depth shadow map (Wang & Molnar): compares against z2 of a second, peeled raster pass, no bias; the far plane where there is no z2",
    params: &[PARAMS],
    build: |v| {
        let (radius, kernel) = build_window(v);
        Technique::SecondDepth { radius, kernel }
    },
    values,
    gpu,
    nodes: |n| nodes(n, 1),
    visibility,
    variant: |t| u8::from(window(t).0 > 0).to_string(),
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    reach: peel_reach,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: no_encoding,
    maps: &[],
    example: "scenes/techniques/second_depth.toml",
    colour: [0xc4, 0x9c, 0x94],
    sweep: SweepPlan::Defaults,
};
