// One pass of ESM's log-space blur (shared/blur_log_pass) for texels that lie within SPAN =
// 80 of each other: c·z with c ≤ 80. No per-output fallback (see `blur_log_wide`).
// #import shared/blur_log_pass
// Traffic (the cost model, src/graph/cost): a row workgroup loads its WG_SIZE · PER texels and
// a halo of r each side; a column workgroup WG_SIZE columns of PER + 2r texels each.
// #traffic src: select(WG_SIZE * PER + 2 * min(params.radius, MAX_RADIUS), WG_SIZE * (PER + 2 * min(params.radius, MAX_RADIUS)), params.axis == 1) per group
// #traffic dst: all

const WIDE: bool = false;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    blur_log(wg.xy, li);
}
