//! The technique registry: one [`TechniqueDef`] per scene name, each in its own file owning its
//! name, WGSL id, parameter table (key, range, default, doc), how its [`Technique`] is built
//! from checked values and read back, the clamps it applies and its example scene. Front ends
//! iterate [`REGISTRY`] or look a technique up ([`by_name`], [`of`]) instead of matching on
//! it. The graph nodes, GPU fields and visibility calls of every technique are in
//! `nodes.rs`, `light_gpu.rs` and `shade.rs`.

mod cascade_shade;
mod code_values;
mod csm;
mod csm_sat;
mod cssm;
mod encoding;
mod esm;
mod evsm;
mod hard;
mod light_gpu;
mod msm;
mod msm_soft;
mod nodes;
mod parameters_doc;
pub mod params;
mod pcf;
mod pcss;
mod reach;
mod second_depth;
mod shade;
mod smrt;
mod sweep_plan;
mod vsm;
mod vssm;

use crate::model::{Light, ParamSource, ParamSpec, ParamValues, Technique};
use crate::wgsl_mirrors::LightGpu;
pub(crate) use cascade_shade::pick_and_blend;
pub use cascade_shade::{CascadeGroup, shade_key_cascaded};
pub use csm::{basis_sequence, csm_maps, csm_z_channels, csm_z_maps, search_maps};
pub use csm_sat::{
    CsmBasis, CsmSatParams, INTERLEAVED_MAX_WIDTH, MomentTable, Moments, add_csm_tables,
    add_moment_table, basis_interleave, basis_table,
};
use encoding::no_encoding;
pub use encoding::{ChannelNaming, Encoding, MapChannels, encoding, map_kinds};
use light_gpu::unit_range;
pub use light_gpu::{sat_coding, sat_variant, soft_lookup_area, soft_max_width, soft_width_cap};
pub use msm::msm_quantized;
pub use nodes::LightNodes;
pub use nodes::{
    PACKED_MAP_TYPE, add_light_nodes, depth_name, float_moments_format, linear_name, map_channels,
    map_tables, map_type, maps_packed, moments_format,
};
pub use parameters_doc::parameters_markdown;
pub use params::{Clamp, ClampReason, sat_exponent_limit};
pub use reach::{cascade_guard, reach, texels_past_radius};
pub use second_depth::{peels, second_depth_name};
pub use shade::{
    SAT_SAMPLER, ShadeInput, VisibilityBody, map_binding, shade_key, shading_block,
    shading_block_cascaded, visibility_body,
};
pub use sweep_plan::{SweepPlan, SweepVariant, SweptStorages, SweptTerms};

/// One technique as the front ends see it (a struct of plain functions, so the registry is a
/// static table).
#[derive(Debug)]
pub struct TechniqueDef {
    /// The scene name (`technique = "…"`).
    pub name: &'static str,
    /// The id the shading kernel reads (`LightGpu::technique`, `wgsl_mirrors::TECHNIQUE_*`).
    pub id: u32,
    /// One line for documentation.
    pub doc: &'static str,
    /// Its keys, table by table (shared tables from [`params`], then its own); the common
    /// biases ([`params::COMMON`]) are every technique's and not repeated here.
    pub params: &'static [&'static [ParamSpec]],
    /// The technique of checked values.
    pub build: fn(&ParamValues) -> Technique,
    /// The values of a technique of this name (the keys that apply to it), so that a
    /// technique built in code is checked by the same tables.
    pub values: fn(&Technique) -> ParamValues,
    /// Values past what the technique keeps accurate, clamped after checking (EVSM's and
    /// ESM's exponents), each recorded.
    pub clamp: fn(&mut Technique, &mut Vec<Clamp>),
    /// Its fields of the light's GPU description (`LightGpu::new` fills the id, the
    /// matrices, the filter's, the table's and the soft search cap's fields).
    pub gpu: fn(&Technique, &mut LightGpu),
    /// The nodes it adds to the light's graph after the depth and linear depth, and what the
    /// shading reads.
    pub nodes: fn(&mut LightNodes) -> ShadeInput,
    /// Its visibility in the shading block: modules and statements with the light's maps
    /// bound as given.
    pub visibility: fn(&Light, &[String]) -> VisibilityBody,
    /// What its visibility code depends on besides its name, table, footprint and maps (the
    /// shading kernel's cache key: PCF's hardware kernel, CSM's terms).
    pub variant: fn(&Technique) -> String,
    /// Per channel, the range of the values its summed-area table sums (`sat_coding`).
    pub value_range: fn(&Technique) -> ([f32; 4], [f32; 4]),
    /// Whether it needs an area light (`size` > 0): PCSS and the soft techniques.
    pub area_light: bool,
    /// How far around a receiver's texel its lookup reads a point light's face, in face texels
    /// (`face`: the face's side), counting what its prefilter folded into the texels it reads:
    /// the faces' guard band rests on it ([`reach()`]). An error says why a face cannot bound it.
    pub reach: fn(&Technique, u32) -> Result<f32, String>,
    /// The texels its lookup reads past its search radius (capped at `max_search`): PCSS's taps
    /// take the nearest texel (1), a table's window rounds its edges to texels and snaps the
    /// blocker window outward (2); `None` without a search. A point light's reach and a
    /// cascade's guard band ([`cascade_guard`]) add it.
    pub texels_past_radius: Option<f32>,
    /// Whether it works in cascades (`cascades` > 1): `Err` says why not.
    pub cascades: Result<(), &'static str>,
    /// The encoding its maps store (the prefiltered techniques), with the parameters its f64
    /// reference takes; `None` for techniques that read the depth or build a table from it.
    pub encoding: fn(&Technique) -> Option<Encoding>,
    /// The channel names of the maps it adds, by resource kind (`shadowgraph dump`).
    pub maps: &'static [MapChannels],
    /// A scene that shows it.
    pub example: &'static str,
    /// Its colour in the evaluation's plots (sRGB), so families read at a glance.
    pub colour: [u8; 3],
    /// How the evaluation sweeps it.
    pub sweep: SweepPlan,
}

