//! Reference of `kernels/msm.wgsl`; the quantization of `kernels/shared/msm_quantize.wgsl` is
//! `crate::msm_quantize` (shared with the technique code), re-exported here.

use super::Texels;
pub use crate::msm_quantize::{dequantize, quantize};

/// `(z, z², z³, z⁴)` per texel, or its quantization.
pub fn msm(linear: &Texels, quantized: bool) -> Texels {
    let data = linear
        .data
        .iter()
        .flat_map(|&z| {
            let b = [z, z * z, z * z * z, z * z * z * z];
            if quantized { quantize(b) } else { b }
        })
        .collect();
    Texels {
        channels: 4,
        data,
        ..linear.clone()
    }
}
