//! Reference of `kernels/esm.wgsl`.

use super::Texels;

/// The log moment `c·z`.
pub fn esm(linear: &Texels, exponent: f64) -> Texels {
    Texels {
        data: linear.data.iter().map(|z| exponent * z).collect(),
        ..linear.clone()
    }
}
