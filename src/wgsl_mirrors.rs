//! The WGSL mirrors: every `#[repr(C)]` mirror of a WGSL struct the Rust side fills
//! (bytemuck), each naming the struct it mirrors (`tests/kernels_validate/` checks their sizes
//! against naga's layouts), and the technique ids and flags the shading kernel reads. What fills a
//! [`LightGpu`] from a light lives with the techniques (`crate::technique`); the parameters of
//! the filter and table kernels live beside their graph builders (`crate::filter::MipParams`,
//! `crate::sat`).

use crate::model::{Light, LightKind};

/// A light as the shading kernel reads it. Mirrors `struct Light` in
/// `kernels/shared/light.wgsl` (a test checks the size against naga's layout).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightGpu {
    /// World → light clip.
    pub view_proj: [[f32; 4]; 4],
    /// World → light view.
    pub view: [[f32; 4]; 4],
    /// Colour × intensity.
    pub radiance: [f32; 3],
    /// 0 directional, 1 spot, 2 point.
    pub kind: u32,
    /// Light position.
    pub position: [f32; 3],
    /// Near plane.
    pub near: f32,
    /// Unit direction light → target.
    pub direction: [f32; 3],
    /// Far plane.
    pub far: f32,
    /// Shadow-map size in texels.
    pub map_size: [f32; 2],
    /// Map width in world units (directional) or per unit distance (spot).
    pub width_at_unit: f32,
    /// Area-light width.
    pub size: f32,
    /// Constant bias, linear depth units.
    pub bias: f32,
    /// Normal offset, texels.
    pub normal_bias: f32,
    /// Spot: cos(fov/2); directional: −1.
    pub cos_outer: f32,
    /// The technique's id (`TECHNIQUE_*`).
    pub technique: u32,
    /// PCF radius.
    pub radius: u32,
    /// PCF kernel: 0 box, 1 tent, 2 hardware.
    pub kernel: u32,
    /// PCSS blocker taps.
    pub blocker_samples: u32,
    /// PCSS filter taps.
    pub filter_samples: u32,
    /// PCSS and soft techniques: search cap (UV).
    pub max_search: f32,
    /// VSM light-bleeding reduction.
    pub bleed: f32,
    /// VSM/EVSM minimum variance (depth units²).
    pub min_variance: f32,
    /// EVSM positive exponent; ESM exponent.
    pub exp_pos: f32,
    /// EVSM negative exponent.
    pub exp_neg: f32,
    /// EVSM: 2 or 4 stored moments.
    pub moments: u32,
    /// MSM moment bias α.
    pub moment_bias: f32,
    /// MSM: bit 0 Hausdorff (else Hamburger), bit 1 quantized storage.
    pub msm_flags: u32,
    /// CSM terms M.
    pub csm_terms: u32,
    /// CSM ringing attenuation α.
    pub csm_attenuation: f32,
    /// CSM receiver-depth offset.
    pub csm_offset: f32,
    /// CSM response scale.
    pub csm_scale: f32,
    /// Mip levels of the filtered map (0 when the filter is not `mips`).
    pub mip_levels: u32,
    /// `log2` of the mip filter width in texels.
    pub filter_lod: f32,
    /// SAT filter: box width in texels (0 when the filter is not `sat`).
    pub filter_width: f32,
    /// Mips filter: 0 reads a fixed width; ≥ 1 follows the pixel's footprint with up to this
    /// many trilinear taps along its major axis.
    pub max_anisotropy: u32,
    /// SAT filter: the table's per-channel offset (`sat::SatCoding::offset`).
    pub sat_offset: [f32; 4],
    /// SAT filter: the table's per-channel scale (`sat::SatCoding::scale`).
    pub sat_scale: [f32; 4],
    /// CSSM: sharpening strength A of `v^p`, `p = 1 + A·exp(−B (d − z_avg))`.
    pub sharpen: f32,
    /// CSSM: sharpening falloff B, per linear depth unit.
    pub sharpen_falloff: f32,
    /// Soft techniques: cap on the search and filter widths in texels (`technique::soft_max_width`;
    /// 0 otherwise).
    pub max_width: f32,
    /// Receiver-plane depth bias: the cap on each tap's depth correction, linear depth units
    /// (0: off; `Shadow::receiver_plane`).
    pub receiver_plane: f32,
    /// SMRT: rays per receiver.
    pub smrt_rays: u32,
    /// SMRT: depth-map samples per ray.
    pub smrt_steps: u32,
    /// SMRT: cap on the receding slope of the surface extrapolated behind an occluder.
    pub smrt_max_slope: f32,
    /// Distance from the light's position to its target (the directional emitter's rays run
    /// from each emitter point to the target, as in `truth::emitter`).
    pub target_distance: f32,
    /// Cascades (appended): the camera's eye, from which a pixel's view distance is measured.
    pub cascade_eye: [f32; 3],
    /// Cascades of this directional light (0 or 1: one map; this entry is cascade 0).
    pub cascade_count: u32,
    /// Cascades: the camera's unit forward direction.
    pub cascade_forward: [f32; 3],
    /// Cascades: index in the shading pass's lights of cascade 1 (the rest follow).
    pub cascade_first: u32,
    /// Cascades: the view distance the first cascade starts at.
    pub cascade_near: f32,
    /// Cascades: the blend band, a fraction of each cascade's view-distance range.
    pub cascade_blend: f32,
    /// Map UV per unit of a face's UV: (1, 1) for a one-map light, (1/3, 1/2) for a point
    /// light's atlas of 3 × 2 faces (offsets in world or face units reach the atlas through it).
    pub face_uv: [f32; 2],
    /// Cascades: each cascade's far view distance, cascade `c` at `[c / 4][c % 4]`.
    pub cascade_far: [[f32; 4]; 2],
    /// Tables: 1 where the light's summed-area table is f32 and read with filtered fetches,
    /// its rectangles on the 2⁻⁸-texel grid (`sat_mean_linear`), else 0. The shading kernel's
    /// lookups are chosen when it is generated; the CPU references read this.
    pub sat_filtered: u32,
    /// Tables: the largest `|v − sat_offset|` of any channel over the representation's value
    /// range (half the widest channel's range): the error models' bound on the table's corner
    /// sums (`tolerance::filtered_table_error`).
    pub sat_amplitude: f32,
    /// CSSM: how the filtered series is resolved: 0 the paper's clamp and sharpening alone
    /// (`resolve = "sharpen"`); 1 the two-depth inversion with the search's z_avg
    /// (`"two_depth_search"`, or `"two_depth"` with the CSM-Z search); 2 with the blockers'
    /// depth over the filter square (`"two_depth"` with the moment search). Non-zero also has
    /// the receiver plane's slope computed.
    pub cssm_two_depth: u32,
    /// PCSS: 1 where the filter radius is capped at `max_search` as the search's is, so that
    /// no tap leaves the map's guard band (a point light's faces, a cascade's band); else 0.
    pub capped_filter: u32,
}

