//! Reference of `kernels/csm.wgsl`.

use std::f64::consts::PI;

use super::Texels;

/// All `2·terms` basis channels `(sin c_k z, cos c_k z)` for k = 1..=terms, per texel
/// (the GPU splits them into maps of four channels).
pub fn csm(linear: &Texels, terms: u32) -> Texels {
    let data = linear
        .data
        .iter()
        .flat_map(|&z| {
            (1..=terms).flat_map(move |k| {
                let c = PI * f64::from(2 * k - 1);
                [(c * z).sin(), (c * z).cos()]
            })
        })
        .collect();
    Texels {
        channels: 2 * terms as usize,
        data,
        ..linear.clone()
    }
}
