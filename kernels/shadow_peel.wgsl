// Depth peeling from a light (Everitt 2001): the second-nearest surface per texel. The same
// vertices and matrix as `shadow_depth` (and `@invariant` positions in both, so a surface
// rasterizes to the same depth in both passes); each fragment at or in front of the first depth
// map, plus PEEL_EPSILON, is discarded, so the depth test keeps the nearest surface behind it.

struct LightView {
    view_proj: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> light: LightView;
@group(0) @binding(1) var first_depth: texture_depth_2d;

// #import shared/vertex

// Depth-buffer units (keep in sync with `PEEL_EPSILON` in src/wgsl_mirrors.rs). A fragment of the
// first surface reaches this pass at the depth it was stored with, but a driver may interpolate
// the fragment stage's z and the depth attachment's value differently by a few ULPs (2⁻²⁴ at
// depth 0.5–1): 2⁻¹⁸ is 64 such ULPs and 4·10⁻⁶ of the depth range, so a first surface never
// survives as its own second; surfaces closer than that to the first are peeled with it.
const PEEL_EPSILON: f32 = 1.0 / 262144.0;

struct VsOut {
    @builtin(position) @invariant clip: vec4<f32>,
}

@vertex
fn vs_main(v: VsIn) -> VsOut {
    return VsOut(light.view_proj * vec4<f32>(v.position, 1.0));
}

@fragment
fn fs_main(v: VsOut) {
    let first = textureLoad(first_depth, vec2<i32>(v.clip.xy), 0);
    if v.clip.z <= first + PEEL_EPSILON {
        discard;
    }
}