/// Technique id of `hard` (`LightGpu::technique`; `TECHNIQUE_HARD` in
/// `kernels/shared/light.wgsl`, as every id below).
pub const TECHNIQUE_HARD: u32 = 0;
/// Technique id of `pcf`.
pub const TECHNIQUE_PCF: u32 = 1;
/// Technique id of `pcss`.
pub const TECHNIQUE_PCSS: u32 = 2;
/// Technique id of `vsm`.
pub const TECHNIQUE_VSM: u32 = 3;
/// Technique id of `evsm2` and `evsm4` (`LightGpu::moments` tells them apart).
pub const TECHNIQUE_EVSM: u32 = 4;
/// Technique id of `esm`.
pub const TECHNIQUE_ESM: u32 = 5;
/// Technique id of `msm`.
pub const TECHNIQUE_MSM: u32 = 6;
/// Technique id of `csm`.
pub const TECHNIQUE_CSM: u32 = 7;
/// Technique id of `cssm`.
pub const TECHNIQUE_CSSM: u32 = 8;
/// Technique id of `vssm`.
pub const TECHNIQUE_VSSM: u32 = 9;
/// Technique id of `msm_soft`.
pub const TECHNIQUE_MSM_SOFT: u32 = 10;
/// Technique id of `smrt`.
pub const TECHNIQUE_SMRT: u32 = 20;
/// Technique id of `midpoint`.
pub const TECHNIQUE_MIDPOINT: u32 = 30;
/// Technique id of `second_depth`.
pub const TECHNIQUE_SECOND_DEPTH: u32 = 31;

