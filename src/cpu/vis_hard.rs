//! Reference of `kernels/shared/vis_hard.wgsl`.

use super::Map;
use super::light::LightSample;
use crate::gpu_data::LightGpu;

/// Lit (1) when the receiver is no deeper than the nearest texel plus the bias.
pub fn vis_hard(map: &Map, l: &LightGpu, s: &LightSample) -> f64 {
    let (x, y) = map.texel_of(s.uv);
    if s.depth <= map.load(x, y) + f64::from(l.bias) {
        1.0
    } else {
        0.0
    }
}
