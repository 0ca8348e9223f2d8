//! What the stage computes (a technique with its parameters, validated with the scene file's
//! rules) and what changes per frame (the light's matrices and depth range).

use glam::{Mat4, Vec3, Vec4};

use super::StageError;
use crate::filter::MAX_BLUR_RADIUS;
use crate::scene::{
    BlurKernel, DEFAULT_MAX_SEARCH, DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, Filter, Light,
    LightKind, Prefilter, Shadow, Soft, Storage, Technique, exponent_limit,
};
use crate::technique::LightGpu;

/// Largest map side a scene accepts before the device is asked (as `shadow_map` in scenes).
const MAX_SIDE: u32 = 1 << 16;

/// The stage's fixed settings: a technique with its parameters, the map size it is made for,
/// and the shading constants the visibility functions read. Build one with a constructor
/// ([`PrefilterConfig::vsm`], …) and adjust it with the `with_*` methods; defaults are the
/// scene file's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrefilterConfig {
    /// Technique with its parameters (storage format, filter and its parameters, exponents).
    pub technique: Technique,
    /// Shadow-map side in texels. Pipelines are made for it; a depth texture of another size
    /// is planned anew (and the pooled textures reallocated).
    pub size: u32,
    /// Constant bias at the comparison, in linear depth units.
    pub bias: f32,
    /// Normal offset in shadow-map texels, scaled by `1 − N·L`.
    pub normal_bias: f32,
    /// Area-light width in world units (PCSS penumbrae; 0 for a point light).
    pub light_size: f32,
    /// A `with_*` call that did not apply to the technique (reported by validation).
    not_applicable: Option<&'static str>,
    /// Whether [`PrefilterConfig::with_moment_bias`] set MSM's bias (else it follows the
    /// storage's default, as in a scene file).
    moment_bias_set: bool,
}

/// The blur a scene gets without filter keys: radius 2, sigma 1, Gaussian.
const DEFAULT_BLUR: Filter = Filter::Blur {
    radius: 2.0,
    sigma: 1.0,
    kernel: BlurKernel::Gaussian,
};

const DEFAULT_PREFILTER: Prefilter = Prefilter {
    storage: Storage::F32,
    filter: DEFAULT_BLUR,
};

/// A soft technique's table without `format`, `sat_sums` or `max_search` keys.
const DEFAULT_SOFT: Soft = Soft {
    storage: Storage::F32,
    sums: crate::sat::SatVariant::Fixed,
    max_search: DEFAULT_MAX_SEARCH,
};

impl PrefilterConfig {
    /// `technique` on `size`² maps with the scene file's default bias, normal bias and size.
    pub fn new(technique: Technique, size: u32) -> Self {
        Self {
            technique,
            size,
            bias: 0.002,
            normal_bias: 1.0,
            light_size: 0.0,
            not_applicable: None,
            moment_bias_set: false,
        }
    }

    /// VSM with a scene's defaults: f32 moments, Gaussian blur of radius 2, bleed reduction
    /// 0.2, variance floor 1e-5.
    pub fn vsm(size: u32) -> Self {
        Self::new(
            Technique::Vsm {
                prefilter: DEFAULT_PREFILTER,
                bleed: 0.2,
                min_variance: 1e-5,
            },
            size,
        )
    }

    /// EVSM with two moments and a scene's defaults (c⁺ = 40, floor 1e-4, no bleed reduction).
    pub fn evsm2(size: u32) -> Self {
        Self::evsm(size, false)
    }

    /// EVSM with four moments and a scene's defaults (c⁺ = 40, c⁻ = 5).
    pub fn evsm4(size: u32) -> Self {
        Self::evsm(size, true)
    }

    fn evsm(size: u32, four: bool) -> Self {
        Self::new(
            Technique::Evsm {
                prefilter: DEFAULT_PREFILTER,
                four,
                exp_pos: 40.0,
                exp_neg: 5.0,
                bleed: 0.0,
                min_variance: 1e-4,
            },
            size,
        )
    }

    /// ESM with a scene's defaults: c = 80, Gaussian blur of radius 2 in log space.
    pub fn esm(size: u32) -> Self {
        Self::new(
            Technique::Esm {
                filter: DEFAULT_BLUR,
                exponent: 80.0,
            },
            size,
        )
    }

