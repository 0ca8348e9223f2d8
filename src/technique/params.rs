//! The parameter tables techniques share (every range and default is written here or in its
//! technique's file, once), how a [`StorageFilter`] or [`Soft`] is built from checked values and
//! read back into them, and the clamps of exponential techniques.

use crate::filter::MAX_BLUR_RADIUS;
use crate::model::{
    BlurKernel, DEFAULT_MAX_SEARCH, Filter, Needs, ParamDefault, ParamKind, ParamSpec, ParamValue,
    ParamValues, Soft, Storage, StorageFilter,
};
use crate::{model::SatVariant, sat::lookup_area};

pub use super::code_values::{Given, GivenError, Loose};

/// A number spec without conditions.
pub(super) const fn float(
    key: &'static str,
    lo: f64,
    hi: f64,
    d: f32,
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        key,
        kind: ParamKind::Float { lo, hi },
        default: ParamDefault::Float(d),
        needs: &[],
        doc,
    }
}

/// An integer spec without conditions.
pub(super) const fn int(
    key: &'static str,
    lo: i64,
    hi: i64,
    d: u32,
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        key,
        kind: ParamKind::Int { lo, hi },
        default: ParamDefault::Int(d),
        needs: &[],
        doc,
    }
}

/// A choice spec without conditions.
pub(super) const fn choice(
    key: &'static str,
    options: &'static [&'static str],
    d: &'static str,
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        key,
        kind: ParamKind::Choice(options),
        default: ParamDefault::Choice(d),
        needs: &[],
        doc,
    }
}

/// Keys every technique accepts (`Shadow`'s biases).
pub const COMMON: &[ParamSpec] = &[
    float(
        "bias",
        -1.0,
        1.0,
        0.002,
        "constant bias at the comparison, linear depth units",
    ),
    float(
        "slope_bias",
        0.0,
        100.0,
        1.0,
        "slope-scaled bias at rasterization",
    ),
    float(
        "normal_bias",
        0.0,
        100.0,
        1.0,
        "normal offset in texels, scaled by 1 − N·L",
    ),
];

const RECEIVER_PLANE_ON: &[Needs] = &[Needs {
    key: "bias_mode",
    one_of: &["receiver_plane"],
    why: "needs `bias_mode = \"receiver_plane\"`",
}];

/// The default cap on a tap's receiver-plane depth correction, linear depth units (MJP's
/// Shadows sample caps its fractional-sampling bias at 0.01).
pub const DEFAULT_RECEIVER_PLANE_CAP: f32 = 0.01;

/// The receiver-plane bias keys of the techniques that compare depths tap by tap (`hard`,
/// `pcf`'s box and tent windows): `bias_mode` and its cap.
pub const RECEIVER_PLANE: &[ParamSpec] = &[
    choice(
        "bias_mode",
        &["constant", "receiver_plane"],
        "constant",
        "`receiver_plane` also moves each tap's receiver depth along the receiver's plane (from the G-buffer normal)",
    ),
    ParamSpec {
        needs: RECEIVER_PLANE_ON,
        ..float(
            "receiver_plane_cap",
            1e-6,
            1.0,
            DEFAULT_RECEIVER_PLANE_CAP,
            "cap on each tap's receiver-plane depth correction, linear depth units",
        )
    },
];

/// `Shadow::receiver_plane` of checked values: the cap when `bias_mode = "receiver_plane"`, else 0.
pub fn receiver_plane(v: &ParamValues) -> f32 {
    match (v.get("bias_mode"), v.get("receiver_plane_cap")) {
        (Some(ParamValue::Choice("receiver_plane")), Some(ParamValue::Float(cap))) => cap,
        _ => 0.0,
    }
}

/// `format` of the float representations (VSM, EVSM, CSM and their soft forms).
pub const FLOAT_FORMAT: &[ParamSpec] = &[choice(
    "format",
    &["f32", "f16"],
    "f32",
    "storage precision of the representation",
)];

/// `format` of MSM (16-bit storages through the optimized quantization).
pub const MSM_FORMAT: &[ParamSpec] = &[choice(
    "format",
    &["f32", "f16", "unorm16"],
    "f32",
    "storage precision of the moments (16-bit ones quantized)",
)];

