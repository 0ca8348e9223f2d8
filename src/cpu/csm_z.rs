//! Reference of `kernels/csm_z.wgsl`.

use std::f64::consts::PI;

use super::Texels;

/// All `2·terms + 1` CSM-Z channels `[z, z·sin c₁z, z·cos c₁z, …, z·cos c_M z]` per texel
/// (the GPU splits them into maps of four channels, the last padded with zeros).
pub fn csm_z(linear: &Texels, terms: u32) -> Texels {
    let data = linear
        .data
        .iter()
        .flat_map(|&z| {
            std::iter::once(z).chain((1..=terms).flat_map(move |k| {
                let c = PI * f64::from(2 * k - 1);
                [z * (c * z).sin(), z * (c * z).cos()]
            }))
        })
        .collect();
    Texels {
        channels: 2 * terms as usize + 1,
        data,
        ..linear.clone()
    }
}
