//! The model: plain data that every layer above reads — lights, cameras, techniques with their
//! parameters, filters, storages and their limits. No GPU objects and no file formats: the
//! scene parser (`scene`), the plug-in's config (`prefilter`) and the technique registry
//! (`technique`) all build or read these values.

pub mod cascades;
mod defaults;
mod params;
pub mod point;
mod sat_variant;
mod technique;

pub use defaults::{
    DEFAULT_MAX_SEARCH, DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, default_moment_bias,
    default_soft_moment_bias, exponent_limit,
};
pub use params::{
    Needs, ParamDefault, ParamKind, ParamSource, ParamSpec, ParamValue, ParamValues, check_params,
    keys,
};

use glam::{Mat4, Vec3};

pub use cascades::Cascades;
pub use sat_variant::SatVariant;
pub use technique::{Soft, StorageFilter, Technique};

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
