//! Reference of `kernels/esm.wgsl`.

use super::Texels;

/// The log moment `c·z`.
pub fn esm(linear: &Texels, exponent: f64) -> Texels {
    Texels {
        data: linear.data.iter().map(|z| exponent * z).collect(),
        ..linear.clone()
    }
}

/// The moment scaled by `exp(−c)`, `exp(c (z − 1))`: what `esm` stores for a summed-area table
/// (`params.linear`).
pub fn esm_linear(linear: &Texels, exponent: f64) -> Texels {
    Texels {
        data: linear
            .data
            .iter()
            .map(|z| (exponent * (z - 1.0)).exp())
            .collect(),
        ..linear.clone()
    }
}