/// Every technique, in the order scene errors list them.
pub static REGISTRY: &[&TechniqueDef] = &[
    &hard::DEF,
    &pcf::DEF,
    &pcss::DEF,
    &vsm::DEF,
    &evsm::EVSM2,
    &evsm::EVSM4,
    &esm::DEF,
    &msm::DEF,
    &csm::DEF,
    &cssm::DEF,
    &vssm::DEF,
    &msm_soft::DEF,
    &smrt::DEF,
    &second_depth::MIDPOINT,
    &second_depth::SECOND_DEPTH,
];

/// Every technique's scene name, in registry order.
pub fn names() -> Vec<&'static str> {
    REGISTRY.iter().map(|d| d.name).collect()
}

/// The technique named `name` in scene files.
pub fn by_name(name: &str) -> Option<&'static TechniqueDef> {
    REGISTRY.iter().copied().find(|d| d.name == name)
}

/// The registry entry of `t`.
pub fn of(t: &Technique) -> &'static TechniqueDef {
    by_name(t.name()).expect("every technique's name is registered")
}

/// Checks `source` against technique `def`'s tables and builds it, with the clamps applied.
pub fn check_and_build<S: ParamSource>(
    def: &TechniqueDef,
    source: &S,
) -> Result<(Technique, Vec<Clamp>), S::Error> {
    let values = crate::model::check_params(def.params, source)?;
    let mut t = (def.build)(&values);
    let mut clamps = Vec::new();
    (def.clamp)(&mut t, &mut clamps);
    Ok((t, clamps))
}

/// `def` with every key at its default.
pub fn default_of(def: &TechniqueDef) -> Technique {
    let values = crate::model::check_params(def.params, &params::Given(&ParamValues::default()));
    (def.build)(&values.unwrap_or_default())
}

/// `def` with `values` over its defaults, taken as they are: for a technique built in code,
/// whose values a later check reports (`None` when a value is of another kind than its key's or
/// a key is set where it does not apply).
pub fn build_with(def: &TechniqueDef, values: &ParamValues) -> Option<Technique> {
    let values = crate::model::check_params(def.params, &params::Loose(values)).ok()?;
    Some((def.build)(&values))
}

/// The technique named `name` with `values` over its defaults, taken as they are (a later
/// check reports them); `None` for a name the registry does not know or values its tables
/// cannot hold.
pub fn named(name: &str, values: &[(&'static str, crate::model::ParamValue)]) -> Option<Technique> {
    build_with(by_name(name)?, &ParamValues(values.to_vec()))
}

/// `t` with `values` set over its own (the keys it has), rebuilt by its entry; `None` when a
/// key does not apply to it.
pub fn with_values(
    t: &Technique,
    values: &[(&'static str, crate::model::ParamValue)],
) -> Option<Technique> {
    let def = of(t);
    let mut v = (def.values)(t);
    for &(key, value) in values {
        v.get(key)?;
        v.set(key, value);
    }
    build_with(def, &v)
}

/// The value of key `key` of `t` (its entry's `values`); `None` where the key does not apply.
pub fn value(t: &Technique, key: &str) -> Option<crate::model::ParamValue> {
    (of(t).values)(t).get(key)
}

/// Whether option `name` of key `key` is one `def` accepts.
pub fn accepts(def: &TechniqueDef, key: &str, name: &str) -> bool {
    def.params.iter().flat_map(|t| t.iter()).any(|s| {
        s.key == key && matches!(s.kind, crate::model::ParamKind::Choice(o) if o.contains(&name))
    })
}

/// No GPU fields besides the common ones.
fn no_gpu(_: &Technique, _: &mut LightGpu) {}

/// Nothing besides the name.
fn no_variant(_: &Technique) -> String {
    String::new()
}

/// No clamps.
fn no_clamp(_: &mut Technique, _: &mut Vec<Clamp>) {}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every registered technique round-trips: its defaults' values build it again, and its
    /// name is its technique's.
    #[test]
    fn defaults_round_trip_through_values() {
        for def in REGISTRY {
            let t = default_of(def);
            assert_eq!(t.name(), def.name);
            let values = (def.values)(&t);
            let again =
                crate::model::check_params(def.params, &params::Given(&values)).expect(def.name);
            assert_eq!((def.build)(&again), t, "{}", def.name);
        }
    }

    /// Setting a number through the entry (`with_values`, as the stability suite sets MSM's
    /// moment bias) changes that key and no other, on every technique's defaults and on MSM
    /// with a blur at f16.
    #[test]
    fn with_values_changes_only_its_key() {
        use crate::model::ParamValue::Float;
        let msm_f16 = with_values(
            &default_of(&msm::DEF),
            &[("format", crate::model::ParamValue::Choice("f16"))],
        );
        let cases = REGISTRY.iter().map(|d| default_of(d)).chain(msm_f16);
        for t in cases {
            let before = (of(&t).values)(&t);
            for &(key, value) in &before.0 {
                let Float(x) = value else { continue };
                let y = 0.5 * x + 0.25;
                let changed = with_values(&t, &[(key, Float(y))]).expect(key);
                let after = (of(&changed).values)(&changed);
                for &(k, v) in &before.0 {
                    let want = if k == key { Float(y) } else { v };
                    assert_eq!(after.get(k), Some(want), "{} {key}: {k}", t.name());
                }
            }
        }
    }
}
