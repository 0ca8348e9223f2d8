//! A light's GPU description ([`LightGpu`], mirrored in `crate::gpu_data`) filled from its
//! technique, and the summed-area-table coding a technique's representation needs.

use crate::gpu_data::{
    LightGpu, MSM_HAUSDORFF, MSM_QUANTIZED, TECHNIQUE_CSM, TECHNIQUE_CSSM, TECHNIQUE_ESM,
    TECHNIQUE_EVSM, TECHNIQUE_HARD, TECHNIQUE_MSM, TECHNIQUE_MSM_SOFT, TECHNIQUE_PCF,
    TECHNIQUE_PCSS, TECHNIQUE_VSM, TECHNIQUE_VSSM,
};
use crate::model::{Filter, Light, LightKind, PcfKernel, Soft, Technique, mip_levels};
use crate::sat::{SatCoding, SatVariant, lookup_area};

use super::msm_quantized;

impl LightGpu {
    /// The GPU description of `light`.
    pub fn new(light: &Light) -> Self {
        let view = light.view();
        let (technique, radius, kernel, blocker_samples, filter_samples, max_search) = match light
            .shadow
            .technique
        {
            Technique::Hard => (TECHNIQUE_HARD, 0, 0, 0, 0, 0.0),
            Technique::Pcf { radius, kernel } => {
                let k = match kernel {
                    PcfKernel::Box => 0,
                    PcfKernel::Tent => 1,
                    PcfKernel::Hardware => 2,
                };
                (TECHNIQUE_PCF, radius, k, 0, 0, 0.0)
            }
            Technique::Pcss {
                blocker_samples,
                filter_samples,
                max_search,
            } => (
                TECHNIQUE_PCSS,
                0,
                0,
                blocker_samples,
                filter_samples,
                max_search,
            ),
            Technique::Vsm { .. } => (TECHNIQUE_VSM, 0, 0, 0, 0, 0.0),
            Technique::Evsm { .. } => (TECHNIQUE_EVSM, 0, 0, 0, 0, 0.0),
            Technique::Esm { .. } => (TECHNIQUE_ESM, 0, 0, 0, 0, 0.0),
            Technique::Msm { .. } => (TECHNIQUE_MSM, 0, 0, 0, 0, 0.0),
            Technique::Csm { .. } => (TECHNIQUE_CSM, 0, 0, 0, 0, 0.0),
            Technique::Cssm { soft, .. } => (TECHNIQUE_CSSM, 0, 0, 0, 0, soft.max_search),
            Technique::Vssm { soft, .. } => (TECHNIQUE_VSSM, 0, 0, 0, 0, soft.max_search),
            Technique::MsmSoft { soft, .. } => (TECHNIQUE_MSM_SOFT, 0, 0, 0, 0, soft.max_search),
        };
        let (bleed, min_variance, exp_pos, exp_neg, moments) = match light.shadow.technique {
            Technique::Vsm {
                bleed,
                min_variance,
                ..
            }
            | Technique::Vssm {
                bleed,
                min_variance,
                ..
            } => (bleed, min_variance, 0.0, 0.0, 2),
            Technique::Evsm {
                four,
                exp_pos,
                exp_neg,
                bleed,
                min_variance,
                ..
            } => (
                bleed,
                min_variance,
                exp_pos,
                exp_neg,
                if four { 4 } else { 2 },
            ),
            Technique::Esm { exponent, .. } => (0.0, 0.0, exponent, 0.0, 1),
            Technique::Msm { bleed, .. } | Technique::MsmSoft { bleed, .. } => {
                (bleed, 0.0, 0.0, 0.0, 4)
            }
            _ => (0.0, 0.0, 0.0, 0.0, 0),
        };
        let (moment_bias, msm_flags) = match light.shadow.technique {
            Technique::Msm {
                hausdorff,
                moment_bias,
                ..
            }
            | Technique::MsmSoft {
                hausdorff,
                moment_bias,
                ..
            } => (
                moment_bias,
                msm_flags(hausdorff, msm_quantized(&light.shadow.technique)),
            ),
            _ => (0.0, 0),
        };
        let (csm_terms, csm_attenuation, csm_offset, csm_scale) = match light.shadow.technique {
            Technique::Csm {
                terms,
                attenuation,
                offset,
                scale,
                ..
            }
            | Technique::Cssm {
                terms,
                attenuation,
                offset,
                scale,
                ..
            } => (terms, attenuation, offset, scale),
            _ => (0, 0.0, 0.0, 1.0),
        };
        let (sharpen, sharpen_falloff) = match light.shadow.technique {
            Technique::Cssm {
                sharpen,
                sharpen_falloff,
                ..
            } => (sharpen, sharpen_falloff),
            _ => (0.0, 0.0),
        };
        let (mip_levels, filter_lod, max_anisotropy) = match light.shadow.technique.filter() {
            Some(Filter::Mips {
                width,
                max_anisotropy,
            }) => (
                mip_levels(light.shadow_map, light.shadow_map),
                width.max(1.0).log2(),
                max_anisotropy,
            ),
            _ => (0, 0.0, 0),
        };
        let (kind, cos_outer) = match light.kind {
            LightKind::Directional { .. } => (0, -1.0),
            LightKind::Spot { fov_degrees } => (1, (0.5 * fov_degrees.to_radians()).cos()),
        };
        Self {
            view_proj: (light.projection() * view).to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            radiance: light.radiance.to_array(),
            kind,
            position: light.position.to_array(),
            near: light.near,
            direction: light.direction().to_array(),
            far: light.far,
            map_size: [light.shadow_map as f32; 2],
            width_at_unit: light.width_at_unit(),
            size: light.size,
            bias: light.shadow.bias,
            normal_bias: light.shadow.normal_bias,
            cos_outer,
            technique,
            radius,
            kernel,
            blocker_samples,
            filter_samples,
            max_search,
            bleed,
            min_variance,
            exp_pos,
            exp_neg,
            moments,
            moment_bias,
            msm_flags,
            csm_terms,
            csm_attenuation,
            csm_offset,
            csm_scale,
            mip_levels,
            filter_lod,
            filter_width: 0.0,
            max_anisotropy,
            sat_offset: [0.0; 4],
            sat_scale: [1.0; 4],
            sharpen,
            sharpen_falloff,
            max_width: soft_max_width(light).unwrap_or(0.0),
            _pad1: 0,
        }
        .with_sat(light)
    }