    /// MSM, 32-bit raw moments, Hamburger reconstruction, the scene default blur.
    pub fn msm(size: u32) -> Self {
        Self::new(
            Technique::Msm {
                prefilter: crate::scene::Prefilter {
                    storage: Storage::F32,
                    filter: DEFAULT_BLUR,
                },
                hausdorff: false,
                moment_bias: crate::scene::default_moment_bias(Storage::F32),
                bleed: 0.0,
            },
            size,
        )
    }

    /// CSM with `terms` Fourier terms and the scene defaults (attenuation 1, offset ½/M,
    /// scale 2), the scene default blur.
    pub fn csm(size: u32, terms: u32) -> Self {
        Self::new(
            Technique::Csm {
                prefilter: crate::scene::Prefilter {
                    storage: Storage::F32,
                    filter: DEFAULT_BLUR,
                },
                terms,
                attenuation: 1.0,
                offset: 0.5 / terms.max(1) as f32,
                scale: 2.0,
            },
            size,
        )
    }

    /// Soft VSM (`vssm`) with a scene's defaults, for an area light `light_size` wide: f32
    /// moments in a fixed-point table, search cap 0.1, bleed reduction 0.2, floor 1e-5.
    pub fn vssm(size: u32, light_size: f32) -> Self {
        let mut c = Self::new(
            Technique::Vssm {
                soft: DEFAULT_SOFT,
                bleed: 0.2,
                min_variance: 1e-5,
            },
            size,
        );
        c.light_size = light_size;
        c
    }

    /// Soft MSM (`msm_soft`) with a scene's defaults: f32 moments (summed quantized, as every
    /// MSM table) in a fixed-point table, Hamburger reconstruction, search cap 0.1, the soft
    /// moment bias of f32.
    pub fn msm_soft(size: u32, light_size: f32) -> Self {
        let mut c = Self::new(
            Technique::MsmSoft {
                soft: DEFAULT_SOFT,
                hausdorff: false,
                moment_bias: crate::scene::default_soft_moment_bias(Storage::F32),
                bleed: 0.0,
            },
            size,
        );
        c.light_size = light_size;
        c
    }

    /// Convolution soft shadow maps (`cssm`) with `terms` terms and a scene's defaults
    /// (attenuation 1, offset ½/M, scale 2, the default sharpening, search cap 0.1).
    pub fn cssm(size: u32, terms: u32, light_size: f32) -> Self {
        let mut c = Self::new(
            Technique::Cssm {
                soft: DEFAULT_SOFT,
                terms,
                attenuation: 1.0,
                offset: 0.5 / terms.max(1) as f32,
                scale: 2.0,
                sharpen: DEFAULT_SHARPEN,
                sharpen_falloff: DEFAULT_SHARPEN_FALLOFF,
            },
            size,
        );
        c.light_size = light_size;
        c
    }

    /// The technique, map size and shading constants of a scene's light.
    pub fn from_light(light: &Light) -> Self {
        Self {
            technique: light.shadow.technique,
            size: light.shadow_map,
            bias: light.shadow.bias,
            normal_bias: light.shadow.normal_bias,
            light_size: light.size,
            not_applicable: None,
            moment_bias_set: true,
        }
    }

    /// The same with moments stored at `storage` precision (VSM, EVSM, MSM, CSM and the soft
    /// techniques; ESM is always f32; `Unorm16` only for MSM and soft MSM). MSM's moment bias
    /// becomes the storage's default unless [`PrefilterConfig::with_moment_bias`] set it.
    pub fn with_storage(mut self, storage: Storage) -> Self {
        let keep = self.moment_bias_set;
        match &mut self.technique {
            Technique::Msm {
                prefilter,
                moment_bias,
                ..
            } => {
                prefilter.storage = storage;
                if !keep {
                    *moment_bias = crate::scene::default_moment_bias(storage);
                }
            }
            Technique::MsmSoft {
                soft, moment_bias, ..
            } => {
                soft.storage = storage;
                if !keep {
                    *moment_bias = crate::scene::default_soft_moment_bias(storage);
                }
            }
            Technique::Vssm { soft, .. } | Technique::Cssm { soft, .. }
                if storage != Storage::Unorm16 =>
            {
                soft.storage = storage;
            }
            Technique::Vsm { prefilter, .. }
            | Technique::Evsm { prefilter, .. }
            | Technique::Csm { prefilter, .. }
                if storage != Storage::Unorm16 =>
            {
                prefilter.storage = storage;
            }
            _ => self.not_applicable = Some("format"),
        }
        self
    }

