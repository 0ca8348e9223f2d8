// Depth-only rasterization from a light (no fragment stage): the shadow map. Its position is
// `@invariant`, as `shadow_peel`'s, so the peel pass meets each surface at the same depth.

struct LightView {
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> light: LightView;

// #import shared/vertex

@vertex
fn vs_main(v: VsIn) -> @builtin(position) @invariant vec4<f32> {
    return light.view_proj * vec4<f32>(v.position, 1.0);
}
