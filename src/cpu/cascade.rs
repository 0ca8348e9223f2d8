//! f64 reference of `kernels/shared/cascade.wgsl`: which cascade a receiver reads and how far
//! into the blend band toward the next it is.

use glam::DVec3;

use crate::wgsl_mirrors::LightGpu;

/// A receiver's cascade and blend (`CascadePick`), with its view distance and the band edges
/// a test needs to tell where f32 may pick otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadePick {
    /// The cascade read (the last beyond every far distance).
    pub index: usize,
    /// 0 outside the band, rising to 1 at the cascade's far end.
    pub blend: f64,
    /// The receiver's view distance.
    pub distance: f64,
    /// The picked cascade's far distance (the split the pick depends on).
    pub far: f64,
    /// The band's width (0 for the last cascade or with no band).
    pub band: f64,
}

/// Cascade `c`'s far view distance.
pub fn cascade_far_of(l: &LightGpu, c: usize) -> f64 {
    f64::from(l.cascade_far[c / 4][c % 4])
}

/// `cascade_pick` in f64.
pub fn pick(l: &LightGpu, p: DVec3) -> CascadePick {
    let eye = DVec3::from_array(l.cascade_eye.map(f64::from));
    let forward = DVec3::from_array(l.cascade_forward.map(f64::from));
    let d = (p - eye).dot(forward);
    let count = l.cascade_count as usize;
    let mut start = f64::from(l.cascade_near);
    for c in 0..count.saturating_sub(1) {
        let far = cascade_far_of(l, c);
        if d <= far {
            let band = f64::from(l.cascade_blend) * (far - start);
            let blend = if band > 0.0 {
                ((d - (far - band)) / band).clamp(0.0, 1.0)
            } else {
                0.0
            };
            return CascadePick {
                index: c,
                blend,
                distance: d,
                far,
                band,
            };
        }
        start = far;
    }
    let last = count.saturating_sub(1);
    CascadePick {
        index: last,
        blend: 0.0,
        distance: d,
        far: cascade_far_of(l, last),
        band: 0.0,
    }
}

/// The blended visibility of a receiver from its cascades' visibilities: `vis(c)` of the
/// picked cascade, mixed toward the next one's by the blend.
pub fn blend(pick: &CascadePick, mut vis: impl FnMut(usize) -> f64) -> f64 {
    let v = vis(pick.index);
    if pick.blend <= 0.0 {
        return v;
    }
    v + (vis(pick.index + 1) - v) * pick.blend
}
