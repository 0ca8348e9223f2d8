//! The area light's emitter and its samples: where the sample points lie on the emitter, and
//! the hard-shadow light each of them is rasterized from.
//!
//! The emitter is the model PCSS's penumbra estimate assumes (`kernels/shared/vis_pcss.wgsl`):
//! a square of side `size`, centred at the light's position, in the plane perpendicular to its
//! direction (spanned by the light view's x and y axes).
//!
//! - **Spot**: each sample point `p_k` is a point light. Its shadow map is the light's
//!   frustum moved parallel to itself to `p_k` (same axis, same near and far, so the linear
//!   depth of a point is the same for every sample), with the field of view widened just
//!   enough that every relevant receiver (view distance ≥ `z_min`) stays inside it.
//! - **Directional**: the emitter is far away; each sample is a *directional* light whose
//!   parallel rays run from `p_k` to the light's target, so the emitter subtends
//!   `size / D` radians seen from the target (`D` = position–target distance). Its map is an
//!   oblique (sheared) orthographic projection onto the light's own image plane, with the
//!   light's own near/far planes (linear depth unchanged), its half-width grown to cover the
//!   light's frustum between near and far. PCSS's directional estimate instead puts the
//!   emitter in the light's plane (penumbra `size·(Z_r − Z_b)/Z_b`): the two agree for
//!   blockers at distance `D` and differ by `D / Z_b` elsewhere; the truth keeps the
//!   directional light's parallel rays, so a size of 0 gives the directional hard shadow.
//! - **Point**: the emitter is a sphere of diameter `size` (uniform radiance, so each receiver
//!   sees a uniform disc). Its sample points lie in the ball with density `∝ 1/√(R² − ρ²)`
//!   ([`ball_point`]), the one density whose projection along *every* direction is uniform
//!   over the disc of radius R (its Abel transform is constant), so one set of samples, shared
//!   by all receivers, samples each receiver's disc uniformly. Seen from a receiver at distance
//!   `D` the disc is a cone, not a parallel projection: the sampled directions are uniform over
//!   the disc to within a relative `O(R / D)`. Each sample is a point light at `p_k` with the
//!   light's near and far planes and a hard-shadow atlas of `resolution`² faces.

use glam::{DVec3, Mat4, Vec4};

use crate::model::{Light, LightKind, Technique};
use crate::wgsl_mirrors::LightGpu;

/// Relative margin added to a widened frustum, so receivers at its edge stay a few texels in.
const MARGIN: f64 = 0.01;

/// `k` points on a stratified, jittered grid over the unit square `[−½, ½]²` (deterministic
/// for a `seed`). Rows hold `⌊k / rows⌋` or one more point, and each row's height is
/// proportional to its count, so every stratum has area `1 / k` (an unbiased estimator for
/// any `k`, square or not).
pub fn stratified_offsets(k: u32, seed: u64) -> Vec<[f64; 2]> {
    let k = k.max(1) as usize;
    let rows = (k as f64).sqrt().floor().max(1.0) as usize;
    let mut rng = SplitMix64(seed ^ 0x9e37_79b9_7f4a_7c15);
    let mut out = Vec::with_capacity(k);
    let mut y0 = 0.0;
    for r in 0..rows {
        let cols = k / rows + usize::from(r < k % rows);
        let h = cols as f64 / k as f64;
        for c in 0..cols {
            let x = (c as f64 + rng.unit()) / cols as f64;
            let y = y0 + h * rng.unit();
            out.push([x - 0.5, y - 0.5]);
        }
        y0 += h;
    }
    out
}

/// The single point at the emitter's centre (the light's own hard shadow).
pub fn centre_offset() -> Vec<[f64; 2]> {
    vec![[0.0, 0.0]]
}

/// SplitMix64 (Steele, Lea & Flood 2014): a small deterministic generator, so the truth does
/// not depend on a random-number crate's stream.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The light's emitter frame: unit `right`, `up` (the emitter plane) and `axis` (its direction),
/// from the light's own view matrix.
pub fn frame(light: &Light) -> (DVec3, DVec3, DVec3) {
    let v = light.view();
    let row = |i: usize| {
        let r: Vec4 = v.row(i);
        DVec3::new(r.x.into(), r.y.into(), r.z.into()).normalize()
    };
    (row(0), row(1), -row(2))
}

/// World position of the emitter point at `offset` (units of `size`; a point light's: the
/// point of its spherical emitter [`ball_point`] maps the offset to).
pub fn point(light: &Light, offset: [f64; 2]) -> DVec3 {
    let s = f64::from(light.size);
    if light.kind == LightKind::Point {
        return light.position.as_dvec3() + s * ball_point(offset);
    }
    let (right, up, _) = frame(light);
    light.position.as_dvec3() + s * (offset[0] * right + offset[1] * up)
}

