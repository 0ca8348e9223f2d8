//! The scene file as written: TOML with every value spanned, so each error names its line.

use serde::Deserialize;
use toml::Spanned;

/// A scalar or a list of numbers (`size = 2` or `size = [2, 1, 3]`).
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum Num {
    /// One number.
    One(f64),
    /// Several.
    Many(Vec<f64>),
}

/// A spanned 3-vector.
pub type V3 = Spanned<[f64; 3]>;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Ambient light colour.
    pub ambient: Option<V3>,
    /// `[output]`.
    pub output: OutputFile,
    /// `[camera]`.
    pub camera: CameraFile,
    /// `[[light]]`.
    #[serde(default, rename = "light")]
    pub lights: Vec<LightFile>,
    /// `[[object]]`.
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectFile>,
    /// `[animation]`.
    pub animation: Option<AnimationFile>,
}

/// `[output]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputFile {
    /// Image width in pixels.
    pub width: Spanned<i64>,
    /// Image height in pixels.
    pub height: Spanned<i64>,
    /// Background colour.
    pub background: Option<V3>,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    /// Eye position.
    pub position: V3,
    /// Look-at point.
    pub target: V3,
    /// Up vector (default +Y).
    pub up: Option<V3>,
    /// Vertical field of view.
    pub fov_y_degrees: Spanned<f64>,
}

/// `[[light]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightFile {
    /// `directional`, `spot` or `point`.
    pub kind: Spanned<String>,
    /// Light position (directional: where its orthographic frustum starts).
    pub position: V3,
    /// Point the light aims at (required but for point lights, which light every direction).
    pub target: Option<V3>,
    /// Spot cone angle (full), degrees.
    pub fov_degrees: Option<Spanned<f64>>,
    /// Directional: half-width of the orthographic frustum.
    pub extent: Option<Spanned<f64>>,
    /// Near plane distance.
    pub near: Option<Spanned<f64>>,
    /// Far plane distance.
    pub far: Option<Spanned<f64>>,
    /// Area-light width in world units (soft shadows).
    pub size: Option<Spanned<f64>>,
    /// Colour.
    pub color: Option<V3>,
    /// Intensity multiplier.
    pub intensity: Option<Spanned<f64>>,
    /// Shadow-map resolution (square).
    pub shadow_map: Option<Spanned<i64>>,
    /// `[light.shadow]`.
    pub shadow: Option<ShadowFile>,
    /// How often the map is redrawn: frames (1, k) or `"static"`.
    pub update: Option<Spanned<toml::Value>>,
}

