//! A light's shadow technique: the [`Technique`] enum with its parameters, and the plain data
//! accessors every layer reads ([`Technique::filter`], [`Technique::soft`],
//! [`Technique::prefilter`], …). Each accessor matches every variant by name, with no `_` arm,
//! so that a new variant is a compile error here until it answers each; what a technique *does*
//! (its reach, its cascades, its maps, its encoding) is its registry entry's
//! (`src/technique/<name>.rs`), and no file outside the registry and this one matches on the
//! enum (`tests/registry.rs`).

use super::{CssmResolve, CssmSearch, Filter, PcfKernel, SatVariant, Storage};

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
pub struct StorageFilter {
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
        prefilter: StorageFilter,
        /// Light-bleeding reduction `linstep(bleed, 1, p_max)`.
        bleed: f32,
        /// Minimum variance.
        min_variance: f32,
    },
    /// Exponential variance shadow maps (Lauritzen): depth warped to [−1, 1], then
    /// `exp(c⁺ z')` and its square (EVSM2), plus `−exp(−c⁻ z')` and its square (EVSM4).
    Evsm {
        /// Storage and filter of the moments.
        prefilter: StorageFilter,
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
        prefilter: StorageFilter,
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
        prefilter: StorageFilter,
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
            Technique::Hard
            | Technique::Pcf { .. }
            | Technique::Pcss { .. }
            | Technique::Cssm { .. }
            | Technique::Vssm { .. }
            | Technique::MsmSoft { .. }
            | Technique::Smrt { .. }
            | Technique::Midpoint { .. }
            | Technique::SecondDepth { .. } => None,
        }
    }

    /// The storage and table of a soft technique (`cssm`, `vssm`, `msm_soft`).
    pub fn soft(&self) -> Option<Soft> {
        let mut t = *self;
        t.soft_mut().copied()
    }

    /// The storage and table of a soft technique, to change them (`None` for the others).
    pub fn soft_mut(&mut self) -> Option<&mut Soft> {
        match self {
            Technique::Cssm { soft, .. }
            | Technique::Vssm { soft, .. }
            | Technique::MsmSoft { soft, .. } => Some(soft),
            Technique::Hard
            | Technique::Pcf { .. }
            | Technique::Pcss { .. }
            | Technique::Vsm { .. }
            | Technique::Evsm { .. }
            | Technique::Esm { .. }
            | Technique::Msm { .. }
            | Technique::Csm { .. }
            | Technique::Smrt { .. }
            | Technique::Midpoint { .. }
            | Technique::SecondDepth { .. } => None,
        }
    }

    /// The cap on the blocker search's radius (and the soft techniques' filter's), shadow-map
    /// UV, of PCSS and the soft techniques (`max_search`); `None` for the others.
    pub fn max_search(&self) -> Option<f32> {
        let mut t = *self;
        t.max_search_mut().map(|uv| *uv)
    }

    /// [`Technique::max_search`], to change it.
    fn max_search_mut(&mut self) -> Option<&mut f32> {
        match self {
            Technique::Pcss { max_search, .. } => Some(max_search),
            Technique::Cssm { soft, .. }
            | Technique::Vssm { soft, .. }
            | Technique::MsmSoft { soft, .. } => Some(&mut soft.max_search),
            Technique::Hard
            | Technique::Pcf { .. }
            | Technique::Vsm { .. }
            | Technique::Evsm { .. }
            | Technique::Esm { .. }
            | Technique::Msm { .. }
            | Technique::Csm { .. }
            | Technique::Smrt { .. }
            | Technique::Midpoint { .. }
            | Technique::SecondDepth { .. } => None,
        }
    }

    /// This technique with its [`Technique::max_search`] set to `uv` (unchanged without one).
    pub fn with_max_search(mut self, uv: f32) -> Self {
        if let Some(max_search) = self.max_search_mut() {
            *max_search = uv;
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
            Technique::Vsm { prefilter, .. }
            | Technique::Evsm { prefilter, .. }
            | Technique::Msm { prefilter, .. }
            | Technique::Csm { prefilter, .. } => Some(prefilter.storage),
            Technique::Cssm { soft, .. }
            | Technique::Vssm { soft, .. }
            | Technique::MsmSoft { soft, .. } => Some(soft.storage),
            Technique::Hard
            | Technique::Pcf { .. }
            | Technique::Pcss { .. }
            | Technique::Smrt { .. }
            | Technique::Midpoint { .. }
            | Technique::SecondDepth { .. } => None,
        }
    }

    /// The storage and filter of a prefiltered technique (VSM, EVSM, MSM, CSM; ESM has a filter
    /// only).
    pub fn prefilter(&self) -> Option<StorageFilter> {
        match *self {
            Technique::Vsm { prefilter, .. }
            | Technique::Evsm { prefilter, .. }
            | Technique::Msm { prefilter, .. }
            | Technique::Csm { prefilter, .. } => Some(prefilter),
            Technique::Hard
            | Technique::Pcf { .. }
            | Technique::Pcss { .. }
            | Technique::Esm { .. }
            | Technique::Cssm { .. }
            | Technique::Vssm { .. }
            | Technique::MsmSoft { .. }
            | Technique::Smrt { .. }
            | Technique::Midpoint { .. }
            | Technique::SecondDepth { .. } => None,
        }
    }

    /// The name used in scene files: its registry entry's (`technique::of` looks the entry up
    /// by it, and the registry's tests hold every entry's technique to its name).
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
