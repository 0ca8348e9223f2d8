//! The model: plain data that every layer above reads — lights, cameras, techniques with their
//! parameters, filters, storages and their limits. No GPU objects and no file formats: the
//! scene parser (`scene`), the plug-in's config (`prefilter`) and the technique registry
//! (`technique`) all build or read these values.

pub mod cascades;
mod defaults;
mod params;
pub mod point;
mod sat_variant;

pub use defaults::{
    DEFAULT_MAX_SEARCH, DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, default_moment_bias,
    default_soft_moment_bias, exponent_limit,
};
pub use params::{
    Needs, ParamDefault, ParamKind, ParamSource, ParamSpec, ParamValue, ParamValues, check, keys,
};

use glam::{Mat4, Vec3};

pub use cascades::Cascades;
pub use sat_variant::SatVariant;

/// CSSM's blocker search (`blocker_search`): which table's means over the search square give
/// the blocker share and average depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CssmSearch {
    /// MSM's four moments `(z, z², z³, z⁴)`, quantized as `msm_soft`'s table holds them, in one
    /// table; MSM's three-point estimate (`msm_soft`'s search): one table read at the search
    /// width.
    Moments,
    /// The paper's CSM-Z basis `[z, z·sin c_k z, z·cos c_k z]` with CSM's basis: `E[f̄·z] /
    /// E[f̄]`, ⌈M/2⌉ + ⌈(2M + 1)/4⌉ tables read at the search width.
    CsmZ,
}

impl CssmSearch {
    /// The scene key's value.
    pub fn name(self) -> &'static str {
        match self {
            Self::Moments => "moments",
            Self::CsmZ => "csm_z",
        }
    }
}

/// CSSM's resolve (`resolve`): how the filtered CSM series becomes visibility.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CssmResolve {
    /// Away from contact, the series inverted for the share of blockers between the receiver
    /// plane and the blockers' depth, that depth estimated over the filter square from the
    /// moments' table (with the moment search; 4 more loads), else the search's z_avg.
    TwoDepth,
    /// The same with the search's z_avg as the blockers' depth.
    TwoDepthSearch,
    /// The paper's clamp and sharpening alone.
    Sharpen,
}

impl CssmResolve {
    /// The scene key's value.
    pub fn name(self) -> &'static str {
        match self {
            Self::TwoDepth => "two_depth",
            Self::TwoDepthSearch => "two_depth_search",
            Self::Sharpen => "sharpen",
        }
    }
}

/// A perspective camera.
#[derive(Clone, Debug)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Look-at point.
    pub target: Vec3,
    /// Up vector.
    pub up: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f32,
}

impl Camera {
    /// World → clip for an image of `aspect` = width / height.
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let proj = Mat4::perspective_rh(self.fov_y_degrees.to_radians(), aspect, 0.05, 500.0);
        proj * Mat4::look_at_rh(self.position, self.target, self.up)
    }
}

/// The projection a light's shadow map uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Orthographic, half-width `extent`.
    Directional {
        /// Half-width of the frustum in world units.
        extent: f32,
    },
    /// Perspective with a square frustum of full angle `fov_degrees`.
    Spot {
        /// Full cone angle, degrees.
        fov_degrees: f32,
    },
    /// Omnidirectional: six perspective faces in one atlas ([`point`]).
    Point,
}

/// Weights of an N×N PCF window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PcfKernel {
    /// Equal weights.
    Box,
    /// Bilinear tent weights `(r + 1 − |dx|)(r + 1 − |dy|)`.
    Tent,
    /// The hardware 2×2 comparison sampler (`textureSampleCompareLevel`).
    Hardware,
}

/// Storage precision of a prefiltered representation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// 32-bit float channels.
    F32,
    /// 16-bit float channels.
    F16,
    /// 16-bit normalized channels (MSM's optimized quantization; needs the device feature
    /// `TEXTURE_FORMAT_16BIT_NORM`).
    Unorm16,
}

