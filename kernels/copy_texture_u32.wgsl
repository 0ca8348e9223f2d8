// The texture yardstick of `shadowgraph bench` for unsigned-integer textures (summed-area
// tables in fixed point): `copy_texture` with `texture_2d<u32>` and `rgba32uint` storage.
// Traffic (the cost model, src/graph/cost): every texel read once and written once.
// #traffic src: all
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<u32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32uint, write>;

const WG_SIZE: u32 = 16u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(src)) {
        return;
    }
    textureStore(dst, id.xy, textureLoad(src, id.xy, 0));
}
