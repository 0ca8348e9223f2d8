//! Defaults and safe limits of technique parameters: the plain rules that scene validation and
//! the plug-in's config both apply.

use super::Storage;

/// CSSM's default sharpening strength A (`sharpen`): with [`DEFAULT_SHARPEN_FALLOFF`], the
/// best of a small grid (A ∈ {0, 1, 2, 4, 8, 16}, B ∈ {2, 5, 10, 20, 50, 100}) measured as the
/// mean distance to PCSS on the CSSM, pole and sphere scenes with M = 8 and fitted depth ranges
/// (A = 16 was marginally closer on two of them; 8 darkens less).
pub const DEFAULT_SHARPEN: f32 = 8.0;

/// CSSM's default sharpening falloff B (`sharpen_falloff`), per linear depth unit: the
/// darkening fades to 1/e where the receiver is 0.1 of the depth range behind its blockers.
pub const DEFAULT_SHARPEN_FALLOFF: f32 = 10.0;

/// Default `max_search` (shadow-map UV) of PCSS and the soft techniques.
pub const DEFAULT_MAX_SEARCH: f32 = 0.1;

/// Default MSM moment bias α per storage, from the measured sweep of bias against error
/// (docs/STABILITY.md, "MSM moment bias"; `cargo run --release --example msm_bias_sweep`): the smallest
/// bias of the sweep whose largest error behind a flat occluder is at most half the stability
/// suite's bound (case 8: 0.01 for f32, 0.03 for unorm16, 0.25 for f16 moments, whose 11-bit
/// significand leaves them 2⁻¹² of their range). Against the area-light truth they cost f32
/// and unorm16 at most 3% of the mean error of 10⁻⁵ on `sphere_on_plane` and `pole`; f16 9%
/// of its best.
pub fn default_moment_bias(storage: Storage) -> f32 {
    match storage {
        Storage::F32 => 5e-4,
        Storage::Unorm16 => 1e-3,
        Storage::F16 => 3e-3,
    }
}

/// Default moment bias of soft MSM (`msm_soft`) per storage, chosen as
/// [`default_moment_bias`] against case 8's bound for summed-area tables (0.05; f16 0.25).
/// The table sums quantized moments whatever the storage (`technique::msm_quantized`).
pub fn default_soft_moment_bias(storage: Storage) -> f32 {
    match storage {
        Storage::F32 => 2e-4,
        Storage::Unorm16 => 3e-4,
        Storage::F16 => 3e-3,
    }
}

/// Largest exponent whose squared moment stays finite after filtering: ln(FLT_MAX) = 88.7
/// and ln(65504) = 11.09, halved for the square, with margin for fp32 (reference.md).
pub fn exponent_limit(storage: Storage) -> f32 {
    match storage {
        Storage::F32 => 42.0,
        Storage::F16 | Storage::Unorm16 => 5.54,
    }
}