/// Weights of the separable blur.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlurKernel {
    /// `exp(−i² / 2σ²)` for `|i| ≤ ceil(radius)`.
    Gaussian,
    /// 1 for `|i| ≤ floor(radius)`, the fraction `radius − floor(radius)` one texel further.
    Box,
}

/// How a prefiltered representation is filtered before shading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Not filtered (shading still interpolates bilinearly).
    None,
    /// Separable blur, one pass per axis, clamp-to-edge.
    Blur {
        /// Radius in texels.
        radius: f32,
        /// Gaussian sigma in texels.
        sigma: f32,
        /// Weights.
        kernel: BlurKernel,
    },
    /// A full mip chain (area-weighted 2×2 reduction, odd sizes included), sampled
    /// trilinearly at the level of `width`.
    Mips {
        /// Filter width in level-0 texels (level `log2(width)` is sampled).
        width: f32,
        /// 0: the width is fixed. ≥ 1: the pixel's footprint in the map widens it (its minor
        /// axis) and up to this many trilinear taps follow its major axis.
        max_anisotropy: u32,
    },
    /// A summed-area table (`src/sat.rs`), read as the mean over a `width`-texel square
    /// around the receiver with four lookups per channel and sub-texel edges.
    Sat {
        /// Box width in texels.
        width: f32,
        /// How the table stores its sums.
        variant: SatVariant,
    },
}

/// How a soft technique (`cssm`, `vssm`, `msm_soft`) stores its representation and reads it:
/// always through a summed-area table, at a width per receiver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Soft {
    /// Storage precision of the representation the table sums.
    pub storage: Storage,
    /// How the table stores its sums.
    pub sums: SatVariant,
    /// Cap on the blocker-search half-width and on the filter's half-width, in shadow-map UV
    /// (as PCSS's `max_search`); the fixed-point table is coded for squares of that size.
    pub max_search: f32,
}

/// How a prefiltered technique stores and filters its representation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prefilter {
    /// Storage precision.
    pub storage: Storage,
    /// Filter.
    pub filter: Filter,
}

