//! Reference of `kernels/shared/vis_smrt.wgsl`: shadow-map ray tracing toward fixed points on
//! the emitter, in f64. The emitter points are built as the truth's grid is
//! (`truth::emitter::stratified_offsets`), row by row, with every point at its stratum's centre.

use super::Map;
use super::light::LightSample;
use crate::wgsl_mirrors::LightGpu;

/// The `n` emitter points (units of the light's size, in `[−½, ½]²`), in the shader's order.
pub fn emitter_points(n: u32) -> Vec<[f64; 2]> {
    let n = n.max(1) as usize;
    let rows = (1..=n).take_while(|r| r * r <= n).last().unwrap_or(1);
    let mut out = Vec::with_capacity(n);
    let mut y0 = 0.0;
    for r in 0..rows {
        let cols = n / rows + usize::from(r < n % rows);
        let h = cols as f64 / n as f64;
        for c in 0..cols {
            out.push([(c as f64 + 0.5) / cols as f64 - 0.5, y0 + 0.5 * h - 0.5]);
        }
        y0 += h;
    }
    out
}

/// The ray parameters of the `n` samples, from the light end: `((n − i − ½) / n)²`.
pub fn sample_times(n: u32) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let f = (f64::from(n - i) - 0.5) / f64::from(n);
            f * f
        })
        .collect()
}

/// Where the ray from `s` toward emitter point `o` is at parameter `t` (0 the receiver, 1 the
/// near plane): its map UV and its linear depth.
pub fn ray_point(l: &LightGpu, s: &LightSample, o: [f64; 2], t: f64) -> ([f64; 2], f64) {
    let near = f64::from(l.near);
    let (size, w) = (f64::from(l.size), f64::from(l.width_at_unit));
    // Lateral world offset of the ray from the receiver's line of sight at view distance z.
    let z_r = s.view_z;
    let z = z_r - t * (z_r - near);
    let (dx, dy) = if l.kind == 1 {
        // Toward the point (size·o, 0) in view space: u = x / (w z) moves by size·o/w·(1/z − 1/z_r).
        let k = 1.0 / z - 1.0 / z_r;
        (size * o[0] * k / w, size * o[1] * k / w)
    } else {
        // Parallel to the line from the emitter point to the target, D away.
        let k = (z_r - z) / f64::from(l.target_distance);
        (size * o[0] * k / w, size * o[1] * k / w)
    };
    let depth = (z - near) / f64::from(l.far - l.near);
    ([s.uv[0] + dx, s.uv[1] - dy], depth)
}

/// Whether the ray toward emitter point `o` is occluded.
pub fn occluded(map: &Map, l: &LightGpu, s: &LightSample, o: [f64; 2]) -> bool {
    let bias = f64::from(l.bias);
    let cap = f64::from(l.smrt_max_slope) * s.depth;
    // The last sample in front of the stored surface: (t, stored depth), and the surface's
    // slope between it and the one before, per unit of travel toward the receiver.
    let mut last: Option<(f64, f64)> = None;
    let mut slope = 0.0;
    for t in sample_times(l.smrt_steps) {
        let (uv, ray) = ray_point(l, s, o, t);
        if !uv.iter().all(|c| (0.0..=1.0).contains(c)) {
            continue;
        }
        let (x, y) = map.texel_of(uv);
        let z = map.load(x, y);
        match last {
            _ if ray <= z + bias => {
                if let Some((t0, z0)) = last {
                    slope = (z - z0) / (t0 - t);
                }
                last = Some((t, z));
            }
            None => return true,
            Some((t0, z0)) => {
                if ray > z0 + slope.min(cap) * (t0 - t) + bias {
                    return true;
                }
            }
        }
    }
    false
}

/// The share of the rays toward the emitter points that no sample occludes.
pub fn vis_smrt(map: &Map, l: &LightGpu, s: &LightSample) -> f64 {
    if s.view_z <= f64::from(l.near) {
        return 1.0;
    }
    let points = emitter_points(l.smrt_rays);
    let lit = points.iter().filter(|&&o| !occluded(map, l, s, o)).count();
    lit as f64 / points.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The points lie in the square, one per stratum of area 1/n: seven make rows of 4 and 3.
    #[test]
    fn emitter_points_fill_the_square_by_strata() {
        let p = emitter_points(7);
        assert_eq!(p.len(), 7);
        assert!((p[0][0] + 0.375).abs() < 1e-12 && (p[0][1] + 0.5 - 2.0 / 7.0).abs() < 1e-12);
        assert!((p[4][0] + 1.0 / 3.0).abs() < 1e-12);
        for n in 1..40 {
            let p = emitter_points(n);
            let mean = p.iter().fold([0.0, 0.0], |a, q| [a[0] + q[0], a[1] + q[1]]);
            assert!(
                mean[0].abs() < 1e-9 && mean[1].abs() < 1e-9,
                "{n}: {mean:?}"
            );
            assert!(p.iter().all(|q| q.iter().all(|c| c.abs() < 0.5)));
        }
    }
}
