// The EVSM encoding fused into the blur (import-only module of `evsm_blur` and
// `evsm_blur_row`): its parameters and encoding over shared/encode_blur, the texel
// shared/encode_blur_rgba's. The importing kernel declares the row path's shape, `const ROW`
// and `const ROW_RUN` (shared/encode_blur), and its `// #traffic` lines:
// #completed-by-importer
// #import shared/encode_blur
// #import shared/encode_blur_rgba
// #import shared/evsm_moments

// Keep in sync with `ExpParams` in src/wgsl_mirrors.rs, then `BlurParams` in src/filter.rs.
struct Params {
    depth: DepthParams,
    exp_pos: f32,
    exp_neg: f32,
    linear: u32,
    _pad0: u32,
    blur: BlurSpec,
}

// The parameters the encoding reads (shared/encode_blur's `Coding`).
struct Coding {
    exp_pos: f32,
    exp_neg: f32,
}

// Whether `encode` reads the depths beside its texel (shared/encode_blur):
// its moments are of the texel alone.
const NEIGHBOURS: bool = false;

fn coding() -> Coding {
    return Coding(params.exp_pos, params.exp_neg);
}

fn encode(z: f32, left: f32, right: f32, up: f32, down: f32, c: Coding) -> vec4<f32> {
    return evsm_moments(z, c.exp_pos, c.exp_neg);
}
