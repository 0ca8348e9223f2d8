//! `esm`: exponential shadow maps (Annen et al. 2008), `c·z` filtered in log space; always f32
//! (f16 `c·z` would cost percent-level visibility error).

use super::TechniqueDef;
use super::csm_sat::{Moments, moment_table_nodes};
use super::encoding::{ChannelNaming, Encoding, MapChannels};
use super::no_variant;
use super::params::{
    Clamp, ClampReason, FILTER, clamp, filter, filter_values, float, sat_exponent_limit,
};
use super::shade::{ShadeInput, prefiltered};
use super::sweep_plan::{SweepPlan, SweptStorages};
use crate::filter::BlurMode;
use crate::kernels::KernelId;
use crate::model::{ParamSpec, ParamValue, ParamValues, Storage, Technique};
use crate::wgsl_mirrors::ExpParams;
use crate::wgsl_mirrors::TECHNIQUE_ESM;

const PARAMS: &[ParamSpec] = &[float(
    "exponent",
    0.01,
    1e4,
    80.0,
    "exponent c (past 80 the log-space blur takes `blur_log_wide`, which also handles texels spread wider than 80)",
)];

fn values(t: &Technique) -> ParamValues {
    let mut out = ParamValues::default();
    if let Technique::Esm { filter, exponent } = t {
        filter_values(filter, &mut out);
        out.set("exponent", ParamValue::Float(*exponent));
    }
    out
}

/// The exponent clamped to what a summed-area table keeps accurate.
fn clamp_exponent(t: &mut Technique, out: &mut Vec<Clamp>) {
    if let Technique::Esm { filter, exponent } = t {
        let sat = sat_exponent_limit(filter, true);
        *exponent = clamp("exponent", *exponent, sat, ClampReason::Sat, out);
    }
}

/// The log moment `c z`, or for a summed-area table (which sums linearly) `exp(c (z − 1))`,
/// filtered in log space.
fn nodes(n: &mut super::LightNodes) -> ShadeInput {
    let Technique::Esm { filter, exponent } = n.light.shadow.technique else {
        return n.one(n.depth.clone());
    };
    // Through a summed-area table the moment exp(c (z − 1)) is computed in the table's own
    // tile passes, never stored.
    if let Some(table) = moment_table_nodes(n, Moments::Esm, [exponent, 0.0], Storage::F32) {
        return table;
    }
    let mut params = ExpParams::new(exponent, 0.0);
    params.depth = n.lin;
    params.linear = u32::from(matches!(filter, crate::model::Filter::Sat { .. }));
    let format = wgpu::TextureFormat::R32Float;
    n.encoded(
        KernelId::Esm,
        format,
        bytemuck::bytes_of(&params),
        // c·z lies in [0, c].
        BlurMode::log_sum_exp(exponent),
    )
}

/// ESM's `c·z`.
fn esm_encoding(t: &Technique) -> Option<Encoding> {
    match *t {
        Technique::Esm { exponent, .. } => Some(Encoding::Esm { exponent }),
        _ => None,
    }
}

/// ESM's map (`light{i}.esm`), stored in log form `c·z = log(exp(c·z))` so that blurring
/// (log-sum-exp) never overflows.
const ESM_MAPS: MapChannels = MapChannels {
    kind: "esm",
    naming: ChannelNaming::Fixed(&["log_exp"]),
};

/// `esm`.
pub(super) static DEF: TechniqueDef = TechniqueDef {
    name: "esm",
    id: TECHNIQUE_ESM,
    doc: "exponential shadow maps, filtered in log space",
    params: &[FILTER, PARAMS],
    build: |v| Technique::Esm {
        filter: filter(v),
        exponent: v.float("exponent"),
    },
    values,
    gpu: |t, g| {
        if let Technique::Esm { exponent, .. } = *t {
            g.exp_pos = exponent;
            g.moments = 1;
        }
    },
    nodes,
    visibility: |light, maps| {
        prefiltered(light, maps, "shared/vis_esm", "vis_esm", "vis_esm_of_sat")
    },
    variant: no_variant,
    // Stored linearly for a table: `exp(c (z − 1)) ∈ [e^{−c}, 1]`, coded as ±1.
    value_range: |_| ([-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]),
    clamp: clamp_exponent,
    area_light: false,
    reach: super::reach::filtered,
    texels_past_radius: None,
    cascades: Ok(()),
    encoding: esm_encoding,
    maps: &[ESM_MAPS],
    example: "scenes/techniques/esm.toml",
    colour: [0x94, 0x67, 0xbd],
    sweep: SweepPlan::Prefiltered {
        storages: SweptStorages::F32Only,
        terms: None,
    },
};
