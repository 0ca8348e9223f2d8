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

// The redesign layout (`exec::KernelLayout::Redesign`, REDESIGN true) gives an invocation
// TEXELS_X texels, WG_SIZE apart along x so that neighbouring lanes stay on neighbouring
// texels, and issues every load (each texel's and its four neighbours') before the first
// texel's arithmetic and store (one texel in flight an invocation left the texture copies at
// 0.3 of the buffer copy on an H200); each texel's arithmetic is the one-texel kernel's, so
// both give the same map bit for bit. The dispatch covers WG_SIZE · TEXELS_X columns a
// workgroup (`kernels::TEXELS_X_CONSTANT`).
override REDESIGN: bool = false;
override TEXELS_X: u32 = select(1u, 4u, REDESIGN);
const TEXELS_MAX: u32 = 4u;

fn depth_at(p: vec2<i32>, size: vec2<i32>) -> f32 {
    return linear_depth(textureLoad(src, clamp(p, vec2<i32>(0), size - 1), 0).r, params.depth);
}

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
) {
    if REDESIGN {
        main_texels(wg.xy, lid.xy);
        return;
    }
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

// The raw depth at `p`, clamped to the map.
fn raw_at(p: vec2<i32>, size: vec2<i32>) -> f32 {
    return textureLoad(src, clamp(p, vec2<i32>(0), size - 1), 0).r;
}

// TEXELS_X texels an invocation (the redesign layout): every texel's and its neighbours' loads
// first, then each texel.
fn main_texels(wg: vec2<u32>, lid: vec2<u32>) {
    let size = vec2<i32>(textureDimensions(src));
    let y = i32(wg.y * WG_SIZE + lid.y);
    let x0 = i32(wg.x * TEXELS_X * WG_SIZE + lid.x);
    // Past the edge a lane loads the last texel's cross again (cached already) and skips its
    // store: the loads stay unconditional, so none waits on another's branch.
    var centre: array<f32, TEXELS_MAX>;
    var around: array<vec4<f32>, TEXELS_MAX>;
    for (var k = 0u; k < TEXELS_X; k++) {
        let q = min(vec2<i32>(x0 + i32(k * WG_SIZE), y), size - 1);
        centre[k] = textureLoad(src, q, 0).r;
        around[k] = vec4<f32>(
            raw_at(q - vec2<i32>(1, 0), size),
            raw_at(q + vec2<i32>(1, 0), size),
            raw_at(q - vec2<i32>(0, 1), size),
            raw_at(q + vec2<i32>(0, 1), size)
        );
    }
    if y >= size.y {
        return;
    }
    for (var k = 0u; k < TEXELS_X; k++) {
        let p = vec2<i32>(x0 + i32(k * WG_SIZE), y);
        if p.x >= size.x {
            continue;
        }
        if !depth_is_finite(centre[k]) {
            atomicAdd(&stats[0], 1u);
        }
        let a = around[k];
        let m = vsm_moments(
            linear_depth(centre[k], params.depth),
            linear_depth(a.x, params.depth),
            linear_depth(a.y, params.depth),
            linear_depth(a.z, params.depth),
            linear_depth(a.w, params.depth)
        );
        textureStore(dst, p, vec4<f32>(m, 0.0, 0.0));
    }
}
