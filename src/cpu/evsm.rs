//! Reference of `kernels/evsm.wgsl`.

use super::Texels;

/// `(pos, pos², neg, neg²)` with `pos = exp(c⁺ (2z − 1))`, `neg = −exp(−c⁻ (2z − 1))`.
pub fn evsm(linear: &Texels, exp_pos: f64, exp_neg: f64) -> Texels {
    let data = linear
        .data
        .iter()
        .flat_map(|&z| {
            let w = 2.0 * z - 1.0;
            let (pos, neg) = ((exp_pos * w).exp(), -(-exp_neg * w).exp());
            [pos, pos * pos, neg, neg * neg]
        })
        .collect();
    Texels {
        channels: 4,
        data,
        ..linear.clone()
    }
}