const BLUR: &[Needs] = &[Needs {
    key: "filter",
    one_of: &["blur"],
    why: "needs `filter = \"blur\"`",
}];
const GAUSSIAN_BLUR: &[Needs] = &[
    BLUR[0],
    Needs {
        key: "filter_kernel",
        one_of: &["gaussian"],
        why: "does not apply to the box kernel",
    },
];
const WIDTH_WHY: &str = "needs `filter = \"mips\"` or `\"sat\"`";
const MIPS: &[Needs] = &[Needs {
    key: "filter",
    one_of: &["mips"],
    why: WIDTH_WHY,
}];
const SAT: &[Needs] = &[Needs {
    key: "filter",
    one_of: &["sat"],
    why: WIDTH_WHY,
}];

/// The default Gaussian sigma: half the radius, at least half a texel.
fn default_sigma(v: &ParamValues) -> ParamValue {
    ParamValue::Float(sigma_for(v.float("filter_radius")))
}

fn sigma_for(radius: f32) -> f32 {
    (0.5 * radius).max(0.5)
}

/// The filter keys of a prefiltered technique (`format` is the technique's own table).
pub const FILTER: &[ParamSpec] = &[
    choice(
        "filter",
        &["none", "blur", "mips", "sat"],
        "blur",
        "how the representation is filtered before shading",
    ),
    ParamSpec {
        needs: BLUR,
        ..float(
            "filter_radius",
            0.0,
            MAX_BLUR_RADIUS as f64,
            2.0,
            "blur radius in texels (fractional for box edges)",
        )
    },
    ParamSpec {
        needs: BLUR,
        ..choice(
            "filter_kernel",
            &["gaussian", "box"],
            "gaussian",
            "blur weights",
        )
    },
    ParamSpec {
        needs: GAUSSIAN_BLUR,
        default: ParamDefault::Rule(default_sigma),
        ..float(
            "filter_sigma",
            0.1,
            100.0,
            1.0,
            "Gaussian sigma in texels (default max(radius/2, 0.5))",
        )
    },
    ParamSpec {
        needs: MIPS,
        ..float(
            "filter_width",
            1.0,
            65536.0,
            1.0,
            "mip filter width in level-0 texels",
        )
    },
    ParamSpec {
        needs: SAT,
        ..float(
            "filter_width",
            1.0,
            1024.0,
            3.0,
            "summed-area-table box width in texels",
        )
    },
    ParamSpec {
        needs: &[Needs {
            key: "filter",
            one_of: &["sat"],
            why: "needs `filter = \"sat\"`",
        }],
        ..choice(
            "sat_sums",
            &["fixed", "float"],
            "fixed",
            "table sums: u32 fixed point or f32",
        )
    },
    ParamSpec {
        needs: &[Needs {
            key: "filter",
            one_of: &["mips"],
            why: "needs `filter = \"mips\"`",
        }],
        ..int(
            "max_anisotropy",
            0,
            16,
            0,
            "most trilinear taps along the pixel's footprint (0: fixed width)",
        )
    },
];

/// The table keys of a soft technique (`format` is the technique's own table).
pub const SOFT: &[ParamSpec] = &[
    choice(
        "sat_sums",
        &["fixed", "float"],
        "fixed",
        "table sums: u32 fixed point, or f32 whose filter lookups are four bilinear-filtered fetches (needs FLOAT32_FILTERABLE)",
    ),
    float(
        "max_search",
        1e-4,
        1.0,
        DEFAULT_MAX_SEARCH,
        "cap on the blocker-search and filter half-widths, shadow-map UV (in cascades: of the light's one map, 2·extent wide, the same world reach in every cascade)",
    ),
];

/// MSM's reconstruction and bleeding keys (`moment_bias` is per technique: its default
/// differs).
pub const MSM: &[ParamSpec] = &[
    choice(
        "reconstruction",
        &["hamburger", "hausdorff"],
        "hamburger",
        "MSM reconstruction",
    ),
    float(
        "bleed_reduction",
        0.0,
        0.99,
        0.0,
        "light-bleeding reduction",
    ),
];

/// The offset's default: half a term's spacing, ½/M.
fn default_offset(v: &ParamValues) -> ParamValue {
    ParamValue::Float(0.5 / v.int("terms").max(1) as f32)
}

/// CSM's series keys (`csm`, `cssm`).
pub const CSM: &[ParamSpec] = &[
    int("terms", 1, 16, 8, "Fourier terms M"),
    float(
        "attenuation",
        0.0,
        20.0,
        1.0,
        "ringing attenuation α: term k weighted by exp(−α (k/M)²)",
    ),
    ParamSpec {
        default: ParamDefault::Rule(default_offset),
        ..float(
            "offset",
            0.0,
            0.5,
            0.0625,
            "offset subtracted from the receiver depth (default ½/M)",
        )
    },
    float(
        "scale",
        1.0,
        16.0,
        2.0,
        "scale of the response about ½ before the clamp",
    ),
];

