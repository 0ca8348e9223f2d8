//! What the stage computes (a technique with its parameters, checked by the technique
//! registry's tables, as a scene file's are) and what changes per frame (the light's matrices
//! and depth range).

use super::StageError;
use crate::model::Cascades;
use crate::model::SatVariant;
use crate::model::{
    BlurKernel, CssmResolve, CssmSearch, Filter, Light, ParamValue, ParamValues, Storage, Technique,
};
use crate::technique::params::{CASCADES, COMMON, Given, GivenError, filter_values, storage_name};
use crate::technique::{self, TechniqueDef};

/// Largest map side a scene accepts before the device is asked (as `shadow_map` in scenes).
const MAX_SIDE: u32 = 1 << 16;

/// The stage's fixed settings: a technique with its parameters, the map size it is made for,
/// and the shading constants the visibility functions read. Build one with a constructor
/// ([`PrefilterConfig::vsm`], …) and adjust it with the `with_*` methods; defaults are the
/// scene file's (the registry's parameter tables).
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
    /// Receiver-plane depth bias: the cap on each tap's correction (0: off; `hard` and `pcf`
    /// box/tent only, checked by validation).
    pub receiver_plane: f32,
    /// Area-light width in world units (PCSS penumbrae; 0 for a point light).
    pub light_size: f32,
    /// Cascades of a directional light: the scene keys `cascades`, `cascade_lambda` and
    /// `cascade_blend`, checked by the same table ([`PrefilterConfig::with_cascades`]);
    /// [`crate::prefilter::Prefilter::fit_cascades`] fits them, one light slot each.
    pub cascades: Cascades,
    /// A `with_*` call that did not apply to the technique (reported by validation).
    not_applicable: Option<&'static str>,
    /// Whether [`PrefilterConfig::with_moment_bias`] set MSM's bias (else it follows the
    /// storage's default, as in a scene file).
    moment_bias_set: bool,
}

/// The registry entry named `name` with every key at its default.
fn named(name: &str) -> Technique {
    let def = technique::by_name(name).expect("the constructors name registered techniques");
    technique::default_of(def)
}