/// A light's shadow technique and its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Technique {
    /// One comparison at the nearest texel.
    Hard,
    /// Percentage-closer filtering.
    Pcf {
        /// Window radius in texels (window is `2r + 1` wide).
        radius: u32,
        /// Weights.
        kernel: PcfKernel,
    },
    /// Percentage-closer soft shadows (Fernando 2005).
    Pcss {
        /// Blocker-search taps.
        blocker_samples: u32,
        /// Filter taps.
        filter_samples: u32,
        /// Cap on the blocker-search radius in shadow-map UV.
        max_search: f32,
    },
    /// Variance shadow maps (Donnelly & Lauritzen 2006): moments (z, z²), filtered.
    Vsm {
        /// Storage and filter of the moments.
        prefilter: Prefilter,
        /// Light-bleeding reduction `linstep(bleed, 1, p_max)`.
        bleed: f32,
        /// Minimum variance.
        min_variance: f32,
    },
    /// Exponential variance shadow maps (Lauritzen): depth warped to [−1, 1], then
    /// `exp(c⁺ z')` and its square (EVSM2), plus `−exp(−c⁻ z')` and its square (EVSM4).
    Evsm {
        /// Storage and filter of the moments.
        prefilter: Prefilter,
        /// Four moments (EVSM4) rather than two (EVSM2).
        four: bool,
        /// Positive exponent c⁺ (already clamped to the storage's safe limit).
        exp_pos: f32,
        /// Negative exponent c⁻ (EVSM4; clamped likewise).
        exp_neg: f32,
        /// Light-bleeding reduction.
        bleed: f32,
        /// Variance floor in depth units², scaled through the warp's derivative.
        min_variance: f32,
    },
    /// Exponential shadow maps (Annen et al. 2008): `c·z` stored and filtered in log space
    /// (log-sum-exp), so no exponent overflows; visibility `clamp(exp(L − c·d), 0, 1)`.
    Esm {
        /// Filter (storage is always f32: f16 `c·z` would cost percent-level visibility error).
        filter: Filter,
        /// Exponent c.
        exponent: f32,
    },
    /// Moment shadow maps (Peters & Klein 2015): (z, z², z³, z⁴), raw in f32 or through the
    /// optimized 16-bit quantization; Hamburger or Hausdorff reconstruction.
    Msm {
        /// Storage (f32 raw; f16 or unorm16 quantized) and filter.
        prefilter: Prefilter,
        /// Hausdorff (support on [0, 1]) rather than Hamburger reconstruction.
        hausdorff: bool,
        /// Moment bias α toward the moments of a fixed three-point distribution.
        moment_bias: f32,
        /// Light-bleeding reduction.
        bleed: f32,
    },
    /// Convolution shadow maps (Annen et al. 2007): Fourier basis sin(c_k z), cos(c_k z),
    /// k = 1..M, in ⌈M/2⌉ four-channel maps.
    Csm {
        /// Storage and filter of the basis images.
        prefilter: Prefilter,
        /// Number of terms M (1–16).
        terms: u32,
        /// Ringing attenuation α: term k weighted by exp(−α (k/M)²).
        attenuation: f32,
        /// Offset subtracted from the receiver depth.
        offset: f32,
        /// Scale of the response about ½ before the clamp to [0, 1].
        scale: f32,
    },
    /// Convolution soft shadow maps (Annen et al. 2008): the CSM basis and the CSM-Z basis
    /// (z, z·sin c_k z, z·cos c_k z) through summed-area tables; the average blocker depth over
    /// the light cone's search square, the PCSS penumbra width, the CSM lookup at that width,
    /// then the selective sharpening `v^p`, `p = 1 + A·exp(−B (d − z_avg))`, or (`two_depth`)
    /// away from contact the series inverted for the share of blockers at their depth.
    Cssm {
        /// Storage, table sums and search cap.
        soft: Soft,
        /// Number of terms M (1–16).
        terms: u32,
        /// Ringing attenuation α: term k weighted by exp(−α (k/M)²).
        attenuation: f32,
        /// Offset subtracted from the receiver depth.
        offset: f32,
        /// Scale of the response about ½ before the clamp to [0, 1].
        scale: f32,
        /// Sharpening strength A (0: none).
        sharpen: f32,
        /// Sharpening falloff B per linear depth unit of `d − z_avg`.
        sharpen_falloff: f32,
        /// Where the blocker search's means come from.
        search: CssmSearch,
        /// How the filtered series becomes visibility (`kernels/shared/vis_cssm.wgsl`).
        resolve: CssmResolve,
    },
    /// Variance soft shadow maps (Yang et al. 2010): from the VSM moments over the search
    /// square, the Chebyshev share p of lit texels and `z_avg = (μ − p·d)/(1 − p)`; then VSM
    /// at the penumbra width.
    Vssm {
        /// Storage, table sums and search cap.
        soft: Soft,
        /// Light-bleeding reduction of the final bound.
        bleed: f32,
        /// Minimum variance.
        min_variance: f32,
    },
    /// Shadow-map ray tracing (after UE5's and EEVEE's SMRT): rays from the receiver toward
    /// stratified points on the emitter, each marched through the linear depth map.
    Smrt {
        /// Rays per receiver (points on the emitter).
        rays: u32,
        /// Depth-map samples per ray.
        steps: u32,
        /// Cap on how fast the last surface seen in front of a ray may recede behind an
        /// occluder, relative to the ray's own depth rate (0: it does not recede).
        max_slope: f32,
    },
    /// Midpoint shadow maps (Woo 1992): the shading compares against the midpoint of the first
    /// and second rasterized depths (a second, peeled raster pass), with no bias; the far plane
    /// where no second surface exists.
    Midpoint {
        /// PCF window radius in texels over the comparisons (0: the nearest texel alone).
        radius: u32,
        /// PCF weights (box or tent).
        kernel: PcfKernel,
    },
    /// Second-depth shadow maps (Wang & Molnar 1994): the shading compares against the second
    /// rasterized depth, with no bias; the far plane where none exists.
    SecondDepth {
        /// PCF window radius in texels over the comparisons (0: the nearest texel alone).
        radius: u32,
        /// PCF weights (box or tent).
        kernel: PcfKernel,
    },
    /// Moment soft shadow maps (after Peters et al. 2016): the blocker depth from the four
    /// moments over the search square (the mean of the support points in front of the receiver
    /// of the three-point distribution through d that Hamburger MSM reconstructs), then MSM at
    /// the penumbra width.
    MsmSoft {
        /// Storage (f32 raw; f16 or unorm16 quantized), table sums and search cap.
        soft: Soft,
        /// Hausdorff rather than Hamburger reconstruction for the final visibility.
        hausdorff: bool,
        /// Moment bias α.
        moment_bias: f32,
        /// Light-bleeding reduction.
        bleed: f32,
    },
}