    /// The SAT fields for `light` (left as they are without a summed-area table or when its
    /// coding is invalid, which [`sat_coding`] reports). A soft technique's width is per
    /// receiver: `filter_width` stays 0.
    fn with_sat(mut self, light: &Light) -> Self {
        if let Ok(Some(c)) = sat_coding(light) {
            if let Some(Filter::Sat { width, .. }) = light.shadow.technique.filter() {
                self.filter_width = width;
            }
            self.sat_offset = c.offset;
            self.sat_scale = c.scale;
        }
        self
    }
}

/// The MSM flags of a reconstruction and representation.
fn msm_flags(hausdorff: bool, quantized: bool) -> u32 {
    u32::from(hausdorff) * MSM_HAUSDORFF + u32::from(quantized) * MSM_QUANTIZED
}

/// The largest square a soft technique reads (blocker search or filter), in texels:
/// `2·max_search·map_size`, clamped to `[1, map_size]` (a larger square is clamped to the map
/// by the lookups anyway); `None` for other techniques. Per-receiver widths are clamped to it
/// in `kernels/shared/blocker.wgsl`, and the fixed-point table is coded for it.
pub fn soft_max_width(light: &Light) -> Option<f32> {
    let soft = light.shadow.technique.soft()?;
    Some(soft_width_cap(soft.max_search, light.shadow_map))
}

/// [`soft_max_width`] for a search cap `max_search` (UV) on a `map`² shadow map.
pub fn soft_width_cap(max_search: f32, map: u32) -> f32 {
    let n = map as f32;
    (2.0 * max_search * n).clamp(1.0, n.max(1.0))
}

/// The window area a soft technique's fixed-point table is coded for: [`lookup_area`] of
/// its width cap plus one texel (the rectangle's edges are formed in f32 from a per-receiver
/// width).
pub fn soft_lookup_area(max_search: f32, map: u32) -> u64 {
    let w = soft_width_cap(max_search, map) + 1.0;
    lookup_area(w, w)
}