/// The storage a `format` option names.
pub fn storage(name: &str) -> Storage {
    match name {
        "f16" => Storage::F16,
        "unorm16" => Storage::Unorm16,
        _ => Storage::F32,
    }
}

/// The `format` option of a storage.
pub fn storage_name(s: Storage) -> &'static str {
    match s {
        Storage::F32 => "f32",
        Storage::F16 => "f16",
        Storage::Unorm16 => "unorm16",
    }
}

fn sums(name: &str) -> SatVariant {
    if name == "float" {
        SatVariant::Float
    } else {
        SatVariant::Fixed
    }
}

fn sums_name(v: SatVariant) -> &'static str {
    match v {
        SatVariant::Fixed => "fixed",
        SatVariant::Float => "float",
    }
}

/// The filter of checked [`FILTER`] values.
pub fn filter(v: &ParamValues) -> Filter {
    match v.choice("filter") {
        "none" => Filter::None,
        "mips" => Filter::Mips {
            width: v.float("filter_width"),
            max_anisotropy: v.int("max_anisotropy"),
        },
        "sat" => Filter::Sat {
            width: v.float("filter_width"),
            variant: sums(v.choice("sat_sums")),
        },
        _ => {
            let radius = v.float("filter_radius");
            let kernel = match v.choice("filter_kernel") {
                "box" => BlurKernel::Box,
                _ => BlurKernel::Gaussian,
            };
            // The box kernel reads no sigma; it keeps the default so equal scenes compare equal.
            let sigma = match v.get("filter_sigma") {
                Some(ParamValue::Float(s)) => s,
                _ => sigma_for(radius),
            };
            Filter::Blur {
                radius,
                sigma,
                kernel,
            }
        }
    }
}

/// The [`FILTER`] values of `f` (only the keys that apply to it).
pub fn filter_values(f: &Filter, out: &mut ParamValues) {
    let mut set = |k, v| out.set(k, v);
    match *f {
        Filter::None => set("filter", ParamValue::Choice("none")),
        Filter::Blur {
            radius,
            sigma,
            kernel,
        } => {
            set("filter", ParamValue::Choice("blur"));
            set("filter_radius", ParamValue::Float(radius));
            let gaussian = kernel == BlurKernel::Gaussian;
            let name = if gaussian { "gaussian" } else { "box" };
            set("filter_kernel", ParamValue::Choice(name));
            if gaussian {
                set("filter_sigma", ParamValue::Float(sigma));
            }
        }
        Filter::Mips {
            width,
            max_anisotropy,
        } => {
            set("filter", ParamValue::Choice("mips"));
            set("filter_width", ParamValue::Float(width));
            set("max_anisotropy", ParamValue::Int(max_anisotropy));
        }
        Filter::Sat { width, variant } => {
            set("filter", ParamValue::Choice("sat"));
            set("filter_width", ParamValue::Float(width));
            set("sat_sums", ParamValue::Choice(sums_name(variant)));
        }
    }
}

/// The storage and filter of checked `format` and [`FILTER`] values.
pub fn prefilter(v: &ParamValues) -> StorageFilter {
    StorageFilter {
        storage: storage(v.choice("format")),
        filter: filter(v),
    }
}

/// The values of `p` (`format` and the filter's keys).
pub fn prefilter_values(p: &StorageFilter, out: &mut ParamValues) {
    out.set("format", ParamValue::Choice(storage_name(p.storage)));
    filter_values(&p.filter, out);
}

/// The table of checked `format` and [`SOFT`] values.
pub fn soft(v: &ParamValues) -> Soft {
    Soft {
        storage: storage(v.choice("format")),
        sums: sums(v.choice("sat_sums")),
        max_search: v.float("max_search"),
    }
}

/// The values of `s`.
pub fn soft_values(s: &Soft, out: &mut ParamValues) {
    out.set("format", ParamValue::Choice(storage_name(s.storage)));
    out.set("sat_sums", ParamValue::Choice(sums_name(s.sums)));
    out.set("max_search", ParamValue::Float(s.max_search));
}

/// A value a technique changed after checking, and why (each front end words where).
#[derive(Clone, Debug, PartialEq)]
pub struct Clamp {
    /// The key.
    pub key: &'static str,
    /// The value given (or defaulted).
    pub from: f32,
    /// The value used.
    pub to: f32,
    /// Why.
    pub reason: ClampReason,
}

