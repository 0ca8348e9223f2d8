// One pass of a separable blur (Gaussian, or box with fractional edge weights) over every
// channel of any float representation: the weighted sum of each texel's 2r + 1 neighbours
// along the pass's axis, PER outputs an invocation (shared/blur_pass; a row's interleaved
// WG_SIZE apart so that neighbouring invocations touch neighbouring texels), each summed as the
// centre and then the symmetric pairs, w₀·v₀ + Σ wᵢ·(v₋ᵢ + vᵢ), straight from the texture.
// (Reading each texel once into PER running sums instead was 2.2 times faster on llvmpipe at
// r = 4, but its different f32 rounding of the sums moved MSM moments onto points where the
// per-pixel MSM tolerances of tests/scenes.rs and the stability suite's case 3 fail; this
// order keeps the sums the earlier kernel computed.)
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

// The invocation's outputs along the pass's axis (`vertical`: a constant at each call).
fn blur_outputs(b: BlurLine, vertical: bool) {
    for (var k = 0; k < b.count; k++) {
        let o = out_offset(b, k);
        var s = weight(0, b.r) * tap(b, o, vertical);
        for (var i = 1; i <= b.r; i++) {
            s += weight(i, b.r) * (tap(b, o - i, vertical) + tap(b, o + i, vertical));
        }
        put(b, o, s, vertical);
    }
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let b = blur_line(wg.xy, li, true, COL_PER);
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