/// The registry entry named `name` with `values` over its defaults.
fn named_with(name: &str, values: &[(&'static str, ParamValue)]) -> Technique {
    technique::named(name, values).unwrap_or_else(|| named(name))
}

impl PrefilterConfig {
    /// `technique` on `size`² maps with the scene file's default bias, normal bias and size.
    pub fn new(technique: Technique, size: u32) -> Self {
        Self {
            technique,
            size,
            bias: 0.002,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            light_size: 0.0,
            cascades: Cascades::SINGLE,
            not_applicable: None,
            moment_bias_set: false,
        }
    }

    /// The technique named `name` in scene files (any of `technique::names()`, e.g. `"vsm"`,
    /// `"msm_soft"`) with every key at a scene's default, on `size`² maps; the `with_*` methods
    /// change its values, checked by [`PrefilterConfig::validated`]. An unknown name is a
    /// [`StageError::Config`] of `technique` listing the registered ones.
    pub fn named(name: &str, size: u32) -> Result<Self, StageError> {
        let def = technique::by_name(name).ok_or_else(|| {
            config_err(
                "technique",
                format!(
                    "unknown technique \"{name}\" (expected one of: {})",
                    technique::names().join(", ")
                ),
            )
        })?;
        Ok(Self::new(technique::default_of(def), size))
    }

    /// VSM with a scene's defaults: f32 moments, Gaussian blur of radius 2, bleed reduction
    /// 0.2, variance floor 1e-5.
    pub fn vsm(size: u32) -> Self {
        Self::new(named("vsm"), size)
    }

    /// EVSM with two moments and a scene's defaults (c⁺ = 40, floor 1e-4, no bleed reduction).
    pub fn evsm2(size: u32) -> Self {
        Self::new(named("evsm2"), size)
    }

    /// EVSM with four moments and a scene's defaults (c⁺ = 40, c⁻ = 5).
    pub fn evsm4(size: u32) -> Self {
        Self::new(named("evsm4"), size)
    }

    /// ESM with a scene's defaults: c = 80, Gaussian blur of radius 2 in log space.
    pub fn esm(size: u32) -> Self {
        Self::new(named("esm"), size)
    }

    /// MSM, 32-bit raw moments, Hamburger reconstruction, the scene default blur.
    pub fn msm(size: u32) -> Self {
        Self::new(named("msm"), size)
    }

    /// CSM with `terms` Fourier terms and the scene defaults (attenuation 1, offset ½/M,
    /// scale 2), the scene default blur.
    pub fn csm(size: u32, terms: u32) -> Self {
        Self::new(
            named_with("csm", &[("terms", ParamValue::Int(terms))]),
            size,
        )
    }

    /// Soft VSM (`vssm`) with a scene's defaults, for an area light `light_size` wide: f32
    /// moments in a fixed-point table, search cap 0.1, bleed reduction 0.2, floor 1e-5.
    pub fn vssm(size: u32, light_size: f32) -> Self {
        Self::new(named("vssm"), size).with_light_size(light_size)
    }

    /// Soft MSM (`msm_soft`) with a scene's defaults: f32 moments (summed quantized, as every
    /// MSM table) in a fixed-point table, Hamburger reconstruction, search cap 0.1, the soft
    /// moment bias of f32.
    pub fn msm_soft(size: u32, light_size: f32) -> Self {
        Self::new(named("msm_soft"), size).with_light_size(light_size)
    }

    /// Convolution soft shadow maps (`cssm`) with `terms` terms and a scene's defaults
    /// (attenuation 1, offset ½/M, scale 2, the default sharpening, search cap 0.1).
    pub fn cssm(size: u32, terms: u32, light_size: f32) -> Self {
        let t = named_with("cssm", &[("terms", ParamValue::Int(terms))]);
        Self::new(t, size).with_light_size(light_size)
    }

    /// The same with the area light's width `light_size` (world units; PCSS and the soft
    /// techniques need it > 0).
    pub fn with_light_size(mut self, light_size: f32) -> Self {
        self.light_size = light_size;
        self
    }

    /// `count` cascades (1–8; 1: one map) split by the practical split's `lambda` (0 uniform,
    /// 1 logarithmic) with a blend band of `blend` (0–0.5 of each cascade's range): a scene's
    /// `cascades`, `cascade_lambda` and `cascade_blend`, checked by validation as a scene's are
    /// (soft techniques refuse more than one).
    pub fn with_cascades(mut self, count: u32, lambda: f32, blend: f32) -> Self {
        self.cascades = Cascades {
            count,
            lambda,
            blend,
        };
        self
    }

    /// The technique, map size and shading constants of a scene's light.
    pub fn from_light(light: &Light) -> Self {
        Self {
            technique: light.shadow.technique,
            size: light.shadow_map,
            bias: light.shadow.bias,
            normal_bias: light.shadow.normal_bias,
            receiver_plane: light.shadow.receiver_plane,
            light_size: light.size,
            cascades: light.shadow.cascades,
            not_applicable: None,
            moment_bias_set: true,
        }
    }

    /// The technique with `change` made to its values, rebuilt by the registry; `key` is
    /// reported as not applying when the technique has no such key, or refuses the option.
    fn with_values(mut self, key: &'static str, change: impl FnOnce(&mut ParamValues)) -> Self {
        let def = technique::of(&self.technique);
        let mut values = (def.values)(&self.technique);
        let before = values.get(key);
        change(&mut values);
        let refused = match values.get(key) {
            Some(ParamValue::Choice(name)) => !technique::accepts(def, key, name),
            _ => false,
        };
        match technique::build_with(def, &values) {
            Some(t) if before.is_some() && !refused => self.technique = t,
            _ => self.not_applicable = Some(key),
        }
        self
    }

    /// The same with moments stored at `storage` precision (VSM, EVSM, MSM, CSM and the soft
    /// techniques; ESM is always f32; `Unorm16` only for MSM and soft MSM). MSM's moment bias
    /// becomes the storage's default unless [`PrefilterConfig::with_moment_bias`] set it.
    pub fn with_storage(self, storage: Storage) -> Self {
        let keep = self.moment_bias_set;
        self.with_values("format", |v| {
            v.set("format", ParamValue::Choice(storage_name(storage)));
            if !keep {
                v.remove("moment_bias");
            }
        })
    }

    /// The same with `filter` over the representation (VSM, EVSM, ESM, MSM, CSM; the soft
    /// techniques always read a summed-area table: see [`PrefilterConfig::with_soft`]).
    pub fn with_filter(self, filter: Filter) -> Self {
        self.with_values("filter", |v| {
            for k in [
                "filter_radius",
                "filter_sigma",
                "filter_kernel",
                "filter_width",
                "sat_sums",
                "max_anisotropy",
            ] {
                v.remove(k);
            }
            filter_values(&filter, v);
        })
    }

    /// The same with a soft technique's table sums and search cap (`cssm`, `vssm`,
    /// `msm_soft`; the storage is set by [`PrefilterConfig::with_storage`]).
    pub fn with_soft(self, sums: SatVariant, max_search: f32) -> Self {
        if !technique::of(&self.technique).area_light || self.technique.soft().is_none() {
            return Self {
                not_applicable: Some("sat_sums"),
                ..self
            };
        }
        self.with_values("sat_sums", |v| {
            let name = match sums {
                SatVariant::Fixed => "fixed",
                SatVariant::Float => "float",
            };
            v.set("sat_sums", ParamValue::Choice(name));
            v.set("max_search", ParamValue::Float(max_search));
        })
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
        self = self.with_values("moment_bias", |v| {
            v.set("moment_bias", ParamValue::Float(alpha));
        });
        if self.not_applicable.is_none() {
            self.moment_bias_set = true;
        }
        self
    }

    /// The same with CSSM's blocker search (the scene key `blocker_search`): MSM's quantized
    /// moments in one table (the default) or the paper's CSM-Z basis. Not applicable to other
    /// techniques (validation names the key).
    pub fn with_blocker_search(self, search: CssmSearch) -> Self {
        self.with_values("blocker_search", |v| {
            v.set("blocker_search", ParamValue::Choice(search.name()));
        })
    }

    /// The same with CSSM's resolve (the scene key `resolve`): `CssmResolve::TwoDepth` (the
    /// default: away from contact, the filtered series inverted for the share of blockers at
    /// their depth over the filter square), `TwoDepthSearch` (at the search's z_avg: 4 fewer
    /// loads) or `Sharpen` (the paper's clamp and sharpening alone). Not applicable to other
    /// techniques.
    pub fn with_cssm_resolve(self, resolve: CssmResolve) -> Self {
        self.with_values("resolve", |v| {
            v.set("resolve", ParamValue::Choice(resolve.name()));
        })
    }

    /// The same with the receiver-plane depth bias on, each tap's correction capped at `cap`
    /// linear depth units (0: off).
    pub fn with_receiver_plane(mut self, cap: f32) -> Self {
        self.receiver_plane = cap;
        self
    }

    /// The same with constant bias `bias` (linear depth units).
    pub fn with_bias(mut self, bias: f32) -> Self {
        self.bias = bias;
        self
    }

    /// Checks every value against the technique's parameter table (the scene file's rules)
    /// and returns the configuration the stage runs, with EVSM and ESM exponents clamped as
    /// a scene's are, and a warning per value changed.
    pub fn validated(&self) -> Result<(Self, Vec<String>), StageError> {
        let def = technique::of(&self.technique);
        if let Some(field) = self.not_applicable {
            return Err(config_err(
                field,
                format!("does not apply to technique \"{}\"", def.name),
            ));
        }
        let side = u64::from(self.size);
        if !(1..=u64::from(MAX_SIDE)).contains(&side) {
            return Err(config_err(
                "size",
                format!("{side} is outside [1, {MAX_SIDE}]"),
            ));
        }
        let common = ParamValues(vec![
            ("bias", ParamValue::Float(self.bias)),
            ("normal_bias", ParamValue::Float(self.normal_bias)),
        ]);
        crate::model::check_params(&[COMMON], &Given(&common)).map_err(given_err)?;
        if self.receiver_plane != 0.0 {
            if !crate::model::keys(def.params).contains(&"bias_mode") {
                return Err(config_err(
                    "receiver_plane",
                    format!("does not apply to technique \"{}\"", def.name),
                ));
            }
            // The scene's rules: the technique's table says where the keys apply and the range.
            let mut values = (def.values)(&self.technique);
            values.set("bias_mode", ParamValue::Choice("receiver_plane"));
            values.set("receiver_plane_cap", ParamValue::Float(self.receiver_plane));
            crate::model::check_params(def.params, &Given(&values)).map_err(given_err)?;
        }
        let c = self.cascades;
        let cascades = ParamValues(vec![
            ("cascades", ParamValue::Int(c.count)),
            ("cascade_lambda", ParamValue::Float(c.lambda)),
            ("cascade_blend", ParamValue::Float(c.blend)),
        ]);
        crate::model::check_params(&[CASCADES], &Given(&cascades)).map_err(given_err)?;
        if c.count > 1 {
            technique::params::cascade_support(&self.technique).map_err(|why| {
                config_err(
                    "cascades",
                    format!("{} cascades of technique \"{}\": {why}", c.count, def.name),
                )
            })?;
        }
        if !self.light_size.is_finite() || !(0.0..=1e6).contains(&self.light_size) {
            return Err(config_err(
                "size (light)",
                format!("{} is outside [0, 1000000]", self.light_size),
            ));
        }
        let mut out = *self;
        // The bias is settled now: a later `with_storage` keeps it, as it keeps a light's.
        out.moment_bias_set = true;
        let warnings;
        (out.technique, warnings) = checked(def, self.technique, self.light_size)?;
        Ok((out, warnings))
    }
}

/// `t` checked against `def`'s tables (the values it holds, as a scene's would be) with its
/// clamps applied, and the warnings of the clamps. The technique is kept as built (a
/// setting that does not apply, such as a box blur's sigma, keeps its value).
fn checked(
    def: &TechniqueDef,
    mut t: Technique,
    light_size: f32,
) -> Result<(Technique, Vec<String>), StageError> {
    let values = (def.values)(&t);
    crate::model::check_params(def.params, &Given(&values)).map_err(given_err)?;
    if technique::peels(&t) {
        return Err(config_err(
            "technique",
            format!(
                "technique \"{}\" reads a second, peeled depth map, and the stage takes one depth texture: use it in the renderer, or a single-depth technique here",
                def.name
            ),
        ));
    }
    if def.area_light && light_size <= 0.0 {
        return Err(config_err(
            "size (light)",
            format!("technique \"{}\" needs an area light width > 0", def.name),
        ));
    }
    let mut clamps = Vec::new();
    (def.clamp)(&mut t, &mut clamps);
    let warnings = clamps.iter().map(|c| c.message(c.key)).collect();
    Ok((t, warnings))
}

fn given_err(e: GivenError) -> StageError {
    config_err(e.key, e.message)
}

fn config_err(field: &str, message: String) -> StageError {
    StageError::Config {
        field: field.to_string(),
        message,
    }
}