/// Every technique id with its WGSL constant's name (checked against
/// `kernels/shared/light.wgsl` by a test).
pub const TECHNIQUE_IDS: &[(&str, u32)] = &[
    ("TECHNIQUE_HARD", TECHNIQUE_HARD),
    ("TECHNIQUE_PCF", TECHNIQUE_PCF),
    ("TECHNIQUE_PCSS", TECHNIQUE_PCSS),
    ("TECHNIQUE_VSM", TECHNIQUE_VSM),
    ("TECHNIQUE_EVSM", TECHNIQUE_EVSM),
    ("TECHNIQUE_ESM", TECHNIQUE_ESM),
    ("TECHNIQUE_MSM", TECHNIQUE_MSM),
    ("TECHNIQUE_CSM", TECHNIQUE_CSM),
    ("TECHNIQUE_CSSM", TECHNIQUE_CSSM),
    ("TECHNIQUE_VSSM", TECHNIQUE_VSSM),
    ("TECHNIQUE_MSM_SOFT", TECHNIQUE_MSM_SOFT),
    ("TECHNIQUE_SMRT", TECHNIQUE_SMRT),
    ("TECHNIQUE_MIDPOINT", TECHNIQUE_MIDPOINT),
    ("TECHNIQUE_SECOND_DEPTH", TECHNIQUE_SECOND_DEPTH),
];

/// MSM flag: Hausdorff reconstruction.
pub const MSM_HAUSDORFF: u32 = 1;
/// MSM flag: moments stored through the optimized quantization.
pub const MSM_QUANTIZED: u32 = 2;

/// How a depth buffer is linearized: `kernels/linearize.wgsl`'s params and the first member
/// (`depth`) of every encoding's params (mirrors `DepthParams` in
/// `kernels/shared/linear_depth.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LinearizeParams {
    /// 1 for a perspective (spot) depth buffer.
    pub perspective: u32,
    /// Near plane.
    pub near: f32,
    /// Far plane.
    pub far: f32,
    /// Padding.
    pub _pad: u32,
}

impl LinearizeParams {
    /// An orthographic depth buffer: depth in [0, 1] is linear already (only clamped, and
    /// non-finite values replaced).
    pub const ORTHOGRAPHIC: Self = Self {
        perspective: 0,
        near: 0.0,
        far: 1.0,
        _pad: 0,
    };

    /// Parameters for `light`'s depth buffer.
    pub fn new(light: &Light) -> Self {
        Self {
            perspective: u32::from(!matches!(light.kind, LightKind::Directional { .. })),
            near: light.near,
            far: light.far,
            _pad: 0,
        }
    }
}

/// Parameters of `kernels/vsm.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VsmParams {
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
}

/// Parameters of `kernels/second_depth.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SecondDepthParams {
    /// The depth buffer's linearization (both depths').
    pub depth: LinearizeParams,
    /// 0: the midpoint of the first and second depths; 1: the second depth. Both store the
    /// far plane (1.0) where no second surface was rasterized.
    pub mode: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// The peel pass's margin in depth-buffer units (`PEEL_EPSILON` in `kernels/shadow_peel.wgsl`,
/// 2⁻¹⁸): a fragment no deeper than the first depth plus this is discarded.
pub const PEEL_EPSILON: f32 = 1.0 / 262_144.0;

/// Parameters of `kernels/msm.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MsmParams {
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
    /// 1: store the optimized quantization of the moments; 0: the raw powers.
    pub quantized: u32,
    /// Padding.
    pub _pad: [u32; 3],
}

