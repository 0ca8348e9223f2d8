// One pass of a separable blur (Gaussian, or box with fractional edge weights) over every
// channel of any float representation: the weighted sum of each texel's 2r + 1 neighbours
// along the pass's axis, each summed as the centre and then the symmetric pairs,
// w₀·v₀ + Σ wᵢ·(v₋ᵢ + vᵢ), straight from the texture (shared/blur_pass), in runs of RUN = 8
// consecutive outputs: the run's taps are read once each (RUN + 2r loads for RUN outputs, where
// one output at a time reads 2r + 1: 2 against 9 an output at r = 4, 9 against 65 at r = 32),
// two sliding windows of RUN taps holding v_{k−i} and v_{k+i} of the run's outputs k as i
// grows. Every output's sum keeps the order above, so the results are those of one output at a
// time, bit for bit (a running sum in tap order, 2.2× faster on llvmpipe, had moved MSM moments
// onto points where the per-pixel MSM tolerances of tests/scenes.rs and the stability suite's
// case 3 fail).
// Rows: an invocation writes PER / RUN runs (one), neighbouring invocations' runs side by side;
// columns: COL_PER / COL_RUN runs down its column.
// #import shared/blur_pass
// Traffic (the cost model, src/graph/cost): a row workgroup loads its WG_SIZE · PER texels and
// a halo of r each side; a column workgroup WG_SIZE columns of COL_PER + 2r texels each.
// #traffic src: select(WG_SIZE * PER + 2 * min(params.radius, MAX_RADIUS), WG_SIZE * (COL_PER + 2 * min(params.radius, MAX_RADIUS)), params.axis == 1) per group
// #traffic dst: all

// Rows down a column one invocation writes: the column halo of 2r rows is read by a workgroup
// once per COL_PER outputs (at r = 3, 38/32 of the map instead of 14/8 with PER rows), while
// 64 · 32 texels a workgroup keep 512² maps at 8192 invocations. Keep in sync with
// `BLUR_COL_PER` in src/filter.rs.
const COL_PER: u32 = 32u;

// The channels of the texture bound to `dst`: the executor sets this for the bound format
// (src/exec/pipelines.rs, `Change::Channels`); 2 for the declared rg32float.
const DST_CHANNELS: u32 = 2u; // #channels dst

// Outputs an invocation sums together (the sliding windows' length): 8 along rows, and along
// columns of one or two channels; 2 along columns of four. On llvmpipe, against runs of 2
// everywhere (benches/RESULTS.md, 2026-11-27), the two-channel passes ran 1.2–1.4× faster at
// r = 4 and 1.6–1.8× at r = 32, and the four-channel rows 1.3–1.6×, but the four-channel
// columns 1.7× slower at 1024² and 2048² with runs of 4 or 8 (as fast at 2000²: a cache effect
// of power-of-two rows as much as the 24 live vec4); on a GPU the taps a run reads fall 4.5× at
// r = 4 (2 an output against 9), for 24 live values an invocation.
const RUN: i32 = 8;
const COL_RUN: i32 = select(RUN, 2, DST_CHANNELS > 2u);

