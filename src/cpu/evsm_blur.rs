//! Reference of `kernels/evsm_blur.wgsl`: the moments of [`super::evsm::evsm`], then both
//! passes of [`super::blur::blur`] (clamp-to-edge), composed from the two independent
//! references.

use super::Texels;
use crate::model::BlurKernel;

/// The blurred moments `(pos, pos², neg, neg²)` of a linear depth map, exponents `c⁺`, `c⁻`.
pub fn evsm_blur(
    linear: &Texels,
    [exp_pos, exp_neg]: [f64; 2],
    radius: f64,
    sigma: f64,
    kernel: BlurKernel,
) -> Texels {
    let moments = super::evsm::evsm(linear, exp_pos, exp_neg);
    super::blur::blur(&moments, radius, sigma, kernel)
}
