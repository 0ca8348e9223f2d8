//! Reference of `kernels/vsm_blur.wgsl`: the moments of [`super::vsm::vsm`], then both passes
//! of [`super::blur::blur`] (clamp-to-edge), composed from the two independent references.

use super::Texels;
use crate::model::BlurKernel;

/// The blurred moments `(z, z² + ¼(∂x² + ∂y²))` of a linear depth map.
pub fn vsm_blur(linear: &Texels, radius: f64, sigma: f64, kernel: BlurKernel) -> Texels {
    super::blur::blur(&super::vsm::vsm(linear), radius, sigma, kernel)
}
