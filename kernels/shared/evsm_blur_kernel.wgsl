// The EVSM encoding fused into the blur (import-only module of `evsm_blur` and
// `evsm_blur_row`): its parameters, texel and entry point over shared/encode_blur. The
// importing kernel declares the row path's shape, `const ROW` and `const ROW_RUN`
// (shared/encode_blur), and its `// #traffic` lines:
// #completed-by-importer
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

const CHANNELS: u32 = 4u;
// The tile its workgroup memory allows (shared/encode_blur). Keep in sync with
// `encode_blur_tile` in src/filter/encode_blur.rs.
const TILE: u32 = 16u;
const SH_TEXELS: u32 = 1024u;
// Outputs an invocation sums in the tile's blur passes, four channels: one output an invocation (shared/encode_blur, `run_sums`).
const RUN: u32 = 1u;
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