/// `[light.shadow]`: the technique and its parameters.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowFile {
    /// Technique name.
    pub technique: Spanned<String>,
    /// Constant depth bias (linear depth units).
    pub bias: Option<Spanned<f64>>,
    /// Slope-scaled bias at rasterization.
    pub slope_bias: Option<Spanned<f64>>,
    /// Normal offset in shadow-map texels.
    pub normal_bias: Option<Spanned<f64>>,
    /// `constant` or `receiver_plane` (hard, pcf box/tent).
    pub bias_mode: Option<Spanned<String>>,
    /// Cap on a tap's receiver-plane depth correction (linear depth units).
    pub receiver_plane_cap: Option<Spanned<f64>>,
    /// Directional lights: number of cascades (1: one map).
    pub cascades: Option<Spanned<i64>>,
    /// The practical split's blend of logarithmic and uniform.
    pub cascade_lambda: Option<Spanned<f64>>,
    /// The blend band between neighbouring cascades, a fraction of each one's range.
    pub cascade_blend: Option<Spanned<f64>>,
    /// PCF radius in texels.
    pub radius: Option<Spanned<i64>>,
    /// PCF weights: `box`, `tent` or `hardware`.
    pub kernel: Option<Spanned<String>>,
    /// PCSS blocker-search taps.
    pub blocker_samples: Option<Spanned<i64>>,
    /// PCSS filter taps.
    pub filter_samples: Option<Spanned<i64>>,
    /// PCSS and soft techniques: cap on the blocker-search radius, in shadow-map UV.
    pub max_search: Option<Spanned<f64>>,
    /// Storage of a prefiltered representation: `f32`, `f16` or `unorm16` (MSM).
    pub format: Option<Spanned<String>>,
    /// Prefilter: `none`, `blur` or `mips`.
    pub filter: Option<Spanned<String>>,
    /// Blur radius in texels (fractional for box edges).
    pub filter_radius: Option<Spanned<f64>>,
    /// Gaussian sigma in texels (default radius / 2).
    pub filter_sigma: Option<Spanned<f64>>,
    /// Blur weights: `gaussian` or `box`.
    pub filter_kernel: Option<Spanned<String>>,
    /// Light-bleeding reduction: `linstep(amount, 1, p)`.
    pub bleed_reduction: Option<Spanned<f64>>,
    /// Minimum variance (VSM, EVSM), depth units².
    pub min_variance: Option<Spanned<f64>>,
    /// ESM exponent c.
    pub exponent: Option<Spanned<f64>>,
    /// EVSM positive exponent c⁺.
    pub exponent_pos: Option<Spanned<f64>>,
    /// EVSM4 negative exponent c⁻.
    pub exponent_neg: Option<Spanned<f64>>,
    /// Mip or SAT filter width in texels.
    pub filter_width: Option<Spanned<f64>>,
    /// SAT sums: `fixed` (u32 fixed point, exact window sums) or `float` (f32).
    pub sat_sums: Option<Spanned<String>>,
    /// Mips: most taps along the pixel's footprint (0: fixed width).
    pub max_anisotropy: Option<Spanned<i64>>,
    /// MSM reconstruction: `hamburger` or `hausdorff`.
    pub reconstruction: Option<Spanned<String>>,
    /// MSM moment bias α.
    pub moment_bias: Option<Spanned<f64>>,
    /// CSM number of Fourier terms M.
    pub terms: Option<Spanned<i64>>,
    /// CSM ringing attenuation α.
    pub attenuation: Option<Spanned<f64>>,
    /// CSM depth offset.
    pub offset: Option<Spanned<f64>>,
    /// CSM response scale.
    pub scale: Option<Spanned<f64>>,
    /// CSSM sharpening strength A.
    pub sharpen: Option<Spanned<f64>>,
    /// CSSM sharpening falloff B.
    pub sharpen_falloff: Option<Spanned<f64>>,
    /// CSSM blocker search: `moments` or `csm_z`.
    pub blocker_search: Option<Spanned<String>>,
    /// CSSM resolve: `two_depth`, `two_depth_search` or `sharpen`.
    pub resolve: Option<Spanned<String>>,
    /// SMRT: rays per receiver.
    pub rays: Option<Spanned<i64>>,
    /// SMRT: depth-map samples per ray.
    pub steps: Option<Spanned<i64>>,
    /// SMRT: cap on the receding slope extrapolated behind an occluder.
    pub max_slope: Option<Spanned<f64>>,
}

/// `[[object]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectFile {
    /// `plane`, `box`, `sphere`, `cylinder` or `mesh`.
    pub shape: Spanned<String>,
    /// Plane: `[x, z]` or one number; box: `[x, y, z]` or one number.
    pub size: Option<Spanned<Num>>,
    /// Sphere and cylinder radius.
    pub radius: Option<Spanned<f64>>,
    /// Cylinder height.
    pub height: Option<Spanned<f64>>,
    /// Mesh file, relative to the scene file.
    pub path: Option<Spanned<String>>,
    /// Translation.
    pub translate: Option<V3>,
    /// Rotation about X, then Y, then Z, degrees.
    pub rotate_degrees: Option<V3>,
    /// Scale: one number or `[x, y, z]`.
    pub scale: Option<Spanned<Num>>,
    /// Albedo.
    pub color: Option<V3>,
}

/// `[animation]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimationFile {
    /// Frames F.
    pub frames: Spanned<i64>,
    /// `[[animation.track]]`.
    #[serde(default, rename = "track")]
    pub tracks: Vec<TrackFile>,
}

/// `[[animation.track]]`: one animated value.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackFile {
    /// What moves: `light[i].position`, `light[i].target`, `camera.position`,
    /// `camera.target` or `object[i].translate`.
    pub animate: Spanned<String>,
    /// Keyframes, in frame order.
    pub keys: Spanned<Vec<KeyFile>>,
}

/// A keyframe: `{ frame = 0, value = [x, y, z] }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyFile {
    /// Its frame.
    pub frame: Spanned<i64>,
    /// The value there.
    pub value: V3,
}
