// The log-sum-exp mip chain's redesign after AMD FidelityFX SPD (shared/mips_spd): `mips_log` as
// the `redesign` kernel layout compiles it, the same dispatches and the same texels bit for bit.
// #import shared/mips_spd
// Traffic (the cost model, src/graph/cost): each dispatch reads the level it reduces once and
// writes each level it stores once (dst0 in the first dispatch only).
// #traffic src: all
// #traffic dst0: all
// #traffic dst1: all
// #traffic dst2: all
// #traffic dst3: all
// #traffic dst4: all
// #traffic dst5: all
// #traffic dst6: all

const LOG_MODE: bool = true;

@compute @workgroup_size(WG, WG)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    mip_dispatch(wg.xy, li, LOG_MODE);
}
