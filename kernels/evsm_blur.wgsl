// Rasterized depth → exponential variance moments (shared/evsm_moments), blurred, in one pass:
// the encoding fused into the separable blur (shared/encode_blur), each texel's two `exp`s
// taken once. With a radius past TILE_RADIUS it is the first of two passes (encode and blur
// along x; `blur` along y). EVSM2 binds an rg32float output and keeps (pos, pos²).

// #import shared/encode_blur
// #import shared/evsm_moments

// Keep in sync with `ExpParams` in src/gpu_data.rs, then `BlurParams` in src/filter.rs.
struct Params {
    depth: DepthParams,
    exp_pos: f32,
    exp_neg: f32,
    linear: u32,
    _pad0: u32,
    blur: BlurSpec,
}

// Traffic (the cost model, src/graph/cost): a tile workgroup loads its TILE² depths with a halo
// of r + 1 each side, a row workgroup three rows of its outputs (ROW, the last of a row the rest) + 2r + 2; each output is stored once.
// #traffic src: select(3 * (dst.width / ceil(dst.width / ROW) + 2 * min(params.blur.radius, MAX_RADIUS) + 2), (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2) * (TILE + 2 * min(params.blur.radius, TILE_RADIUS) + 2), params.blur.axis == 2) per group
// #traffic dst: all
// #traffic stats: none

const CHANNELS: u32 = 4u;
// The tile its workgroup memory allows (shared/encode_blur). Keep in sync with
// `encode_blur_tile` in src/filter/encode_blur.rs.
const TILE: u32 = 16u;
const SH_TEXELS: u32 = 1024u;
// Outputs an invocation sums in the tile's blur passes, four channels: one output an invocation (shared/encode_blur, `run_sums`).
const RUN: u32 = 1u;
// Outputs of a one-row workgroup (the fallback past TILE_RADIUS) and the run an invocation sums
// there (shared/encode_blur). Keep in sync with `encode_blur_row` in src/filter/encode_blur.rs.
const ROW: u32 = 256u;
const ROW_RUN: u32 = 1u;
alias Texel = vec4<f32>;

fn texel_of(v: vec4<f32>) -> Texel {
    return v;
}

fn texel_out(t: Texel) -> vec4<f32> {
    return t;
}

fn encode(z: f32, left: f32, right: f32, up: f32, down: f32) -> vec4<f32> {
    return evsm_moments(z, params.exp_pos, params.exp_neg);
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    encode_blur(wg.xy, li);
}