    /// The same with `filter` over the representation (VSM, EVSM, ESM, MSM, CSM; the soft
    /// techniques always read a summed-area table: see [`PrefilterConfig::with_soft`]).
    pub fn with_filter(mut self, filter: Filter) -> Self {
        match &mut self.technique {
            Technique::Vsm { prefilter, .. }
            | Technique::Evsm { prefilter, .. }
            | Technique::Msm { prefilter, .. }
            | Technique::Csm { prefilter, .. } => {
                prefilter.filter = filter;
            }
            Technique::Esm { filter: f, .. } => *f = filter,
            _ => self.not_applicable = Some("filter"),
        }
        self
    }

    /// The same with a soft technique's table sums and search cap (`cssm`, `vssm`,
    /// `msm_soft`; the storage is set by [`PrefilterConfig::with_storage`]).
    pub fn with_soft(mut self, sums: crate::sat::SatVariant, max_search: f32) -> Self {
        match &mut self.technique {
            Technique::Cssm { soft, .. }
            | Technique::Vssm { soft, .. }
            | Technique::MsmSoft { soft, .. } => {
                soft.sums = sums;
                soft.max_search = max_search;
            }
            _ => self.not_applicable = Some("sat_sums"),
        }
        self
    }

    /// The same with a Gaussian blur of `radius` texels and a scene's default sigma
    /// (`max(radius / 2, 0.5)`).
    pub fn with_blur(self, radius: f32) -> Self {
        self.with_filter(Filter::Blur {
            radius,
            sigma: (0.5 * radius).max(0.5),
            kernel: BlurKernel::Gaussian,
        })
    }

    /// The same on `size`² maps.
    pub fn with_size(mut self, size: u32) -> Self {
        self.size = size;
        self
    }

    /// The same with MSM's moment bias α (`msm`, `msm_soft`; the scene key `moment_bias`,
    /// checked by validation against the same range [0, 0.5]). Without it, α is the default
    /// of the storage (`scene::default_moment_bias`, `default_soft_moment_bias`).
    pub fn with_moment_bias(mut self, alpha: f32) -> Self {
        match &mut self.technique {
            Technique::Msm { moment_bias, .. } | Technique::MsmSoft { moment_bias, .. } => {
                *moment_bias = alpha;
                self.moment_bias_set = true;
            }
            _ => self.not_applicable = Some("moment_bias"),
        }
        self
    }

    /// The same with constant bias `bias` (linear depth units).
    pub fn with_bias(mut self, bias: f32) -> Self {
        self.bias = bias;
        self
    }

    /// Checks every value against the scene file's rules and returns the configuration the
    /// stage runs, with EVSM exponents clamped to the storage's safe limit, and a warning per
    /// value changed.
    pub fn validated(&self) -> Result<(Self, Vec<String>), StageError> {
        if let Some(field) = self.not_applicable {
            return Err(config_err(
                field,
                format!("does not apply to technique \"{}\"", self.technique.name()),
            ));
        }
        let side = u64::from(self.size);
        if !(1..=u64::from(MAX_SIDE)).contains(&side) {
            return Err(config_err(
                "size",
                format!("{side} is outside [1, {MAX_SIDE}]"),
            ));
        }
        range("bias", self.bias, -1.0, 1.0)?;
        range("normal_bias", self.normal_bias, 0.0, 100.0)?;
        range("size (light)", self.light_size, 0.0, 1e6)?;
        let mut out = *self;
        // The bias is settled now: a later `with_storage` keeps it, as it keeps a light's.
        out.moment_bias_set = true;
        let mut warnings = Vec::new();
        out.technique = technique(self.technique, self.light_size, &mut warnings)?;
        Ok((out, warnings))
    }
}

fn config_err(field: &str, message: String) -> StageError {
    StageError::Config {
        field: field.to_string(),
        message,
    }
}

