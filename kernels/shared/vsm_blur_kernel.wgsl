// The VSM encoding fused into the blur (import-only module of `vsm_blur` and `vsm_blur_row`):
// variance-shadow-map moments (shared/vsm_moments) of the rasterized depth, blurred in
// workgroup memory (shared/encode_blur), with its parameters and texel. The importing kernel
// declares the row path's shape, `const ROW` and `const ROW_RUN` (shared/encode_blur), and its
// `// #traffic` lines:
// #completed-by-importer
// #import shared/encode_blur
// #import shared/vsm_moments

// Keep in sync with `VsmParams` in src/wgsl_mirrors.rs, then `BlurParams` in src/filter.rs.
struct Params {
    depth: DepthParams,
    blur: BlurSpec,
}

const CHANNELS: u32 = 2u;
// The tile its workgroup memory allows (shared/encode_blur). Keep in sync with
// `encode_blur_tile` in src/filter/encode_blur.rs.
const TILE: u32 = 24u;
const SH_TEXELS: u32 = 1444u;
// Outputs an invocation sums in the tile's blur passes, two channels: runs of 4 (shared/encode_blur_tile, `run_sums`).
const RUN: u32 = 4u;
// Output rows of a CPU driver's tile (shared/encode_blur, `filter::encode_blur_cpu_rows`):
// 48 encoded rows at r = 4, three pairs for each of the 8 walks.
const CPU_TILE_ROWS: u32 = 40u;
// Encoded rows a strip walks at once (shared/encode_blur_strips, `walk_step`): two, which share their
// depths above and below (`vsm_moments` reads them).
const WALK_ROWS: u32 = 2u;
alias Texel = vec2<f32>;

fn texel_of(v: vec4<f32>) -> Texel {
    return v.xy;
}

fn texel_out(t: Texel) -> vec4<f32> {
    return vec4<f32>(t, 0.0, 0.0);
}

// VSM's encoding reads no parameters (shared/encode_blur's `Coding`).
struct Coding {
    none: u32,
}

// Whether `encode` reads the depths beside its texel (shared/encode_blur):
// the derivatives of `vsm_moments`.
const NEIGHBOURS: bool = true;

fn coding() -> Coding {
    return Coding(0u);
}

fn encode(z: f32, left: f32, right: f32, up: f32, down: f32, c: Coding) -> vec4<f32> {
    return vec4<f32>(vsm_moments(z, left, right, up, down), 0.0, 0.0);
}
