// The first and second rasterized depths → the depth a second-depth shadow map compares
// against: the midpoint (z1 + z2)/2 (Woo 1992, `mode` 0) or the second depth z2 (Wang & Molnar
// 1994, `mode` 1), both linear. Where no second surface was rasterized (z2 still the cleared
// far plane: a lone plane, an open mesh's edge, the map's empty texels) the texel falls back to
// the first depth plus the constant bias, the test a `hard` light makes: the shading then
// compares with no bias of its own. The peel pass (`shadow_peel`) wrote z2.

// #import shared/linear_depth

// Keep in sync with `SecondDepthParams` in src/gpu_data.rs.
struct Params {
    depth: DepthParams,
    mode: u32,          // 0 midpoint, 1 second depth
    fallback_bias: f32, // added to z1 where there is no z2, linear depth units
    _pad0: u32,
    _pad1: u32,
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
    let raw2 = textureLoad(src2, id.xy, 0).r;
    let second = load_linear_depth(src2, id.xy, params.depth);
    if !first.finite || !second.finite {
        atomicAdd(&stats[0], 1u);
    }
    // The peel pass clears to 1.0 (the far plane): nothing behind the first surface.
    let missing = !second.finite || raw2 >= 1.0;
    var z = select(0.5 * (first.z + second.z), second.z, params.mode == 1u);
    z = select(z, first.z + params.fallback_bias, missing);
    textureStore(dst, id.xy, vec4<f32>(z, 0.0, 0.0, 0.0));
}
