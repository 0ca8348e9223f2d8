// The texture yardstick of `shadowgraph bench` at the memory's speed for unsigned-integer
// textures (summed-area tables in fixed point): `copy_texture_x4` with `texture_2d<u32>` and
// `rgba32uint` storage (four texels an invocation, WG_SIZE apart along x, every load issued
// before the first store).
// Storage: rgba32uint by default; the executor re-declares `dst` for the bound format.
// Traffic (the cost model, src/graph/cost): every texel read once and written once.
// #traffic src: all
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<u32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32uint, write>;

const WG_SIZE: u32 = 16u;
const TEXELS_X: u32 = 4u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let size = textureDimensions(src);
    let y = wg.y * WG_SIZE + lid.y;
    let x0 = wg.x * TEXELS_X * WG_SIZE + lid.x;
    // Past the edge a lane loads the last column again (in the cache already) and skips its
    // store: the loads stay unconditional, so none waits on another's branch.
    let last = vec2<u32>(size.x - 1u, min(y, size.y - 1u));
    var v: array<vec4<u32>, TEXELS_X>;
    for (var k = 0u; k < TEXELS_X; k++) {
        v[k] = textureLoad(src, vec2<u32>(min(x0 + k * WG_SIZE, last.x), last.y), 0);
    }
    if y >= size.y {
        return;
    }
    for (var k = 0u; k < TEXELS_X; k++) {
        let x = x0 + k * WG_SIZE;
        if x < size.x {
            textureStore(dst, vec2<u32>(x, y), v[k]);
        }
    }
}
