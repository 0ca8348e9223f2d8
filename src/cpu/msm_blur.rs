//! Reference of `kernels/msm_blur.wgsl`: the moments of [`super::msm::msm`] (quantized for
//! 16-bit storage), then both passes of [`super::blur::blur`] (clamp-to-edge), composed from
//! the two independent references.

use super::Texels;
use crate::model::BlurKernel;

/// The blurred moments `(z, z², z³, z⁴)` of a linear depth map, or with `quantized` their
/// optimized 16-bit quantization, blurred.
pub fn msm_blur(
    linear: &Texels,
    quantized: bool,
    radius: f64,
    sigma: f64,
    kernel: BlurKernel,
) -> Texels {
    super::blur::blur(&super::msm::msm(linear, quantized), radius, sigma, kernel)
}
