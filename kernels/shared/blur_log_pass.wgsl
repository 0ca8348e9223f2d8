// One pass of a separable blur of a one-channel logarithmic representation (import-only module
// of `blur_log` and `blur_log_wide`; ESM's c·z; only the first channel is read and written, so
// no exp is spent on the others): per texel log Σ wᵢ exp(vᵢ) over its 2r + 1 neighbours along
// the axis (shared/blur_pass: PER outputs an invocation). Each texel is exponentiated once,
// relative to the first texel the invocation reads (of its PER + 2r): `v₀ + log Σ w·exp(v −
// v₀)`. Within a span of SPAN every exp lies in [exp(−SPAN), exp(SPAN)], normal f32 both ways,
// and a sum of 2r + 1 of them stays finite; SPIR-V's exp error, (3 + 2|x|) ULP, is bounded by
// the span as it was relative to the maximum.
// `blur_log` serves texels that lie within SPAN of each other (ESM's c·z with c ≤ SPAN, z ∈
// [0, 1]: the planner picks it, `filter::BlurMode::log_sum_exp`). `blur_log_wide` (`const
// WIDE`) serves any spread: the same loop tracks the texels' span, and where they span more
// than SPAN the sums (whose arguments are clamped to ±SPAN, so finite) are dropped and the
// invocation takes each output's own window maximum instead, at one exp per tap: every exp ≤ 1,
// so nothing that matters underflows at any c (ESM at c > SPAN across a depth edge). Two
// kernels, not a run-time test: llvmpipe (Mesa 22.3) runs an `if`'s straight-line body (here
// eight logs and eight stores around the loops) under a lane mask even where no lane takes it,
// and the per-output path cost `blur_log` 1.8× there though no input reached it
// (benches/RESULTS.md, 2026-11-27); on a GPU a branch no lane takes is skipped, so the split
// costs nothing.
// The invocation reads its PER + 2r texels once into PER running sums, kept as named values (an
// array indexed in a loop stays in memory on llvmpipe, three times slower).
// The importing kernel declares `const WIDE: bool` and calls `blur_log` from its `main`:
// #completed-by-importer
// #import shared/blur_pass

// Keep in sync with `LOG_BLUR_SPAN` in src/filter.rs.
const SPAN: f32 = 80.0;

// Rows down a column one invocation writes: PER, the named running sums s0 … s7 below. Keep in
// sync with `BLUR_PER_INVOCATION` in src/filter.rs.
const COL_PER: u32 = PER;

// The log-sum-exp of output k's window around its own maximum.
fn log_sum_at(b: BlurLine, k: i32, vertical: bool) -> f32 {
    var m = -3.0e38;
    for (var i = -b.r; i <= b.r; i++) {
        m = max(m, tap(b, k + i, vertical).x);
    }
    var sum = 0.0;
    for (var i = -b.r; i <= b.r; i++) {
        sum += weight(i, b.r) * exp(tap(b, k + i, vertical).x - m);
    }
    return m + log(sum);
}

fn put_x(b: BlurLine, k: i32, v: f32, vertical: bool) {
    put(b, k, vec4<f32>(v, 0.0, 0.0, 0.0), vertical);
}

// The pass for workgroup `wg`, invocation `li` (the importing kernel's `main`).
fn blur_log(wg: vec2<u32>, li: u32) {
    let b = blur_line(wg, li, PER, COL_PER);
    if !blur_active(b) {
        return;
    }
    // The axis tested once, not at every tap (shared/blur_pass's `tap`).
    if params.axis == 1u {
        blur_log_outputs(b, true);
    } else {
        blur_log_outputs(b, false);
    }
}

// The invocation's PER outputs along the pass's axis (`vertical`: a constant at each call).
fn blur_log_outputs(b: BlurLine, vertical: bool) {
    // One read of the PER + 2r texels: each exponentiated relative to the first, the span
    // tracked alongside (WIDE); where it exceeds SPAN the sums are dropped for the per-output
    // path.
    let first = tap(b, -b.r, vertical).x;
    var hi = first;
    var lo = first;
    var s0 = 0.0;
    var s1 = 0.0;
    var s2 = 0.0;
    var s3 = 0.0;
    var s4 = 0.0;
    var s5 = 0.0;
    var s6 = 0.0;
    var s7 = 0.0;
    let t0 = -b.r;
    var w0 = weight(t0, b.r);
    var w1 = weight(t0 - 1, b.r);
    var w2 = weight(t0 - 2, b.r);
    var w3 = weight(t0 - 3, b.r);
    var w4 = weight(t0 - 4, b.r);
    var w5 = weight(t0 - 5, b.r);
    var w6 = weight(t0 - 6, b.r);
    var w7 = weight(t0 - 7, b.r);
    for (var t = t0; t < i32(PER) + b.r; t++) {
        let x = tap(b, t, vertical).x;
        hi = max(hi, x);
        lo = min(lo, x);
        let v = exp(clamp(x - first, -SPAN, SPAN));
        s0 += w0 * v;
        s1 += w1 * v;
        s2 += w2 * v;
        s3 += w3 * v;
        s4 += w4 * v;
        s5 += w5 * v;
        s6 += w6 * v;
        s7 += w7 * v;
        w7 = w6;
        w6 = w5;
        w5 = w4;
        w4 = w3;
        w3 = w2;
        w2 = w1;
        w1 = w0;
        w0 = weight(t + 1, b.r);
    }
    // A constant condition for `blur_log`: no code for the per-output path there.
    if WIDE && hi - lo > SPAN {
        put_x(b, 0, log_sum_at(b, 0, vertical), vertical);
        put_x(b, 1, log_sum_at(b, 1, vertical), vertical);
        put_x(b, 2, log_sum_at(b, 2, vertical), vertical);
        put_x(b, 3, log_sum_at(b, 3, vertical), vertical);
        put_x(b, 4, log_sum_at(b, 4, vertical), vertical);
        put_x(b, 5, log_sum_at(b, 5, vertical), vertical);
        put_x(b, 6, log_sum_at(b, 6, vertical), vertical);
        put_x(b, 7, log_sum_at(b, 7, vertical), vertical);
        return;
    }
    put_x(b, 0, first + log(s0), vertical);
    put_x(b, 1, first + log(s1), vertical);
    put_x(b, 2, first + log(s2), vertical);
    put_x(b, 3, first + log(s3), vertical);
    put_x(b, 4, first + log(s4), vertical);
    put_x(b, 5, first + log(s5), vertical);
    put_x(b, 6, first + log(s6), vertical);
    put_x(b, 7, first + log(s7), vertical);
}