// The run of outputs `o` .. `o + 7` along the line (`vertical`: a constant at each call). The
// windows are named values, not arrays: llvmpipe kept arrays shifted in a loop in memory (runs
// of 8 that way were no faster than runs of 2 by name).
fn blur_run(b: BlurLine, o: i32, vertical: bool) {
    let c0 = tap(b, o, vertical);
    let c1 = tap(b, o + 1, vertical);
    let c2 = tap(b, o + 2, vertical);
    let c3 = tap(b, o + 3, vertical);
    let c4 = tap(b, o + 4, vertical);
    let c5 = tap(b, o + 5, vertical);
    let c6 = tap(b, o + 6, vertical);
    let c7 = tap(b, o + 7, vertical);
    let w0 = weight(0, b.r);
    var s0 = w0 * c0;
    var s1 = w0 * c1;
    var s2 = w0 * c2;
    var s3 = w0 * c3;
    var s4 = w0 * c4;
    var s5 = w0 * c5;
    var s6 = w0 * c6;
    var s7 = w0 * c7;
    // At offset i: l_k = v_{k−i}, r_k = v_{k+i} of output k (from i = 1).
    var l0 = tap(b, o - 1, vertical);
    var l1 = c0;
    var l2 = c1;
    var l3 = c2;
    var l4 = c3;
    var l5 = c4;
    var l6 = c5;
    var l7 = c6;
    var r0 = c1;
    var r1 = c2;
    var r2 = c3;
    var r3 = c4;
    var r4 = c5;
    var r5 = c6;
    var r6 = c7;
    var r7 = tap(b, o + RUN, vertical);
    // Offsets 1 .. r − 1 slide the windows after their sums; offset r, which needs no next
    // taps, is summed after the loop. With the slide behind `if i < r` inside the loop,
    // llvmpipe ran it as masked selects of all 16 windows at every offset: peeled, 1.2–1.3×
    // faster at r = 32 (benches/RESULTS.md, 2026-11-27); a GPU branches on the
    // uniform test either way.
    for (var i = 1; i < b.r; i++) {
        let w = weight(i, b.r);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        s2 += w * (l2 + r2);
        s3 += w * (l3 + r3);
        s4 += w * (l4 + r4);
        s5 += w * (l5 + r5);
        s6 += w * (l6 + r6);
        s7 += w * (l7 + r7);
        l7 = l6;
        l6 = l5;
        l5 = l4;
        l4 = l3;
        l3 = l2;
        l2 = l1;
        l1 = l0;
        l0 = tap(b, o - i - 1, vertical);
        r0 = r1;
        r1 = r2;
        r2 = r3;
        r3 = r4;
        r4 = r5;
        r5 = r6;
        r6 = r7;
        r7 = tap(b, o + RUN + i, vertical);
    }
    if b.r > 0 {
        let w = weight(b.r, b.r);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        s2 += w * (l2 + r2);
        s3 += w * (l3 + r3);
        s4 += w * (l4 + r4);
        s5 += w * (l5 + r5);
        s6 += w * (l6 + r6);
        s7 += w * (l7 + r7);
    }
    put(b, o, s0, vertical);
    put(b, o + 1, s1, vertical);
    put(b, o + 2, s2, vertical);
    put(b, o + 3, s3, vertical);
    put(b, o + 4, s4, vertical);
    put(b, o + 5, s5, vertical);
    put(b, o + 6, s6, vertical);
    put(b, o + 7, s7, vertical);
}

// The run of outputs `o`, `o + 1` (COL_RUN = 2), as `blur_run`.
fn blur_run2(b: BlurLine, o: i32, vertical: bool) {
    let c0 = tap(b, o, vertical);
    let c1 = tap(b, o + 1, vertical);
    let w0 = weight(0, b.r);
    var s0 = w0 * c0;
    var s1 = w0 * c1;
    var l0 = tap(b, o - 1, vertical);
    var l1 = c0;
    var r0 = c1;
    var r1 = tap(b, o + 2, vertical);
    for (var i = 1; i < b.r; i++) {
        let w = weight(i, b.r);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        l1 = l0;
        l0 = tap(b, o - i - 1, vertical);
        r0 = r1;
        r1 = tap(b, o + 2 + i, vertical);
    }
    if b.r > 0 {
        let w = weight(b.r, b.r);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
    }
    put(b, o, s0, vertical);
    put(b, o + 1, s1, vertical);
}

// The invocation's runs along the pass's axis (`vertical`: a constant at each call): `count`
// outputs in runs of `run` (RUN, or COL_RUN down a column) `step` apart from `first`
// (shared/blur_pass).
fn blur_outputs(b: BlurLine, vertical: bool) {
    let run = select(RUN, COL_RUN, vertical);
    for (var k = 0; k < b.count; k += run) {
        let o = (k / run) * b.step;
        if b.first + o < b.along {
            // A constant condition at each call: each pass compiles one run.
            if run == 2 {
                blur_run2(b, o, vertical);
            } else {
                blur_run(b, o, vertical);
            }
        }
    }
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let b = blur_line(wg.xy, li, u32(select(RUN, COL_RUN, params.axis == 1u)), COL_PER);
    if !blur_active(b) {
        return;
    }
    // The axis tested once, not at every tap (shared/blur_pass's `tap`).
    if params.axis == 1u {
        blur_outputs(b, true);
    } else {
        blur_outputs(b, false);
    }
}
