// Tiles of the summed-area-table kernels (import-only module). A workgroup owns a TILE × TILE
// tile of the map; its GRID × GRID invocations each own a SUB × SUB sub-block, swept row by
// row with SUB running column sums in registers, so invocations meet in workgroup memory only
// through their sub-blocks' edge sums (O(SUB) values for SUB² texels). No function returns an
// array: llvmpipe copies such returns through memory, twenty times slower than the sweep.
// #import shared/sat_params

// Keep in sync with `SAT_TILE` in src/sat.rs.
const SUB: u32 = 8u;
const GRID: u32 = 8u;
const TILE: u32 = 64u; // SUB · GRID
const WG_SIZE: u32 = 64u; // GRID · GRID

// a + b in the variant's arithmetic: wrapping u32, or f32 on the values' bits. The kernels of
// one variant pass `fs` as a constant, so the branch folds away (a uniform branch per add
// costs llvmpipe a quarter of the pass); it is a branch, not a select, so fixed point never
// adds its codes as floats, whose bit patterns may be denormals or NaNs.
fn sat_sum(a: vec4<u32>, b: vec4<u32>, fs: bool) -> vec4<u32> {
    if fs {
        return bitcast<vec4<u32>>(bitcast<vec4<f32>>(a) + bitcast<vec4<f32>>(b));
    }
    return a + b;
}

// The first texel of the sub-block that invocation `li` of tile `tile` owns (invocation li
// is sub-block column li % GRID, row li / GRID).
fn sat_sub_origin(tile: vec2<u32>, li: u32) -> vec2<u32> {
    return tile * TILE + vec2<u32>(li % GRID, li / GRID) * SUB;
}

// The encoded texel `q` of `src` (`size` its size), 0 outside the map (the load is clamped to
// the map and its value discarded, so no invocation branches).
fn sat_texel(
    src: texture_2d<f32>,
    q: vec2<u32>,
    size: vec2<u32>,
    p: SatParams,
    fs: bool,
) -> vec4<u32> {
    let e = sat_encode_as(textureLoad(src, min(q, size - 1u), 0), p, fs);
    return select(vec4<u32>(0u), e, all(q < size));
}