/// Why a value was clamped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClampReason {
    /// Past the storage's safe exponent (`model::exponent_limit`).
    Storage(Storage),
    /// Past what a summed-area table of this width keeps accurate ([`sat_exponent_limit`]).
    Sat,
}

impl Clamp {
    /// The warning, naming the key as `key` (a front end's spelling of it).
    pub fn message(&self, key: &str) -> String {
        let (c, limit) = (self.from, self.to);
        match self.reason {
            ClampReason::Storage(s) => format!(
                "`{key}` = {c} exceeds the safe limit {limit} for {s:?} storage; clamped to {limit}"
            ),
            ClampReason::Sat => format!(
                "`{key}` = {c} exceeds {limit:.2}, the largest a summed-area table of this \
                 `filter_width` keeps accurate; clamped"
            ),
        }
    }
}

/// `c` clamped to `limit` (when set), recording the clamp.
pub fn clamp(
    key: &'static str,
    c: f32,
    limit: Option<f32>,
    reason: ClampReason,
    out: &mut Vec<Clamp>,
) -> f32 {
    match limit {
        Some(to) if c > to => {
            out.push(Clamp {
                key,
                from: c,
                to,
                reason,
            });
            to
        }
        _ => c,
    }
}

/// The largest exponent a summed-area table keeps accurate (`None` without the `sat` filter).
///
/// Window sums are linear, so a table's error is absolute: the fixed-point coding's step per
/// mean is `½ / scale ≈ range · A / 2³²` for windows of `A` texels (src/sat.rs), the f32
/// coding's no better. EVSM's squared moment spans `e^{−2c}..e^{2c}`; its step at the centre
/// of the depth range (moment 1) stays below 2⁻¹⁰ while `e^{2c} · A / 2³² ≤ 2⁻¹⁰`, so
/// `c ≤ ½ ln(2²² / A)`. ESM's `exp(c (z − 1)) ∈ [e^{−c}, 1]` has visibility
/// `mean · e^{c (1 − d)}`, whose error at mid depth stays below 2⁻¹⁰ while
/// `e^{c/2} · A / 2³² ≤ 2⁻¹⁰`, so `c ≤ 2 ln(2²² / A)`.
pub fn sat_exponent_limit(filter: &Filter, esm: bool) -> Option<f32> {
    let Filter::Sat { width, .. } = *filter else {
        return None;
    };
    let area = lookup_area(width, width) as f64;
    let c = 0.5 * (f64::from(1u32 << 22) / area).ln().max(0.02);
    Some(if esm { 4.0 * c } else { c } as f32)
}

/// The cascade keys of a directional light (checked for every technique; only a directional
/// light with a technique [`cascade_support`] accepts may ask for more than one).
pub const CASCADES: &[ParamSpec] = &[
    int(
        "cascades",
        1,
        crate::model::cascades::MAX_CASCADES as i64,
        1,
        "directional lights: cascades split the camera's view range (1: one map over the light's extent); each cascade is its own `shadow_map`² map, prefiltered by the same graph",
    ),
    float(
        "cascade_lambda",
        0.0,
        1.0,
        0.5,
        "the practical split: 0 uniform, 1 logarithmic, between a blend of the two",
    ),
    float(
        "cascade_blend",
        0.0,
        0.5,
        0.1,
        "blend band at the far end of each cascade but the last, as a fraction of its view-distance range: the visibility fades to the next cascade's across it",
    ),
];

/// `Shadow::cascades` of checked [`CASCADES`] values.
pub fn cascades(v: &ParamValues) -> crate::model::Cascades {
    let mut c = crate::model::Cascades::SINGLE;
    if let Some(ParamValue::Int(n)) = v.get("cascades") {
        c.count = n;
    }
    if let Some(ParamValue::Float(x)) = v.get("cascade_lambda") {
        c.lambda = x;
    }
    if let Some(ParamValue::Float(x)) = v.get("cascade_blend") {
        c.blend = x;
    }
    c
}

/// Whether a technique works in cascades: `Err` says why not (its entry's
/// [`super::TechniqueDef::cascades`]). PCSS and the soft techniques
/// size search and penumbra in world units from the light's depths, which every cascade keeps,
/// and each cascade's map carries a guard band of their reach (`technique::cascade_guard`); the
/// second-depth techniques peel each cascade's depth as a light's (every cascade is a drawn
/// light); SMRT's rays march across the map toward the emitter's far side, which no band bounds.
pub fn cascade_support(t: &crate::model::Technique) -> Result<(), &'static str> {
    super::of(t).cascades
}
