//! Reference of `kernels/shared/vis_pcss.wgsl`.

use super::light::{LightSample, linear_to_z, map_width, receiver_offset, tap_offset};
use super::{Map, vogel_disc};
use crate::wgsl_mirrors::LightGpu;

/// Blocker-search radius in face UV (`pcss_search_radius`; map UV · `face_uv`).
pub fn search_radius(l: &LightGpu, s: &LightSample) -> f64 {
    let world = 0.5 * f64::from(l.size) * (s.view_z - f64::from(l.near)) / s.view_z;
    (world / map_width(l, f64::from(l.near))).min(f64::from(l.max_search))
}

/// Blocker search, penumbra estimate, PCF over the penumbra; each tap against the receiver
/// plane's depth at its texel's centre when the receiver-plane bias is on.
pub fn vis_pcss(map: &Map, l: &LightGpu, s: &LightSample) -> f64 {
    let bias = f64::from(l.bias);
    let search = search_radius(l, s);
    let (mut sum, mut count) = (0.0, 0u32);
    for i in 0..l.blocker_samples {
        let o = vogel_disc(i, l.blocker_samples);
        let (x, y) = map.texel_of(offset(l, s, search, o));
        let z = map.load(x, y);
        if z + bias < s.depth + receiver_offset(l, s, tap_offset(l, s, x, y)) {
            sum += z;
            count += 1;
        }
    }
    if count == 0 {
        return 1.0;
    }
    let z_blocker = linear_to_z(l, sum / f64::from(count));
    let penumbra = f64::from(l.size) * (s.view_z - z_blocker) / z_blocker;
    let mut radius = (0.5 * penumbra / map_width(l, s.view_z))
        .max(0.5 / (f64::from(l.map_size[0]) * f64::from(l.face_uv[0])));
    if l.capped_filter != 0 {
        // A point light's or a cascade's filter stays within the search cap, hence within the
        // guard band of its face or cascade.
        radius = radius.min(f64::from(l.max_search));
    }
    let mut lit = 0.0;
    for i in 0..l.filter_samples {
        let o = vogel_disc(i, l.filter_samples);
        let (x, y) = map.texel_of(offset(l, s, radius, o));
        let d = s.depth + receiver_offset(l, s, tap_offset(l, s, x, y));
        if d <= map.load(x, y) + bias {
            lit += 1.0;
        }
    }
    lit / f64::from(l.filter_samples)
}

/// The map UV of a tap `radius` face-UV units from the receiver along unit-disc point `o`.
fn offset(l: &LightGpu, s: &LightSample, radius: f64, o: [f64; 2]) -> [f64; 2] {
    [
        s.uv[0] + radius * f64::from(l.face_uv[0]) * o[0],
        s.uv[1] + radius * f64::from(l.face_uv[1]) * o[1],
    ]
}