/// The point of the unit-diameter ball that a point light's emitter sample at `offset`
/// (`[−½, ½]²`) stands for: its direction from the offset by Lambert's equal-area map
/// (`cos θ = 2·offset.y`, `φ = 2π(offset.x + ½)`: a stratified square gives stratified
/// directions), its radius `ρ = ½·F⁻¹(u)` for the radial distribution of the density
/// `1/√(¼ − ρ²)`, `F(x) = (2/π)(asin x − x√(1 − x²))`, with `u` hashed from the offset's bits
/// (deterministic, independent of the direction). The centre offset (0, 0) is the centre.
pub fn ball_point(offset: [f64; 2]) -> DVec3 {
    if offset == [0.0, 0.0] {
        return DVec3::ZERO;
    }
    let cos_t = (2.0 * offset[1]).clamp(-1.0, 1.0);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * (offset[0] + 0.5);
    let dir = DVec3::new(sin_t * phi.cos(), cos_t, sin_t * phi.sin());
    let mut rng = SplitMix64(offset[0].to_bits() ^ offset[1].to_bits().rotate_left(29));
    let u = rng.unit();
    let cdf = |x: f64| (x.asin() - x * (1.0 - x * x).sqrt()) / std::f64::consts::FRAC_PI_2;
    // F is increasing on [0, 1]: bisection to f64 precision.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < u {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (0.5 * (lo + hi)) * dir
}

/// One emitter sample as the GPU rasterizes and tests it.
#[derive(Clone, Debug)]
pub struct EmitterSample {
    /// The sample point on the emitter.
    pub point: DVec3,
    /// World → clip of each view of its shadow map (column-major, as the raster pass takes
    /// it) with the view's viewport: one, or a point light's six faces.
    pub views: Vec<([f32; 16], [u32; 4])>,
    /// The light the accumulation kernel tests with (`view` is the light's own, so linear
    /// depth is shared by all samples; `view_proj`, `position`, `direction`, `width_at_unit`
    /// and `map_size` are the sample's).
    pub light: LightGpu,
}

/// The hard-shadow lights of `light`'s emitter samples at `offsets`, with `resolution`² maps.
/// `z_min` (spot only) is the smallest view distance of a receiver that must stay inside every
/// sample's frustum. A sample at offset (0, 0) of a light whose emitter needs no widening
/// (all offsets zero, or size 0) has exactly the light's own matrices.
pub fn samples(
    light: &Light,
    offsets: &[[f64; 2]],
    resolution: u32,
    z_min: f64,
) -> Vec<EmitterSample> {
    let s = f64::from(light.size);
    let reach = offsets
        .iter()
        .map(|o| s * o[0].abs().max(o[1].abs()))
        .fold(0.0, f64::max);
    let mut base = light.clone();
    base.shadow_map = resolution;
    base.shadow.technique = Technique::Hard;
    let (near, far) = (f64::from(light.near), f64::from(light.far));
    match light.kind {
        LightKind::Spot { fov_degrees } => {
            if reach > 0.0 {
                let t = (0.5 * f64::from(fov_degrees).to_radians()).tan();
                let widened = (t + reach / z_min.max(near)) * (1.0 + MARGIN);
                let fov = (2.0 * widened.atan()).to_degrees().min(170.0);
                base.kind = LightKind::Spot {
                    fov_degrees: fov as f32,
                };
            }
            offsets
                .iter()
                .map(|&o| {
                    let p = point(light, o);
                    let shift = (p - light.position.as_dvec3()).as_vec3();
                    let mut l = base.clone();
                    l.position += shift;
                    l.target += shift;
                    EmitterSample {
                        point: p,
                        views: l.raster_views(),
                        light: LightGpu::new(&l),
                    }
                })
                .collect()
        }
        // Every sample sees all directions: nothing to widen.
        LightKind::Point => offsets
            .iter()
            .map(|&o| {
                let p = point(light, o);
                let shift = (p - light.position.as_dvec3()).as_vec3();
                let mut l = base.clone();
                l.position += shift;
                l.target += shift;
                EmitterSample {
                    point: p,
                    views: l.raster_views(),
                    light: LightGpu::new(&l),
                }
            })
            .collect(),
        LightKind::Directional { extent } => {
            let d = f64::from((light.target - light.position).length());
            if reach > 0.0 {
                let spread = (1.0 - near / d).abs().max((far / d - 1.0).abs());
                base.kind = LightKind::Directional {
                    extent: ((f64::from(extent) + reach * spread) * (1.0 + MARGIN)) as f32,
                };
            }
            let (proj, view) = (base.projection(), base.view());
            offsets
                .iter()
                .map(|&o| {
                    let p = point(light, o);
                    let (a, b) = (s * o[0], s * o[1]);
                    // View space (z_v < 0 in front): x' = x − (a/D)·z_v − a, likewise y, the
                    // oblique projection along the ray from p to the target onto the image plane.
                    let shear = Mat4::from_cols_array(&[
                        1.0,
                        0.0,
                        0.0,
                        0.0,
                        0.0,
                        1.0,
                        0.0,
                        0.0,
                        (-a / d) as f32,
                        (-b / d) as f32,
                        1.0,
                        0.0,
                        -a as f32,
                        -b as f32,
                        0.0,
                        1.0,
                    ]);
                    let view_proj = proj * shear * view;
                    let mut g = LightGpu::new(&base);
                    g.view_proj = view_proj.to_cols_array_2d();
                    g.position = p.as_vec3().to_array();
                    g.direction = (light.target.as_dvec3() - p)
                        .normalize()
                        .as_vec3()
                        .to_array();
                    EmitterSample {
                        point: p,
                        views: vec![(view_proj.to_cols_array(), [0, 0, resolution, resolution])],
                        light: g,
                    }
                })
                .collect()
        }
    }
}
