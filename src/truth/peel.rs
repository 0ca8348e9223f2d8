//! The f64 reference of a light's first and second rasterized depths (`shadow_depth` and the
//! peel pass `shadow_peel`): per texel, a ray through its centre in the light's projection,
//! every triangle hit along it in depth-buffer units, the nearest inside [0, 1], then the
//! nearest deeper than it by more than [`PEEL_EPSILON`] (1.0, the cleared far plane, where
//! none). No slope-scaled bias: compare against a light with `slope_bias = 0`.

use glam::{DMat4, DVec3, DVec4};

use super::bvh::Bvh;
use crate::wgsl_mirrors::PEEL_EPSILON;
use crate::{model::Light, scene::Scene};

/// Side of the jitter around a texel's centre, texels: where a ray this far off the centre
/// hits other triangles, the texel sits on an edge, where rasterization rules decide.
const JITTER: f64 = 1.0 / 64.0;

/// One texel of the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeeledTexel {
    /// First depth (depth-buffer units; 1.0 where nothing is hit).
    pub z1: f64,
    /// Second depth (1.0 where nothing lies behind the first).
    pub z2: f64,
    /// Whether rays `JITTER` texels off the centre, either way on each axis, meet the same
    /// two triangles: the texel is no edge case of coverage.
    pub robust: bool,
    /// The largest change of either depth per texel seen across the jitter (a plane's depth
    /// slope, for the tolerance of snapped vertex positions).
    pub slope: f64,
}

/// First and second depths with their triangles of the ray at NDC `(x, y)`.
fn depths(bvh: &Bvh, inverse: &DMat4, view_proj: &DMat4, x: f64, y: f64) -> [(f64, usize); 2] {
    let at = |z: f64| {
        let v: DVec4 = *inverse * DVec4::new(x, y, z, 1.0);
        v.truncate() / v.w
    };
    let o = at(0.0);
    let d = (at(1.0) - o).normalize();
    let ndc = |p: DVec3| {
        let c = *view_proj * p.extend(1.0);
        c.z / c.w
    };
    let none = (1.0, usize::MAX);
    let mut found = [none, none];
    let (mut t, mut skip) = (0.0, None);
    while let Some(h) = bvh.nearest(o, d, t, f64::INFINITY, skip) {
        let z = ndc(o + h.t * d);
        if z > 1.0 {
            break;
        }
        (t, skip) = (h.t, Some(h.triangle));
        if z < 0.0 {
            continue;
        }
        if found[0].1 == usize::MAX {
            found[0] = (z, h.triangle);
        } else if z > found[0].0 + f64::from(PEEL_EPSILON) {
            found[1] = (z, h.triangle);
            break;
        }
    }
    found
}

/// The reference depths of light `light` of `scene`, row-major over its map (row 0 at the top,
/// as the rasterizer writes it).
pub fn peeled_depths(scene: &Scene, light: &Light) -> Vec<PeeledTexel> {
    let bvh = Bvh::new(scene);
    let view_proj = light.projection().as_dmat4() * light.view().as_dmat4();
    let inverse = view_proj.inverse();
    let n = light.shadow_map as usize;
    let texel = 2.0 / n as f64;
    let rows: Vec<usize> = (0..n).collect();
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    let chunks: Vec<Vec<PeeledTexel>> = std::thread::scope(|s| {
        let handles: Vec<_> = rows
            .chunks(n.div_ceil(threads))
            .map(|rows| {
                let (bvh, inverse, view_proj) = (&bvh, &inverse, &view_proj);
                s.spawn(move || {
                    let mut out = Vec::with_capacity(rows.len() * n);
                    for &row in rows {
                        for col in 0..n {
                            let x = -1.0 + (col as f64 + 0.5) * texel;
                            let y = 1.0 - (row as f64 + 0.5) * texel;
                            let centre = depths(bvh, inverse, view_proj, x, y);
                            let j = JITTER * texel;
                            let mut robust = true;
                            let mut slope: f64 = 0.0;
                            for (dx, dy) in [(j, 0.0), (-j, 0.0), (0.0, j), (0.0, -j)] {
                                let off = depths(bvh, inverse, view_proj, x + dx, y + dy);
                                robust &= off[0].1 == centre[0].1 && off[1].1 == centre[1].1;
                                for k in 0..2 {
                                    slope = slope.max((off[k].0 - centre[k].0).abs() / JITTER);
                                }
                            }
                            out.push(PeeledTexel {
                                z1: centre[0].0,
                                z2: centre[1].0,
                                robust,
                                slope,
                            });
                        }
                    }
                    out
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    chunks.concat()
}