impl Technique {
    /// The filter of a prefiltered technique's representation.
    pub fn filter(&self) -> Option<Filter> {
        match *self {
            Technique::Vsm { prefilter, .. }
            | Technique::Evsm { prefilter, .. }
            | Technique::Msm { prefilter, .. }
            | Technique::Csm { prefilter, .. } => Some(prefilter.filter),
            Technique::Esm { filter, .. } => Some(filter),
            _ => None,
        }
    }

    /// The storage and table of a soft technique (`cssm`, `vssm`, `msm_soft`).
    pub fn soft(&self) -> Option<Soft> {
        match *self {
            Technique::Cssm { soft, .. }
            | Technique::Vssm { soft, .. }
            | Technique::MsmSoft { soft, .. } => Some(soft),
            _ => None,
        }
    }

    /// The storage and table of a soft technique, to change them (`None` for the others).
    pub fn soft_mut(&mut self) -> Option<&mut Soft> {
        match self {
            Technique::Cssm { soft, .. }
            | Technique::Vssm { soft, .. }
            | Technique::MsmSoft { soft, .. } => Some(soft),
            _ => None,
        }
    }

    /// The cap on the blocker search's radius (and the soft techniques' filter's), shadow-map
    /// UV, of PCSS and the soft techniques (`max_search`); `None` for the others.
    pub fn max_search(&self) -> Option<f32> {
        match *self {
            Technique::Pcss { max_search, .. } => Some(max_search),
            _ => self.soft().map(|s| s.max_search),
        }
    }

    /// This technique with its [`Technique::max_search`] set to `uv` (unchanged without one).
    pub fn with_max_search(mut self, uv: f32) -> Self {
        if let Technique::Pcss { max_search, .. } = &mut self {
            *max_search = uv;
        }
        if let Some(s) = self.soft_mut() {
            s.max_search = uv;
        }
        self
    }

    /// The variant of the summed-area table it reads, if it reads one (the `sat` filter or a
    /// soft technique's table).
    pub fn sat_variant(&self) -> Option<SatVariant> {
        match (self.filter(), self.soft()) {
            (Some(Filter::Sat { variant, .. }), _) => Some(variant),
            (_, Some(Soft { sums, .. })) => Some(sums),
            _ => None,
        }
    }

    /// Whether its table is f32 and its filter reads it with bilinear-filtered fetches: a soft
    /// technique with `sat_sums = "float"` (`sat_filter_float`; the `sat` filter's f32 tables
    /// keep their sixteen loads, whose window sums stay exact to the table at small widths).
    pub fn sat_filtered(&self) -> bool {
        self.soft().is_some_and(|s| s.sums == SatVariant::Float)
    }

    /// The storage precision of a prefiltered or soft technique's representation (ESM's is
    /// always f32); `None` for techniques that shade from the depth.
    pub fn storage(&self) -> Option<Storage> {
        match *self {
            Technique::Esm { .. } => Some(Storage::F32),
            _ => self
                .prefilter()
                .map(|p| p.storage)
                .or(self.soft().map(|s| s.storage)),
        }
    }

