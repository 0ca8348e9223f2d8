//! `midpoint` (Woo 1992) and `second_depth` (Wang & Molnar 1994): shadow maps of the midpoint
//! of the first and second surfaces, or of the second surface, seen from the light. A second
//! raster pass peels the first surface off (`kernels/shadow_peel.wgsl`, imported as
//! [`second_depth_name`]); the `second_depth` kernel turns both depths into the one map the
//! shading compares against with `vis_hard`. Where no second surface exists (a lone plane, the
//! map's empty texels) a texel holds the first depth plus the constant `bias`, so a caster that
//! is not watertight shades as `hard` with that bias there; elsewhere no bias is added.

use super::shade::call;
use super::sweep_plan::SweepPlan;
use super::{LightNodes, ShadeInput, TechniqueDef, no_clamp, no_variant, unit_range};
use crate::gpu_data::{SecondDepthParams, TECHNIQUE_MIDPOINT, TECHNIQUE_SECOND_DEPTH};
use crate::graph::{Dispatch, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::{ParamValues, Technique};

/// Name of light `i`'s second rasterized depth (the peel pass's output, imported into the
/// graph like the first).
pub fn second_depth_name(i: usize) -> String {
    format!("light{i}.depth2")
}

/// Whether technique `t` reads a second, peeled depth map: the renderer then rasterizes it
/// after the first, and the plug-in stage (which takes one depth texture) refuses it.
pub fn peels(t: &Technique) -> bool {
    matches!(t, Technique::Midpoint | Technique::SecondDepth)
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
        fallback_bias: n.light.shadow.bias,
        _pad: [0; 2],
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

/// The constant bias went into the map where it applies (the fallback texels): the shading
/// adds none.
fn gpu(_: &Technique, g: &mut crate::gpu_data::LightGpu) {
    g.bias = 0.0;
}

/// `midpoint`.
pub(super) static MIDPOINT: TechniqueDef = TechniqueDef {
    name: "midpoint",
    id: TECHNIQUE_MIDPOINT,
    doc: "midpoint shadow map (Woo): compares against (z1 + z2)/2 of a second, peeled raster pass; z1 + bias where there is no z2",
    params: &[],
    build: |_| Technique::Midpoint,
    values: |_| ParamValues::default(),
    gpu,
    nodes: |n| nodes(n, 0),
    visibility: |_, maps| call("shared/vis_hard", "vis_hard", maps),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    example: "scenes/techniques/midpoint.toml",
    colour: [0x8c, 0x56, 0x4b],
    sweep: SweepPlan::Defaults,
};

/// `second_depth`.
pub(super) static SECOND_DEPTH: TechniqueDef = TechniqueDef {
    name: "second_depth",
    id: TECHNIQUE_SECOND_DEPTH,
    doc: "second-depth shadow map (Wang & Molnar): compares against z2 of a second, peeled raster pass; z1 + bias where there is no z2",
    params: &[],
    build: |_| Technique::SecondDepth,
    values: |_| ParamValues::default(),
    gpu,
    nodes: |n| nodes(n, 1),
    visibility: |_, maps| call("shared/vis_hard", "vis_hard", maps),
    variant: no_variant,
    value_range: unit_range,
    clamp: no_clamp,
    area_light: false,
    example: "scenes/techniques/second_depth.toml",
    colour: [0xc4, 0x9c, 0x94],
    sweep: SweepPlan::Defaults,
};