/// The table variant of `light`'s summed-area table, if its technique reads one (the `sat`
/// filter or a soft technique).
pub fn sat_variant(light: &Light) -> Option<SatVariant> {
    match (
        light.shadow.technique.filter(),
        light.shadow.technique.soft(),
    ) {
        (Some(Filter::Sat { variant, .. }), _) => Some(variant),
        (_, Some(Soft { sums, .. })) => Some(sums),
        _ => None,
    }
}

/// The summed-area-table coding of light `light`'s representation when it is read through a
/// table (the `sat` filter or a soft technique; `None` otherwise): the value range of every
/// channel over linear depths in [0, 1], and the largest window the lookups touch
/// ([`lookup_area`] of the filter width; for a soft technique of [`soft_max_width`] plus one
/// texel, since its rectangle's edges are formed in f32 from a per-receiver width).
///
/// Ranges: VSM and raw MSM moments [0, 1]; EVSM `±exp(±c z')` and their squares over
/// z' ∈ [−1, 1] as `±max |v|` (offset 0); ESM (stored linearly for the table)
/// `exp(c (z − 1)) ∈ [e^{−c}, 1]` as ±1; CSM's sines and cosines and CSSM's CSM-Z basis
/// (z, z·sin, z·cos) [−1, 1]; quantized MSM moments the range of the quantization over the
/// moment curve, sampled at 4097 depths and widened by 10⁻³ of the range (the curve is a
/// quartic: sampling misses its extremes by far less).
pub fn sat_coding(light: &Light) -> crate::error::Result<Option<SatCoding>> {
    let area = match (light.shadow.technique.filter(), soft_max_width(light)) {
        (Some(Filter::Sat { width, .. }), _) => lookup_area(width, width),
        (_, Some(_)) => match light.shadow.technique.soft() {
            Some(soft) => soft_lookup_area(soft.max_search, light.shadow_map),
            None => return Ok(None),
        },
        _ => return Ok(None),
    };
    let Some(variant) = sat_variant(light) else {
        return Ok(None);
    };
    let (lo, hi) = value_range(&light.shadow.technique);
    Ok(Some(match variant {
        SatVariant::Fixed => SatCoding::fixed(area, lo, hi)?,
        SatVariant::Float => SatCoding::float(lo, hi)?,
    }))
}

/// Per channel, the range of the values a technique's table sums (see [`sat_coding`]).
fn value_range(technique: &Technique) -> ([f32; 4], [f32; 4]) {
    match *technique {
        // Exponential moments span orders of magnitude, most of them close to 0: coded about 0
        // (range ±max|v|) every value keeps f32's relative precision through the lookups'
        // weighting, where a centred offset would leave the small ones an absolute error of
        // 2⁻²⁴ of the largest.
        Technique::Evsm {
            exp_pos, exp_neg, ..
        } => {
            let (p, n) = (exp_pos, exp_neg);
            let hi = [p.exp(), (2.0 * p).exp(), n.exp(), (2.0 * n).exp()];
            (hi.map(|v| -v), hi)
        }
        Technique::Esm { .. } => ([-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]),
        Technique::Msm { .. } | Technique::MsmSoft { .. } if msm_quantized(technique) => {
            quantized_msm_range()
        }
        Technique::Csm { .. } | Technique::Cssm { .. } => ([-1.0; 4], [1.0; 4]),
        _ => ([0.0; 4], [1.0; 4]),
    }
}

/// The range of MSM's optimized quantization over the moment curve (see [`sat_coding`]),
/// computed once (every frame builds each light's `LightGpu`, which asks for it).
fn quantized_msm_range() -> ([f32; 4], [f32; 4]) {
    static RANGE: std::sync::OnceLock<([f32; 4], [f32; 4])> = std::sync::OnceLock::new();
    *RANGE.get_or_init(|| {
        let (mut lo, mut hi) = ([f64::MAX; 4], [f64::MIN; 4]);
        for k in 0..=4096 {
            let z = f64::from(k) / 4096.0;
            let q = crate::msm_quantize::quantize([z, z * z, z.powi(3), z.powi(4)]);
            for c in 0..4 {
                lo[c] = lo[c].min(q[c]);
                hi[c] = hi[c].max(q[c]);
            }
        }
        let pad = |c: usize| 1e-3 * (hi[c] - lo[c]);
        (
            std::array::from_fn(|c| (lo[c] - pad(c)) as f32),
            std::array::from_fn(|c| (hi[c] + pad(c)) as f32),
        )
    })
}
