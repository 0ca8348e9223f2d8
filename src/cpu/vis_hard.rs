//! Reference of `kernels/shared/vis_hard.wgsl`.

use super::Map;
use super::light::{LightSample, receiver_offset, tap_offset};
use crate::wgsl_mirrors::LightGpu;

/// Lit (1) when the receiver (moved along its plane to the texel's centre when the
/// receiver-plane bias is on) is no deeper than the nearest texel plus the bias.
pub fn vis_hard(map: &Map, l: &LightGpu, s: &LightSample) -> f64 {
    let (x, y) = map.texel_of(s.uv);
    let d = s.depth + receiver_offset(l, s, tap_offset(l, s, x, y));
    if d <= map.load(x, y) + f64::from(l.bias) {
        1.0
    } else {
        0.0
    }
}
