//! Reference of `kernels/shared/vis_pcf.wgsl`.

use super::Map;
use super::light::{LightSample, linear_to_ndc, receiver_offset, tap_offset};
use crate::wgsl_mirrors::LightGpu;

/// Weighted mean of comparisons over the (2r + 1)² window (box or tent weights), each against
/// the receiver plane's depth at its texel's centre when the receiver-plane bias is on.
pub fn vis_pcf(map: &Map, l: &LightGpu, s: &LightSample) -> f64 {
    let (cx, cy) = map.texel_of(s.uv);
    let r = i64::from(l.radius);
    let (mut lit, mut total) = (0.0, 0.0);
    for dy in -r..=r {
        for dx in -r..=r {
            let w = if l.kernel == 1 {
                ((r + 1 - dx.abs()) * (r + 1 - dy.abs())) as f64
            } else {
                1.0
            };
            let (x, y) = (cx + dx, cy + dy);
            let d = s.depth + receiver_offset(l, s, tap_offset(l, s, x, y));
            if d <= map.load(x, y) + f64::from(l.bias) {
                lit += w;
            }
            total += w;
        }
    }
    lit / total
}

/// The 2×2 comparison sampler: bilinear weights of four comparisons against the raw depth
/// buffer `raw` (clamp-to-edge addressing, texel centres at half-integers).
pub fn vis_pcf_hardware(raw: &Map, l: &LightGpu, s: &LightSample) -> f64 {
    let reference = linear_to_ndc(l, (s.depth - f64::from(l.bias)).clamp(0.0, 1.0));
    let (w, h) = (raw.size as f64, raw.height() as f64);
    let (fx, fy) = (s.uv[0] * w - 0.5, s.uv[1] * h - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (ax, ay) = (fx - x0, fy - y0);
    let pass = |x: f64, y: f64| {
        if reference <= raw.load(x as i64, y as i64) {
            1.0
        } else {
            0.0
        }
    };
    (1.0 - ay) * ((1.0 - ax) * pass(x0, y0) + ax * pass(x0 + 1.0, y0))
        + ay * ((1.0 - ax) * pass(x0, y0 + 1.0) + ax * pass(x0 + 1.0, y0 + 1.0))
}
