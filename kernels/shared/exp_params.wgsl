// Parameters of the exponential encodings `evsm` and `esm` (import-only module).

// #import shared/linear_depth

// Keep in sync with `ExpParams` in src/wgsl_mirrors.rs.
struct Params {
    depth: DepthParams,      // the depth buffer's linearization (shared/linear_depth)
    exp_pos: f32,            // evsm: c⁺; esm: c
    exp_neg: f32,            // evsm: c⁻
    linear: u32,             // esm: 1 stores exp(c (z − 1)) (for a summed-area table), 0 c·z
    _pad0: u32,
}