/// A finite value inside `[lo, hi]`, worded as the scene parser words it. The scene checks
/// its f64 text before rounding to f32; here the bounds are rounded instead, so that the f32 a
/// scene bound turns into (0.99 → 0.9900000095) passes as it does in a scene.
fn range(field: &str, v: f32, lo: f64, hi: f64) -> Result<(), StageError> {
    if !v.is_finite() || v < lo as f32 || v > hi as f32 {
        return Err(config_err(field, format!("{v} is outside [{lo}, {hi}]")));
    }
    Ok(())
}

fn int_range(field: &str, v: u32, lo: u32, hi: u32) -> Result<(), StageError> {
    if v < lo || v > hi {
        return Err(config_err(field, format!("{v} is outside [{lo}, {hi}]")));
    }
    Ok(())
}

/// The scene rules of each technique (`src/scene/validate.rs`, `shadow`); techniques without
/// parameters pass as they are.
fn technique(
    t: Technique,
    light_size: f32,
    warnings: &mut Vec<String>,
) -> Result<Technique, StageError> {
    Ok(match t {
        Technique::Pcf { radius, .. } => {
            int_range("radius", radius, 0, 32)?;
            t
        }
        Technique::Pcss {
            blocker_samples,
            filter_samples,
            max_search,
        } => {
            int_range("blocker_samples", blocker_samples, 1, 256)?;
            int_range("filter_samples", filter_samples, 1, 1024)?;
            range("max_search", max_search, 1e-4, 1.0)?;
            area_light(&t, light_size)?;
            t
        }
        Technique::Cssm {
            soft,
            terms,
            attenuation,
            offset,
            scale,
            sharpen,
            sharpen_falloff,
        } => {
            range("max_search", soft.max_search, 1e-4, 1.0)?;
            range("terms", terms as f32, 1.0, 16.0)?;
            range("attenuation", attenuation, 0.0, 20.0)?;
            range("offset", offset, 0.0, 0.5)?;
            range("scale", scale, 1.0, 16.0)?;
            range("sharpen", sharpen, 0.0, 100.0)?;
            range("sharpen_falloff", sharpen_falloff, 0.0, 1e4)?;
            area_light(&t, light_size)?;
            t
        }
        Technique::Vssm {
            soft,
            bleed,
            min_variance,
        } => {
            range("max_search", soft.max_search, 1e-4, 1.0)?;
            range("bleed_reduction", bleed, 0.0, 0.99)?;
            range("min_variance", min_variance, 0.0, 1.0)?;
            area_light(&t, light_size)?;
            t
        }
        Technique::MsmSoft {
            soft,
            moment_bias,
            bleed,
            ..
        } => {
            range("max_search", soft.max_search, 1e-4, 1.0)?;
            range("moment_bias", moment_bias, 0.0, 0.5)?;
            range("bleed_reduction", bleed, 0.0, 0.99)?;
            area_light(&t, light_size)?;
            t
        }
        Technique::Vsm {
            prefilter,
            bleed,
            min_variance,
        } => {
            filter(&prefilter.filter)?;
            range("bleed_reduction", bleed, 0.0, 0.99)?;
            range("min_variance", min_variance, 0.0, 1.0)?;
            t
        }
        Technique::Evsm {
            prefilter,
            four,
            exp_pos,
            exp_neg,
            bleed,
            min_variance,
        } => {
            filter(&prefilter.filter)?;
            range("bleed_reduction", bleed, 0.0, 0.99)?;
            range("min_variance", min_variance, 0.0, 1.0)?;
            let limit = exponent_limit(prefilter.storage);
            let mut clamp = |field: &str, c: f32| -> Result<f32, StageError> {
                range(field, c, 0.01, 1e4)?;
                if c > limit {
                    warnings.push(format!(
                        "`{field}` = {c} exceeds the safe limit {limit} for {:?} storage; \
                         clamped to {limit}",
                        prefilter.storage
                    ));
                }
                Ok(sat_clamp(
                    warnings,
                    field,
                    c.min(limit),
                    &prefilter.filter,
                    false,
                ))
            };
            Technique::Evsm {
                prefilter,
                four,
                exp_pos: clamp("exponent_pos", exp_pos)?,
                exp_neg: clamp("exponent_neg", exp_neg)?,
                bleed,
                min_variance,
            }
        }
        Technique::Esm {
            filter: f,
            exponent,
        } => {
            filter(&f)?;
            range("exponent", exponent, 0.01, 1e4)?;
            Technique::Esm {
                filter: f,
                exponent: sat_clamp(warnings, "exponent", exponent, &f, true),
            }
        }
        Technique::Msm {
            prefilter,
            moment_bias,
            bleed,
            ..
        } => {
            filter(&prefilter.filter)?;
            range("moment_bias", moment_bias, 0.0, 0.5)?;
            range("bleed_reduction", bleed, 0.0, 0.99)?;
            t
        }
        Technique::Csm {
            prefilter,
            terms,
            attenuation,
            offset,
            scale,
        } => {
            filter(&prefilter.filter)?;
            range("terms", terms as f32, 1.0, 16.0)?;
            range("attenuation", attenuation, 0.0, 20.0)?;
            range("offset", offset, 0.0, 0.5)?;
            range("scale", scale, 1.0, 16.0)?;
            t
        }
        _ => t,
    })
}

