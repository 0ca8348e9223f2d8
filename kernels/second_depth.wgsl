// The first and second rasterized depths → the depth a second-depth shadow map compares
// against: the midpoint (z1 + z2)/2 (Woo 1992, `mode` 0) or the second depth z2 (Wang & Molnar
// 1994, `mode` 1), both linear; the shading compares with no bias. The peel pass
// (`shadow_peel`) wrote z2 and clears to 1.0, the far plane, where no second surface was
// rasterized (a lone plane such as the ground, an open mesh's rim, the map's empty texels); a
// non-finite z2 linearizes to 1.0 too. There z2 is the far plane, as Wang & Molnar store it,
// and both modes store it: nothing lies behind the first surface, so the texel can shadow no
// receiver, and the one surface along its ray is lit. The midpoint of z1 and nothing is
// nothing: Woo's formula with the far plane as z2, (z1 + 1)/2, would put a phantom occluder
// halfway to the far plane, which a first surface near the far plane and steep to the light
// comes within a texel's depth slope of (acne again), so `midpoint` holds 1.0 too. Cost: one
// comparison in the select, no memory.

// #import shared/linear_depth

// Keep in sync with `SecondDepthParams` in src/wgsl_mirrors.rs.
struct Params {
    depth: DepthParams,
    mode: u32, // 0 midpoint, 1 second depth
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Traffic (the cost model, src/graph/cost): both depths in, one texel out.
// #traffic src: all
// #traffic src2: all
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src2: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<r32float, write>;
@group(0) @binding(3) var<uniform> params: Params;
@group(0) @binding(4) var<storage, read_write> stats: array<atomic<u32>>;

const WG_SIZE: u32 = 16u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(dst);
    if any(id.xy >= size) {
        return;
    }
    let first = load_linear_depth(src, id.xy, params.depth);
    let second = load_linear_depth(src2, id.xy, params.depth);
    if !first.finite || !second.finite {
        atomicAdd(&stats[0], 1u);
    }
    // No second surface: `second.z` is 1.0, the far plane, stored as it is (see the top).
    let z = select(0.5 * (first.z + second.z), second.z, params.mode == 1u || second.z >= 1.0);
    textureStore(dst, id.xy, vec4<f32>(z, 0.0, 0.0, 0.0));
}
