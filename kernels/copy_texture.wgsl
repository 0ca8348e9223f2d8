// The texture yardstick of `shadowgraph bench`, one texel an invocation (`copy_texture_x4`
// copies four): copies a float texture texel by texel in the
// 16×16 workgroups of the map kernels, one textureLoad and one textureStore per texel. The
// source may be a depth texture (read as `texture_2d<f32>`, as `linearize` reads it).
// Storage: rgba32float by default; the executor re-declares `dst` for the bound format.
// Traffic (the cost model, src/graph/cost): every texel read once and written once.
// #traffic src: all
// #traffic dst: all
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba32float, write>;

const WG_SIZE: u32 = 16u;

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(src)) {
        return;
    }
    textureStore(dst, id.xy, textureLoad(src, id.xy, 0));
}
