// One pass of a separable blur (Gaussian, or box with fractional edge weights) over every
// channel of any float representation: the weighted sum of each texel's 2r + 1 neighbours
// along the pass's axis, each summed as the centre and then the symmetric pairs,
// w₀·v₀ + Σ wᵢ·(v₋ᵢ + vᵢ), straight from the texture (shared/blur_pass), in runs of RUN = 2
// consecutive outputs: the run's taps are read once each (RUN + 2r loads for RUN outputs, where
// one output at a time reads 2r + 1: 5 against 9 an output at r = 4), two sliding windows of
// RUN taps holding v_{k−i} and v_{k+i} of the run's outputs k as i grows. Every output's sum
// keeps the order above, so the results are those of one output at a time, bit for bit (a
// running sum in tap order, 2.2× faster on llvmpipe, had moved MSM moments onto points where
// the per-pixel MSM tolerances of tests/scenes.rs and the stability suite's case 3 fail).
// Rows: an invocation writes PER / RUN runs, WG_SIZE · RUN apart, neighbouring invocations'
// runs side by side; columns: COL_PER / RUN runs down its column.
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

// Outputs an invocation sums together (the sliding windows' length). 2, not 4: on llvmpipe
// runs of 4 made the two-channel passes 1.2–2.0× faster but four-channel ones 5–13% slower
// (sixteen vec4 live across the tap loop: spilled), where runs of 2 made both faster; on a GPU
// the 48 floats of a run of 4's windows and sums would cut occupancy.
const RUN: i32 = 2;

// The run of outputs `o`, `o + 1` along the line (`vertical`: a constant at each call).
fn blur_run(b: BlurLine, o: i32, vertical: bool) {
    let c0 = tap(b, o, vertical);
    let c1 = tap(b, o + 1, vertical);
    let w0 = weight(0, b.r);
    var s0 = w0 * c0;
    var s1 = w0 * c1;
    // At offset i: l_k = v_{k−i}, r_k = v_{k+i} of output k (from i = 1).
    var l0 = tap(b, o - 1, vertical);
    var l1 = c0;
    var r0 = c1;
    var r1 = tap(b, o + RUN, vertical);
    for (var i = 1; i <= b.r; i++) {
        let w = weight(i, b.r);
        s0 += w * (l0 + r0);
        s1 += w * (l1 + r1);
        if i < b.r {
            l1 = l0;
            l0 = tap(b, o - i - 1, vertical);
            r0 = r1;
            r1 = tap(b, o + RUN + i, vertical);
        }
    }
    put(b, o, s0, vertical);
    put(b, o + 1, s1, vertical);
}

// The invocation's runs along the pass's axis (`vertical`: a constant at each call): `count`
// outputs in runs `step` apart from `first` (shared/blur_pass).
fn blur_outputs(b: BlurLine, vertical: bool) {
    for (var k = 0; k < b.count; k += RUN) {
        let o = (k / RUN) * b.step;
        if b.first + o < b.along {
            blur_run(b, o, vertical);
        }
    }
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let b = blur_line(wg.xy, li, u32(RUN), COL_PER);
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
