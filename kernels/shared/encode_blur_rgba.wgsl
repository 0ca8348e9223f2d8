// The four-channel texel of the encodings fused into the blur (import-only module of
// shared/evsm_blur_kernel and shared/msm_blur_kernel): what shared/encode_blur asks of its
// importer for four channels — a vec4<f32> texel, a 16² tile (its encoded texels at
// TILE_RADIUS, SH_TEXELS of 16 B, in 14.1 of WebGPU's 16 KiB of workgroup memory), one output an
// invocation in the tile's blur.

const CHANNELS: u32 = 4u;
// The tile its workgroup memory allows (shared/encode_blur). Keep in sync with
// `encode_blur_tile` in src/filter/encode_blur.rs.
const TILE: u32 = 16u;
const SH_TEXELS: u32 = 900u;
// Outputs an invocation sums in the tile's blur passes, four channels: one output an invocation (shared/encode_blur_tile, `run_sums`).
const RUN: u32 = 1u;
// Output rows of a CPU driver's tile (shared/encode_blur, `filter::encode_blur_cpu_rows`):
// 40 encoded rows at r = 4, five for each of the 8 walks.
const CPU_TILE_ROWS: u32 = 32u;
// Encoded rows a strip walks at once (shared/encode_blur_strips, `walk_step`): one (the encodings read
// no neighbours, and a second window of four channels took llvmpipe 9% more instructions).
const WALK_ROWS: u32 = 1u;
alias Texel = vec4<f32>;

fn texel_of(v: vec4<f32>) -> Texel {
    return v;
}

fn texel_out(t: Texel) -> vec4<f32> {
    return t;
}
