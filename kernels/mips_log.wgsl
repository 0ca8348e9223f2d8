// A mip chain, up to six levels per dispatch; every texel the log of the mean of exp (logarithmic representations: ESM's c·z) of the texels
// it covers (shared/mip_chain). The executor records the dispatches of a `Dispatch::MipChain`
// node.
// #import shared/mip_chain

const LOG_MODE: bool = true;

@compute @workgroup_size(WG, WG)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    mip_dispatch(wg.xy, lid.xy, LOG_MODE);
}
