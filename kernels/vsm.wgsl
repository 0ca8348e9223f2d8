// Rasterized depth → variance-shadow-map moments (shared/vsm_moments), unfiltered: the map a
// summed-area table, a mip chain or no filter reads (a blur reads the depth itself: `vsm_blur`).
// The depth is linearized here (shared/linear_depth), texel by texel as it is read: no linear
// map is written in between. Non-finite depth becomes 1.0 and is counted once, at the texel's own
// invocation.
// Storage: rg32float by default; the executor re-declares `dst` for f16 (rgba16float).

// #import shared/linear_depth
// #import shared/vsm_moments

// Keep in sync with `VsmParams` in src/wgsl_mirrors.rs.
struct Params {
    depth: DepthParams,
}

// Traffic (the cost model, src/graph/cost): the derivatives read a texel's four neighbours: a tile
// and a one-texel cross-shaped halo.
// #traffic src: WG_SIZE * WG_SIZE + 4 * WG_SIZE per group
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

const WG_SIZE: u32 = 16u;

fn depth_at(p: vec2<i32>, size: vec2<i32>) -> f32 {
    return linear_depth(textureLoad(src, clamp(p, vec2<i32>(0), size - 1), 0).r, params.depth);
}

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(src));
    let p = vec2<i32>(id.xy);
    if any(p >= size) {
        return;
    }
    let depth = load_linear_depth(src, id.xy, params.depth);
    if !depth.finite {
        atomicAdd(&stats[0], 1u);
    }
    let z = depth.z;
    let m = vsm_moments(
        z,
        depth_at(p - vec2<i32>(1, 0), size),
        depth_at(p + vec2<i32>(1, 0), size),
        depth_at(p - vec2<i32>(0, 1), size),
        depth_at(p + vec2<i32>(0, 1), size)
    );
    textureStore(dst, p, vec4<f32>(m, 0.0, 0.0));
}