/// `c` clamped to what a summed-area table keeps accurate (`scene::sat_exponent_limit`), with
/// a warning when it is clamped.
fn sat_clamp(warnings: &mut Vec<String>, field: &str, c: f32, f: &Filter, esm: bool) -> f32 {
    match crate::scene::sat_exponent_limit(f, esm) {
        Some(limit) if c > limit => {
            warnings.push(format!(
                "`{field}` = {c} exceeds {limit:.2}, the largest a summed-area table of this \
                 `filter_width` keeps accurate; clamped"
            ));
            limit
        }
        _ => c,
    }
}

/// PCSS and the soft techniques need an area light (as a scene's `size` > 0).
fn area_light(t: &Technique, light_size: f32) -> Result<(), StageError> {
    if light_size <= 0.0 {
        return Err(config_err(
            "size (light)",
            format!("technique \"{}\" needs an area light width > 0", t.name()),
        ));
    }
    Ok(())
}

fn filter(f: &Filter) -> Result<(), StageError> {
    if let Filter::Blur { radius, sigma, .. } = *f {
        range("filter_radius", radius, 0.0, f64::from(MAX_BLUR_RADIUS))?;
        range("filter_sigma", sigma, 0.1, 100.0)?;
    }
    if let Filter::Mips {
        width,
        max_anisotropy,
    } = *f
    {
        range("filter_width", width, 1.0, 65536.0)?;
        range("max_anisotropy", max_anisotropy as f32, 0.0, 16.0)?;
    }
    if let Filter::Sat { width, .. } = *f {
        range("filter_width", width, 1.0, 1024.0)?;
    }
    Ok(())
}

/// What changes per frame: the matrices the host rasterized the depth texture with, and how
/// its depth maps to distance. The projection follows wgpu's conventions: right-handed view
/// space looking down −Z, depth 0 at `near` and 1 at `far` (glam's `*_rh` projections; not
/// reversed Z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightParams {
    /// World → light view.
    pub view: Mat4,
    /// Light view → clip: the projection the depth texture was rasterized with.
    pub projection: Mat4,
    /// Perspective (spot) rather than orthographic (directional) depth.
    pub perspective: bool,
    /// Near plane (view-space distance).
    pub near: f32,
    /// Far plane.
    pub far: f32,
}

impl LightParams {
    /// An orthographic light of half-width `half_width` (world units), `view` from the host.
    pub fn orthographic(view: Mat4, half_width: f32, near: f32, far: f32) -> Self {
        let e = half_width;
        Self {
            view,
            projection: Mat4::orthographic_rh(-e, e, -e, e, near, far),
            perspective: false,
            near,
            far,
        }
    }

    /// A square perspective light with full field of view `fov_y_radians`.
    pub fn perspective(view: Mat4, fov_y_radians: f32, near: f32, far: f32) -> Self {
        Self {
            view,
            projection: Mat4::perspective_rh(fov_y_radians, 1.0, near, far),
            perspective: true,
            near,
            far,
        }
    }

