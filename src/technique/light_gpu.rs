//! A light's GPU description ([`LightGpu`], mirrored in `crate::wgsl_mirrors`) filled from its
//! technique, and the summed-area-table coding a technique's representation needs.

use crate::model::{Filter, Light, LightKind, Technique, mip_levels};
use crate::wgsl_mirrors::LightGpu;
use crate::{
    model::SatVariant,
    sat::{SatCoding, lookup_area},
};

impl LightGpu {
    /// The GPU description of `light`: its matrices and biases, its technique's id and fields
    /// ([`super::TechniqueDef::gpu`]), the filter's mip fields, the table's coding and the soft
    /// width cap.
    pub fn new(light: &Light) -> Self {
        let view = light.view();
        let t = &light.shadow.technique;
        let def = super::of(t);
        let (mip_levels, filter_lod, max_anisotropy) = match t.filter() {
            Some(Filter::Mips {
                width,
                max_anisotropy,
            }) => (
                {
                    let (w, h) = light.map_dims();
                    mip_levels(w, h)
                },
                width.max(1.0).log2(),
                max_anisotropy,
            ),
            _ => (0, 0.0, 0),
        };
        let (kind, cos_outer) = match light.kind {
            LightKind::Directional { .. } => (0, -1.0),
            LightKind::Spot { fov_degrees } => (1, (0.5 * fov_degrees.to_radians()).cos()),
            LightKind::Point => (2, -1.0),
        };
        let (map_w, map_h) = light.map_dims();
        let mut g = Self {
            view_proj: (light.projection() * view).to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            radiance: light.radiance.to_array(),
            kind,
            position: light.position.to_array(),
            near: light.near,
            direction: light.direction().to_array(),
            far: light.far,
            map_size: [map_w as f32, map_h as f32],
            face_uv: [
                light.shadow_map as f32 / map_w as f32,
                light.shadow_map as f32 / map_h as f32,
            ],
            width_at_unit: light.width_at_unit(),
            size: light.size,
            target_distance: (light.target - light.position).length(),
            bias: light.shadow.bias,
            normal_bias: light.shadow.normal_bias,
            receiver_plane: light.shadow.receiver_plane,
            cos_outer,
            technique: def.id,
            csm_scale: 1.0,
            mip_levels,
            filter_lod,
            max_anisotropy,
            sat_scale: [1.0; 4],
            max_width: soft_max_width(light).unwrap_or(0.0),
            // A point light's faces have guard bands as wide as the search cap; a cascade's
            // band is set where the cascades are fitted (`render::cascade`).
            capped_filter: u32::from(matches!(light.kind, LightKind::Point)),
            ..bytemuck::Zeroable::zeroed()
        };
        if let Some(soft) = t.soft() {
            g.max_search = soft.max_search;
        }
        (def.gpu)(t, &mut g);
        g.with_sat(light)
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
            self.sat_filtered = u32::from(light.shadow.technique.sat_filtered());
            let (lo, hi) = value_range(&light.shadow.technique);
            self.sat_amplitude = (0..4).fold(0.0f32, |a, i| a.max(0.5 * (hi[i] - lo[i])));
        }
        self
    }
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
    light.shadow.technique.sat_variant()
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
    (super::of(technique).value_range)(technique)
}

/// The range of values in [0, 1]: depth moments.
pub(super) fn unit_range(_: &Technique) -> ([f32; 4], [f32; 4]) {
    ([0.0; 4], [1.0; 4])
}

/// The range of MSM's optimized quantization over the moment curve (see [`sat_coding`]),
/// computed once (every frame builds each light's `LightGpu`, which asks for it).
pub(super) fn quantized_msm_range() -> ([f32; 4], [f32; 4]) {
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
