// Rasterized depth → linear light-space depth in [0, 1] (shared/linear_depth), with
// non-finite texels replaced by 1.0 and counted in stats[0]. The encodings linearize the depth
// themselves; this map is planned only where something reads the linear depth (hard, PCF and
// PCSS shading, diagnostics).

// #import shared/linear_depth

// Traffic (the cost model, src/graph/cost): one texel in, one out; the counter is one atomic per
// replaced texel.
// #traffic src: all
// #traffic dst: all
// #traffic stats: none
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<r32float, write>;
@group(0) @binding(2) var<uniform> params: DepthParams;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

const WG_SIZE: u32 = 16u;

// The redesign layout (`exec::KernelLayout::Redesign`, REDESIGN true) gives an invocation
// TEXELS_X texels, WG_SIZE apart along x so that neighbouring lanes stay on neighbouring
// texels, and issues every load before the first texel's arithmetic and store (one load in
// flight an invocation left the texture copies at 0.3 of the buffer copy on an H200); each
// texel's arithmetic is the one-texel kernel's, so both give the same map bit for bit. The
// dispatch covers WG_SIZE · TEXELS_X columns a workgroup (`kernels::TEXELS_X_CONSTANT`).
override REDESIGN: bool = false;
override TEXELS_X: u32 = select(1u, 4u, REDESIGN);
const TEXELS_MAX: u32 = 4u;

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
    let size = textureDimensions(dst);
    if any(id.xy >= size) {
        return;
    }
    encode(id.xy, textureLoad(src, id.xy, 0).r);
}

// Texel `xy` of the map from its raw depth.
fn encode(xy: vec2<u32>, raw: f32) {
    if !depth_is_finite(raw) {
        atomicAdd(&stats[0], 1u);
    }
    textureStore(dst, xy, vec4<f32>(linear_depth(raw, params), 0.0, 0.0, 0.0));
}

// TEXELS_X texels an invocation (the redesign layout): every load first, then each texel.
fn main_texels(wg: vec2<u32>, lid: vec2<u32>) {
    let size = textureDimensions(dst);
    let y = wg.y * WG_SIZE + lid.y;
    let x0 = wg.x * TEXELS_X * WG_SIZE + lid.x;
    // Past the edge a lane loads the last texel again (cached already) and skips its store:
    // the loads stay unconditional, so none waits on another's branch.
    var raw: array<f32, TEXELS_MAX>;
    for (var k = 0u; k < TEXELS_X; k++) {
        raw[k] = textureLoad(src, min(vec2<u32>(x0 + k * WG_SIZE, y), size - 1u), 0).r;
    }
    if y >= size.y {
        return;
    }
    for (var k = 0u; k < TEXELS_X; k++) {
        let x = x0 + k * WG_SIZE;
        if x < size.x {
            encode(vec2<u32>(x, y), raw[k]);
        }
    }
}