    /// A scene light's matrices and planes (what shadowgraph's renderer rasterizes with).
    pub fn from_light(light: &Light) -> Self {
        Self {
            view: light.view(),
            projection: light.projection(),
            perspective: matches!(light.kind, LightKind::Spot { .. }),
            near: light.near,
            far: light.far,
        }
    }

    /// Checks the planes (as a scene does) and that the projection maps the near plane to
    /// depth 0 and the far plane to 1 with the stated kind of `w`.
    pub fn validate(&self) -> Result<(), StageError> {
        let err = |field, message: String| StageError::LightParams { field, message };
        for (field, m) in [("view", self.view), ("projection", self.projection)] {
            if !m.is_finite() {
                return Err(err(field, "has a non-finite element".into()));
            }
        }
        if self.view.determinant().abs() < 1e-12 {
            return Err(err("view", "is not invertible".into()));
        }
        for (field, v) in [("near", self.near), ("far", self.far)] {
            if !v.is_finite() || !(1e-6..=1e7).contains(&v) {
                return Err(err(field, format!("{v} is outside [1e-6, 1e7]")));
            }
        }
        if self.far <= self.near {
            return Err(err(
                "far",
                format!("{} must exceed near ({})", self.far, self.near),
            ));
        }
        // Depth must be 0 at the near plane and 1 at the far one, as `linearize` assumes; w is
        // the distance (perspective) or 1 (orthographic).
        for (plane, z, depth) in [("near", self.near, 0.0), ("far", self.far, 1.0)] {
            let clip = self.projection * Vec4::new(0.0, 0.0, -z, 1.0);
            let w = if self.perspective { z } else { 1.0 };
            let d = clip.z / clip.w;
            if (clip.w - w).abs() > 1e-4 * w || (d - depth).abs() > 1e-4 {
                let kind = if self.perspective {
                    "a perspective"
                } else {
                    "an orthographic"
                };
                return Err(err(
                    "projection",
                    format!(
                        "maps the {plane} plane (z = −{z}) to depth {d} with w = {}, where \
                         {kind} projection with depth 0 at near and 1 at far (not reversed Z) \
                         gives depth {depth} with w = {w}",
                        clip.w
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The scene light these parameters and `config` describe on `size`² maps (how the stage
    /// reuses [`crate::technique::add_light_nodes`]).
    pub fn scene_light(&self, config: &PrefilterConfig, size: u32) -> Light {
        let to_world = self.view.inverse();
        let position = to_world.transform_point3(Vec3::ZERO);
        let forward = to_world.transform_vector3(Vec3::NEG_Z);
        // Symmetric frusta: x_clip = m00·x (orthographic: over w = 1; perspective: over −z).
        let m00 = self.projection.x_axis.x;
        let kind = if self.perspective {
            LightKind::Spot {
                fov_degrees: (2.0 * (1.0 / m00).atan()).to_degrees(),
            }
        } else {
            LightKind::Directional { extent: 1.0 / m00 }
        };
        Light {
            kind,
            position,
            target: position + forward,
            near: self.near,
            far: self.far,
            size: config.light_size,
            radiance: Vec3::ONE,
            shadow_map: size,
            shadow: Shadow {
                technique: config.technique,
                bias: config.bias,
                // Slope-scaled bias is rasterization state: the host's depth pass owns it.
                slope_bias: 0.0,
                normal_bias: config.normal_bias,
            },
        }
    }

    /// The WGSL `struct Light` for these matrices, `config`'s technique and `size`² maps:
    /// the host's `view` and `projection` exactly as given (not rebuilt from a look-at), the
    /// light at the view's origin looking down its −Z, map width from the projection's x
    /// scale, radiance 1 and no spot cone (`cos_outer` = −1: the host shades its own cone).
    pub fn light_gpu(&self, config: &PrefilterConfig, size: u32) -> LightGpu {
        let light = self.scene_light(config, size);
        let mut g = LightGpu::new(&light);
        g.view = self.view.to_cols_array_2d();
        g.view_proj = (self.projection * self.view).to_cols_array_2d();
        g.position = light.position.to_array();
        g.direction = (light.target - light.position).normalize().to_array();
        g.width_at_unit = 2.0 / self.projection.x_axis.x;
        g.map_size = [size as f32; 2];
        g.cos_outer = -1.0;
        g
    }
}