    /// The storage and filter of a prefiltered technique (VSM, EVSM, MSM, CSM; ESM has a filter
    /// only).
    pub fn prefilter(&self) -> Option<Prefilter> {
        match *self {
            Technique::Vsm { prefilter, .. }
            | Technique::Evsm { prefilter, .. }
            | Technique::Msm { prefilter, .. }
            | Technique::Csm { prefilter, .. } => Some(prefilter),
            _ => None,
        }
    }

    /// The name used in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            Technique::Hard => "hard",
            Technique::Pcf { .. } => "pcf",
            Technique::Pcss { .. } => "pcss",
            Technique::Vsm { .. } => "vsm",
            Technique::Evsm { four: false, .. } => "evsm2",
            Technique::Evsm { four: true, .. } => "evsm4",
            Technique::Esm { .. } => "esm",
            Technique::Msm { .. } => "msm",
            Technique::Csm { .. } => "csm",
            Technique::Cssm { .. } => "cssm",
            Technique::Vssm { .. } => "vssm",
            Technique::MsmSoft { .. } => "msm_soft",
            Technique::Smrt { .. } => "smrt",
            Technique::Midpoint { .. } => "midpoint",
            Technique::SecondDepth { .. } => "second_depth",
        }
    }
}

/// How a light's shadow map is made and read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shadow {
    /// Technique.
    pub technique: Technique,
    /// Constant bias at the comparison, in linear depth units.
    pub bias: f32,
    /// Slope-scaled bias at rasterization (wgpu `DepthBiasState::slope_scale`).
    pub slope_bias: f32,
    /// Normal offset in shadow-map texels, scaled by `1 − N·L`.
    pub normal_bias: f32,
    /// Receiver-plane depth bias: the cap on each tap's depth correction along the receiver's
    /// plane, linear depth units; 0 off (`bias_mode = "constant"`).
    pub receiver_plane: f32,
    /// Cascades of a directional light ([`Cascades::SINGLE`]: one map).
    pub cascades: Cascades,
}

/// A light.
#[derive(Clone, Debug)]
pub struct Light {
    /// Projection.
    pub kind: LightKind,
    /// Position.
    pub position: Vec3,
    /// Aim point.
    pub target: Vec3,
    /// Near plane.
    pub near: f32,
    /// Far plane.
    pub far: f32,
    /// Area-light width, world units (0 = point/sharp).
    pub size: f32,
    /// Colour × intensity.
    pub radiance: Vec3,
    /// Shadow-map resolution.
    pub shadow_map: u32,
    /// Shadow settings.
    pub shadow: Shadow,
}

impl Light {
    /// Unit vector from the light toward its target.
    pub fn direction(&self) -> Vec3 {
        (self.target - self.position).normalize()
    }

    /// World → light view space.
    pub fn view(&self) -> Mat4 {
        let dir = self.direction();
        let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
        Mat4::look_at_rh(self.position, self.target, up)
    }

