// Parameters of the exponential encodings `evsm` and `esm` (import-only module).

// Keep in sync with `ExpParams` in src/technique.rs.
struct Params {
    exp_pos: f32,            // evsm: c⁺; esm: c
    exp_neg: f32,            // evsm: c⁻
    _pad0: f32,
    _pad1: f32,
}
