// Depth-only rasterization from a light (no fragment stage): the shadow map. Its position is
// `@invariant`, as `shadow_peel`'s, so the peel pass meets each surface at the same depth.
// Each view of the light (one; a point light's six faces, each drawn into its tile's viewport)
// is one draw whose instance index picks its matrix.

// Views a light rasterizes at most (`model::point::FACES`).
const VIEWS: u32 = 6u;

struct LightView {
    view_proj: array<mat4x4<f32>, VIEWS>,
}

@group(0) @binding(0) var<uniform> light: LightView;

// #import shared/vertex

@vertex
fn vs_main(v: VsIn, @builtin(instance_index) view: u32) -> @builtin(position) @invariant vec4<f32> {
    return light.view_proj[min(view, VIEWS - 1u)] * vec4<f32>(v.position, 1.0);
}