    /// Light view → clip (depth in [0, 1]); a point light's: each face's, over its widened
    /// frustum ([`point::PointLayout::projection`]; a 90° face where its technique has no
    /// layout, which scene validation and the plug-in refuse first).
    pub fn projection(&self) -> Mat4 {
        match self.kind {
            LightKind::Directional { extent } => {
                Mat4::orthographic_rh(-extent, extent, -extent, extent, self.near, self.far)
            }
            LightKind::Spot { fov_degrees } => {
                Mat4::perspective_rh(fov_degrees.to_radians(), 1.0, self.near, self.far)
            }
            LightKind::Point => match self.point_layout() {
                Ok(layout) => layout.projection(self.near, self.far),
                Err(_) => {
                    Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, self.near, self.far)
                }
            },
        }
    }

    /// A point light's face layout for its technique ([`point::reach`]); an error for other
    /// lights or a technique that cannot be bounded to a face.
    pub fn point_layout(&self) -> Result<point::PointLayout, String> {
        if self.kind != LightKind::Point {
            return Err("not a point light".into());
        }
        let reach = point::reach(&self.shadow.technique, self.shadow_map)?;
        point::PointLayout::new(self.shadow_map, reach)
    }

    /// The shadow map's width and height in texels: `shadow_map`² (a point light's atlas of
    /// six faces: `3·shadow_map × 2·shadow_map`).
    pub fn map_dims(&self) -> (u32, u32) {
        match self.kind {
            LightKind::Point => (
                point::COLUMNS * self.shadow_map,
                point::ROWS * self.shadow_map,
            ),
            _ => (self.shadow_map, self.shadow_map),
        }
    }

    /// World → clip of each rasterized view of the light with its viewport in the map
    /// (x, y, width, height in texels): the whole map for one-map lights, the six faces'
    /// tiles for a point light.
    pub fn raster_views(&self) -> Vec<([f32; 16], [u32; 4])> {
        match (self.kind, self.point_layout()) {
            (LightKind::Point, Ok(layout)) => {
                let proj = layout.projection(self.near, self.far);
                (0..point::FACES)
                    .map(|f| {
                        let (x, y) = layout.origin(f);
                        let vp = proj * point::PointLayout::view(self.position, f);
                        (vp.to_cols_array(), [x, y, layout.face, layout.face])
                    })
                    .collect()
            }
            _ => {
                let (w, h) = self.map_dims();
                let vp = self.projection() * self.view();
                vec![(vp.to_cols_array(), [0, 0, w, h])]
            }
        }
    }

    /// World width covered by the shadow map at view distance 1 (spot; a point light's face)
    /// or at any distance (directional): the map spans `width_at_unit * distance` (spot)
    /// world units.
    pub fn width_at_unit(&self) -> f32 {
        match self.kind {
            LightKind::Directional { extent } => 2.0 * extent,
            LightKind::Spot { fov_degrees } => 2.0 * (0.5 * fov_degrees.to_radians()).tan(),
            LightKind::Point => 2.0 * self.point_layout().map_or(1.0, |l| l.tan_half),
        }
    }

    /// One-line description for plans and reports.
    pub fn label(&self) -> String {
        let kind = match self.kind {
            LightKind::Directional { .. } => "directional",
            LightKind::Spot { .. } => "spot",
            LightKind::Point => "point",
        };
        let map = match self.kind {
            LightKind::Point => match self.point_layout() {
                Ok(l) => format!(
                    "six {}² faces, guard band {} texels (90° cores of {}²)",
                    l.face,
                    l.guard,
                    l.face - 2 * l.guard
                ),
                Err(_) => format!("six {}² faces", self.shadow_map),
            },
            _ => format!("{}² map", self.shadow_map),
        };
        format!("{kind}, {} shadows, {map}", self.shadow.technique.name())
    }
}

/// Number of mip levels of a full chain for a `width`×`height` map (down to 1×1).
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// A pinhole camera's unnormalized view rays as `glam`'s `look_at_rh` and `perspective_rh`
/// (the G-buffer's projection) make them: forward `f`, right `s = f × up`, up `u = s × f`,
/// `t = tan(fov_y / 2)`; pixel (x, y) of a `w × h` image sees along
/// `ray00 + (x + ½)·ray_dx + (y + ½)·ray_dy` with `ray00 = f − t·aspect·s + t·u`,
/// `ray_dx = 2t·aspect/w · s`, `ray_dy = −2t/h · u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRays {
    /// Ray through pixel corner (0, 0).
    pub ray00: glam::Vec3,
    /// Per pixel in x.
    pub ray_dx: glam::Vec3,
    /// Per pixel in y.
    pub ray_dy: glam::Vec3,
}

impl CameraRays {
    /// The rays of `camera` for a `width × height` image.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let f = (camera.target - camera.position).normalize();
        let s = f.cross(camera.up).normalize();
        let u = s.cross(f);
        let t = (0.5 * camera.fov_y_degrees.to_radians()).tan();
        let aspect = width as f32 / height as f32;
        Self {
            ray00: f - t * aspect * s + t * u,
            ray_dx: (2.0 * t * aspect / width as f32) * s,
            ray_dy: (-2.0 * t / height as f32) * u,
        }
    }
}
