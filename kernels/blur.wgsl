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
// a halo of r each side; a column workgroup WG_SIZE columns of PER + 2r texels each.
// #traffic src: select(WG_SIZE * PER + 2 * min(params.radius, MAX_RADIUS), WG_SIZE * (PER + 2 * min(params.radius, MAX_RADIUS)), params.axis == 1) per group
// #traffic dst: all

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let b = blur_line(wg.xy, li, true);
    if !blur_active(b) {
        return;
    }
    for (var k = 0; k < i32(PER); k++) {
        let o = out_offset(b, k);
        var s = weight(0, b.r) * tap(b, o);
        for (var i = 1; i <= b.r; i++) {
            s += weight(i, b.r) * (tap(b, o - i) + tap(b, o + i));
        }
        put(b, o, s);
    }
}
