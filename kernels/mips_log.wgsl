// A mip chain, up to six levels per dispatch; every texel the log of the mean of exp of the
// texels it covers (logarithmic representations: ESM's c·z; shared/mip_chain).
// `filter::mip_chain` gives the dispatches of a mip-chain node.
// #import shared/mip_chain
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
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    mip_dispatch(wg.xy, lid.xy, LOG_MODE);
}