/// Parameters of `kernels/csm.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CsmParams {
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
    /// Index of the map `dst0` receives in the light's sequence of maps: the ⌈M/2⌉ CSM basis
    /// maps (`technique::csm_maps`), then (CSSM) the CSM-Z maps (`technique::csm_z_maps`) or the
    /// moment map (MSM's quantized moments).
    pub first_map: u32,
    /// Maps this dispatch writes (`dst0` … `dst<maps − 1>`; 1 to [`CSM_OUTPUTS`]).
    pub maps: u32,
    /// Total terms M (a pair past M is written as zeros).
    pub terms: u32,
    /// 1: the map after the CSM basis maps is MSM's quantized moments `(z, z², z³, z⁴)` (CSSM's
    /// moment search), not the CSM-Z maps.
    pub moments: u32,
}

/// Storage-texture outputs of `kernels/csm.wgsl` (`dst0` … `dst3`): what WebGPU's default
/// `max_storage_textures_per_shader_stage` allows every device, so one read of the depth
/// writes up to four basis maps.
pub const CSM_OUTPUTS: u32 = 4;

/// Parameters of `kernels/evsm.wgsl` and `kernels/esm.wgsl` (mirror their `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ExpParams {
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
    /// c⁺ (EVSM) or c (ESM).
    pub exp_pos: f32,
    /// c⁻ (EVSM4).
    pub exp_neg: f32,
    /// ESM: 1 stores `exp(c (z − 1))` (for a summed-area table, which sums linearly) instead
    /// of the log moment `c z`.
    pub linear: u32,
    /// Padding.
    pub _pad: u32,
}

impl ExpParams {
    /// Exponents `pos`, `neg` on an orthographic depth buffer.
    pub fn new(exp_pos: f32, exp_neg: f32) -> Self {
        Self {
            depth: LinearizeParams::ORTHOGRAPHIC,
            exp_pos,
            exp_neg,
            linear: 0,
            _pad: 0,
        }
    }
}

/// Frame constants of `kernels/shade.wgsl` (mirrors its `Frame`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameGpu {
    /// Image size.
    pub size: [u32; 2],
    /// Number of lights.
    pub light_count: u32,
    /// 1 when the ray fields hold the camera (pixel footprints), 0 for the probe.
    pub has_camera: u32,
    /// Ambient colour.
    pub ambient: [f32; 3],
    /// Padding.
    pub _pad1: f32,
    /// Background colour.
    pub background: [f32; 3],
    /// Padding.
    pub _pad2: f32,
    /// Eye position.
    pub camera: [f32; 3],
    /// Padding.
    pub _pad3: f32,
    /// Unnormalized view ray through pixel corner (0, 0).
    pub ray00: [f32; 3],
    /// Padding.
    pub _pad4: f32,
    /// Ray change per pixel in x: pixel (x, y)'s ray is `ray00 + (x + ½)·ray_dx + (y + ½)·ray_dy`.
    pub ray_dx: [f32; 3],
    /// Padding.
    pub _pad5: f32,
    /// Ray change per pixel in y.
    pub ray_dy: [f32; 3],
    /// Padding.
    pub _pad6: f32,
}

/// Vertex as uploaded: keep in sync with `VsIn` in `kernels/shared/vertex.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// World position.
    pub position: [f32; 3],
    /// World normal.
    pub normal: [f32; 3],
    /// Index into the scene's material (object colour) table.
    pub material: u32,
}

#[cfg(test)]
mod tests {
    use super::TECHNIQUE_IDS;

    /// Every `TECHNIQUE_*` constant of `kernels/shared/light.wgsl` has the value of the Rust
    /// constant of the same name, and the two lists hold the same names.
    #[test]
    fn technique_ids_match_the_wgsl_constants() {
        let wgsl = include_str!("../kernels/shared/light.wgsl");
        let parsed: Vec<(String, u32)> = wgsl
            .lines()
            .filter_map(|line| {
                let rest = line.trim().strip_prefix("const TECHNIQUE_")?;
                let (name, value) = rest.split_once(": u32 = ")?;
                let value = value
                    .trim_end_matches(';')
                    .trim_end_matches('u')
                    .parse()
                    .ok()?;
                Some((format!("TECHNIQUE_{name}"), value))
            })
            .collect();
        let rust: Vec<(String, u32)> = TECHNIQUE_IDS
            .iter()
            .map(|(n, v)| (n.to_string(), *v))
            .collect();
        assert_eq!(parsed, rust);
    }
}
