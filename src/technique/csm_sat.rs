//! CSM, CSSM and the moment techniques through summed-area tables, the representation never
//! stored: the layered tables of [`crate::sat::layers`] whose tile kernels
//! (`kernels/csm_sat_tile_sums.wgsl`, `kernels/csm_sat_tiles.wgsl` and their f32 variants)
//! compute each map from the depth on the fly, one layer a map of the light's sequence
//! (`kernels/shared/csm_maps.wgsl`); the moments of MSM, VSM, EVSM and ESM likewise, one layer
//! by their own kernels (`kernels/msm_sat_*.wgsl`, `vsm_sat_*`, `evsm_sat_*`, `esm_sat_*`).

use super::csm::basis_sequence;
use super::nodes::{LightNodes, float_moments_format, moments_format};
use super::shade::ShadeInput;
use crate::graph::{Graph, SizeRule};
use crate::kernels::KernelId;
use crate::model::{CssmSearch, Light, Storage, Technique};
use crate::sat::layers::{LayeredSat, add_layered_sat};
use crate::wgsl_mirrors::LinearizeParams;
use crate::{
    model::SatVariant,
    sat::{SatCoding, SatParams},
};

/// Parameters of the layered CSM table kernels (mirrors `CsmSatParams` in
/// `kernels/shared/csm_sat_params.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CsmSatParams {
    /// The tables' coding (`layers`: every layer of the stack).
    pub sat: SatParams,
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
    /// The map of the light's sequence workgroup z = 0 computes (z adds to it).
    pub first_map: u32,
    /// Maps this dispatch computes (workgroups along z).
    pub maps: u32,
    /// Total terms M.
    pub terms: u32,
    /// 1: each basis value rounded to f16, as f16 storage of the map would hold it.
    pub f16: u32,
    /// 1: the layer after CSM's is MSM's quantized moments (CSSM's moment search).
    pub moments: u32,
    /// 1: each value rounded to 16-bit unorm, as unorm16 storage of the map would hold it.
    pub unorm16: u32,
    /// EVSM's c⁺, ESM's c (a layer of moments, [`add_moment_table`]).
    pub exp_pos: f32,
    /// EVSM's c⁻.
    pub exp_neg: f32,
    /// Tables a texture, interleaved along x (`LayeredSat::interleave`; pass 3 stores table
    /// `first_map + z` at slot `(first_map + z) mod interleave` of `dst⌊z / interleave⌋`).
    pub interleave: u32,
    /// Padding to a 16-byte multiple.
    pub pad: [u32; 3],
}

/// What the layered tables of one light's basis hold ([`add_csm_tables`]).
#[derive(Clone, Copy, Debug)]
pub struct CsmBasis {
    /// Terms M.
    pub terms: u32,
    /// With the maps of CSSM's blocker search (the CSM-Z maps or MSM's moments), after
    /// the ⌈M/2⌉ CSM maps.
    pub search: Option<CssmSearch>,
    /// The representation's storage: f16 rounds every basis value as an f16 map would.
    pub storage: Storage,
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
    /// Tables a texture, interleaved along x ([`basis_interleave`]; 1: a texture each).
    pub interleave: u32,
}

/// The widest texture the interleaved tables may make: WebGPU's default
/// `max_texture_dimension_2d`, which every adapter allows (so the layout, and the shading
/// code that reads it, do not depend on the device).
pub const INTERLEAVED_MAX_WIDTH: u32 = 8192;

/// Tables a texture for `layers` tables of a map `width` texels wide coded as `variant`:
/// fixed-point tables (read with loads) as many as fit in [`INTERLEAVED_MAX_WIDTH`], f32
/// tables (read with filtered fetches, which would blend interleaved neighbours) one.
pub fn basis_interleave(width: u32, layers: u32, variant: SatVariant) -> u32 {
    match variant {
        SatVariant::Fixed => (INTERLEAVED_MAX_WIDTH / width.max(1)).clamp(1, layers.max(1)),
        SatVariant::Float => 1,
    }
}

/// Where table `k` of a light's `count` basis tables lies: the texture `maps[k / n]`, the
/// tables it holds (`n`, the last texture the rest) and its slot there, `k mod n` (`n` =
/// `interleave`, the textures as [`add_csm_tables`] returned them).
pub fn basis_table(maps: &[String], interleave: u32, count: usize, k: usize) -> (&str, u32, u32) {
    let n = interleave.max(1) as usize;
    let held = n.min(count.saturating_sub(k / n * n));
    let map = maps.get(k / n).map_or("", String::as_str);
    (map, held as u32, (k % n) as u32)
}

/// Tables a texture of light `light`'s basis tables ([`basis_interleave`] for `csm` through
/// tables and `cssm`; 1 for every other light or without tables): what [`csm_sat_nodes`]
/// builds and the shading code reads ([`basis_refs`]).
pub(super) fn light_interleave(light: &Light) -> u32 {
    let (terms, search) = match light.shadow.technique {
        Technique::Csm { terms, .. } => (terms, None),
        Technique::Cssm { terms, search, .. } => (terms, Some(search)),
        _ => return 1,
    };
    let Ok(Some(coding)) = super::light_gpu::sat_coding(light) else {
        return 1;
    };
    let layers = basis_sequence(terms, search).len() as u32;
    basis_interleave(light.map_dims().0, layers, coding.variant)
}

/// One basis table as the shading code reads it.
pub(super) struct TableRef {
    /// The binding of the texture that holds it.
    pub map: String,
    /// For a fixed-point table, its `SatLayer` in that texture (`kernels/shared/sat.wgsl`,
    /// read by the `sat_layer_*` lookups); `None` for an f32 table (a texture each).
    pub layer: Option<String>,
}

/// Light `light`'s `count` basis tables (CSM's, then the search's) with their textures bound
/// as `maps` ([`csm_sat_nodes`]' textures, in order).
pub(super) fn basis_refs(light: &Light, maps: &[String], count: usize) -> Vec<TableRef> {
    let fixed = super::light_gpu::sat_variant(light) == Some(SatVariant::Fixed);
    let n = light_interleave(light);
    (0..count)
        .map(|k| {
            let (map, held, slot) = basis_table(maps, n, count, k);
            TableRef {
                map: map.to_string(),
                layer: fixed.then(|| format!("SatLayer({held}, {slot})")),
            }
        })
        .collect()
}

/// Light `light`'s basis maps as `(resource, channels)`: `light{light}.csm<chunk>` (two terms
/// each), then with `search` its maps (`technique::csm::search_maps`).
/// They are declared, the size of `depth`, in the format an f32 or f16 map of their channels
/// would have (what `map_channels` reads), but never planned: only their tables are.
fn basis_maps(graph: &mut Graph, light: usize, depth: &str, b: &CsmBasis) -> Vec<(String, u32)> {
    basis_sequence(b.terms, b.search)
        .into_iter()
        .map(|(name, channels)| {
            let size = SizeRule::Reduced {
                of: depth.to_string(),
                shift: 0,
            };
            let format = float_moments_format(b.storage, channels);
            let map = graph.resource(format!("light{light}.{name}"), format, size, Some(light));
            (map, channels)
        })
        .collect()
}

/// Adds the summed-area tables of light `light`'s basis maps (`b`; the maps as in
/// `basis_maps`, each table `<map>.sat`) coded as `coding` to `graph`, computed from the
/// imported depth `depth` (read as `texture_2d<f32>`: a depth or an r32float texture) by one
/// layered table ([`add_layered_sat`]): `2 + ⌈maps / 4n⌉` dispatches (n = `b.interleave`),
/// the depth read once a layer in each tile pass. Returns the textures that hold the tables,
/// CSM's then the search's, `b.interleave` a texture ([`basis_table`] finds one).
pub fn add_csm_tables(
    graph: &mut Graph,
    light: usize,
    depth: &str,
    b: &CsmBasis,
    coding: SatCoding,
) -> Vec<String> {
    let tables = basis_maps(graph, light, depth, b);
    let template = CsmSatParams {
        sat: coding.params(4, 0),
        depth: b.depth,
        first_map: 0,
        maps: 0,
        terms: b.terms,
        f16: u32::from(b.storage == Storage::F16),
        moments: u32::from(b.search == Some(CssmSearch::Moments)),
        unorm16: 0,
        exp_pos: 0.0,
        exp_neg: 0.0,
        interleave: b.interleave.max(1),
        pad: [0; 3],
    };
    let kernels = match coding.variant {
        SatVariant::Fixed => [KernelId::CsmSatTileSums, KernelId::CsmSatTiles],
        SatVariant::Float => [KernelId::CsmSatTileSumsF32, KernelId::CsmSatTilesF32],
    };
    depth_tables(
        graph, light, depth, "csm", &tables, kernels, template, coding,
    )
}

/// Adds the summed-area table of light `light`'s moments `m.moments` ([`Moments`]: what the
/// encoding kernel of the technique would store), rounded as `m.storage` would hold them,
/// coded as `coding`, computed from the depth `depth` in the table's own tile passes: one layer
/// of [`add_layered_sat`], 3 dispatches, the depth read twice and the moments never stored.
/// The map `light{light}.<stem>` (`msm`, `vsm`, `evsm`, `esm`) is declared in its storage's
/// format but never planned. Returns `light{light}.<stem>.sat`.
pub fn add_moment_table(
    graph: &mut Graph,
    light: usize,
    depth: &str,
    m: &MomentTable,
    coding: SatCoding,
) -> String {
    let size = SizeRule::Reduced {
        of: depth.to_string(),
        shift: 0,
    };
    let (stem, channels) = match m.moments {
        Moments::Msm => ("msm", 4),
        Moments::Vsm => ("vsm", 2),
        Moments::Evsm { four } => ("evsm", if four { 4 } else { 2 }),
        Moments::Esm => ("esm", 1),
    };
    let format = moments_format(m.storage, channels);
    let map = graph.resource(format!("light{light}.{stem}"), format, size, Some(light));
    let template = CsmSatParams {
        sat: coding.params(channels, 0),
        depth: m.depth,
        first_map: 0,
        maps: 0,
        terms: 0,
        f16: u32::from(m.storage == Storage::F16),
        moments: 0,
        unorm16: u32::from(m.storage == Storage::Unorm16),
        exp_pos: m.exp[0],
        exp_neg: m.exp[1],
        interleave: 1,
        pad: [0; 3],
    };
    let kernels = match (m.moments, coding.variant) {
        (Moments::Msm, SatVariant::Fixed) => [KernelId::MsmSatTileSums, KernelId::MsmSatTiles],
        (Moments::Msm, SatVariant::Float) => {
            [KernelId::MsmSatTileSumsF32, KernelId::MsmSatTilesF32]
        }
        (Moments::Vsm, SatVariant::Fixed) => [KernelId::VsmSatTileSums, KernelId::VsmSatTiles],
        (Moments::Vsm, SatVariant::Float) => {
            [KernelId::VsmSatTileSumsF32, KernelId::VsmSatTilesF32]
        }
        (Moments::Evsm { .. }, SatVariant::Fixed) => {
            [KernelId::EvsmSatTileSums, KernelId::EvsmSatTiles]
        }
        (Moments::Evsm { .. }, SatVariant::Float) => {
            [KernelId::EvsmSatTileSumsF32, KernelId::EvsmSatTilesF32]
        }
        (Moments::Esm, SatVariant::Fixed) => [KernelId::EsmSatTileSums, KernelId::EsmSatTiles],
        (Moments::Esm, SatVariant::Float) => {
            [KernelId::EsmSatTileSumsF32, KernelId::EsmSatTilesF32]
        }
    };
    let tables = depth_tables(
        graph,
        light,
        depth,
        stem,
        &[(map, channels)],
        kernels,
        template,
        coding,
    );
    tables.into_iter().next().unwrap_or_default()
}

/// Which moments [`add_moment_table`] sums.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Moments {
    /// MSM's four, quantized.
    Msm,
    /// VSM's two, (z, z² + ¼ (∂z/∂x² + ∂z/∂y²)).
    Vsm,
    /// EVSM's four, (exp(c⁺z'), its square, −exp(−c⁻z'), its square) with z' = 2z − 1, or the
    /// first two.
    Evsm {
        /// All four (`evsm4`), else the first two.
        four: bool,
    },
    /// ESM's one, exp(c (z − 1)) (the linear moment a table sums).
    Esm,
}

/// What [`add_moment_table`] sums.
#[derive(Clone, Copy, Debug)]
pub struct MomentTable {
    /// Which moments.
    pub moments: Moments,
    /// EVSM's (c⁺, c⁻), ESM's (c, unused); unused otherwise.
    pub exp: [f32; 2],
    /// The moments' storage: f16 and unorm16 round every value as such a map would.
    pub storage: Storage,
    /// The depth buffer's linearization.
    pub depth: LinearizeParams,
}

/// The layered tables of `tables` (`(map, channels)`, in layer order) computed from `depth`
/// by the depth-sourced tile kernels `kernels` (pass 1, pass 3) with parameters `template`
/// (its `first_map`, `maps` and `sat` set per dispatch), nodes named `light{light}.{stem}.sat.*`.
#[allow(clippy::too_many_arguments)]
fn depth_tables(
    graph: &mut Graph,
    light: usize,
    depth: &str,
    stem: &str,
    tables: &[(String, u32)],
    kernels: [KernelId; 2],
    template: CsmSatParams,
    coding: SatCoding,
) -> Vec<String> {
    let params = move |sat: SatParams, first_map: u32, maps: u32| {
        let p = CsmSatParams {
            sat,
            first_map,
            maps,
            ..template
        };
        bytemuck::bytes_of(&p).to_vec()
    };
    let prefix = format!("light{light}.{stem}");
    let sat = LayeredSat {
        source: depth,
        prefix: &prefix,
        tables,
        kernels,
        params: &params,
        coding,
        interleave: template.interleave,
    };
    add_layered_sat(graph, light, &sat)
}

/// [`add_csm_tables`] for the light of `n`, from its depth.
pub(super) fn csm_sat_nodes(
    n: &mut LightNodes,
    storage: Storage,
    terms: u32,
    search: Option<CssmSearch>,
    coding: SatCoding,
) -> Vec<String> {
    let b = CsmBasis {
        terms,
        search,
        storage,
        depth: n.lin,
        interleave: light_interleave(n.light),
    };
    let depth = n.depth.clone();
    add_csm_tables(n.graph, n.i, &depth, &b, coding)
}

/// The light of `n` through a summed-area table (`filter = "sat"` or a soft technique; its
/// coding errors `render::plan_lights` reports first): its table of `moments` (exponents `exp`,
/// storage `storage`) computed from its depth ([`add_moment_table`]); `None` without a table.
pub(super) fn moment_table_nodes(
    n: &mut LightNodes,
    moments: Moments,
    exp: [f32; 2],
    storage: Storage,
) -> Option<ShadeInput> {
    let Ok(Some(coding)) = super::light_gpu::sat_coding(n.light) else {
        return None;
    };
    let m = MomentTable {
        moments,
        exp,
        storage,
        depth: n.lin,
    };
    let depth = n.depth.clone();
    let table = add_moment_table(n.graph, n.i, &depth, &m, coding);
    Some(n.one(table))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Five tables two a texture: the last texture holds one, at slot 0; fixed-point tables
    /// interleave as many as fit in 8192 texels, f32 tables never.
    #[test]
    fn tables_find_their_texture_width_and_slot() {
        let maps: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
        let at: Vec<(&str, u32, u32)> = (0..5).map(|k| basis_table(&maps, 2, 5, k)).collect();
        assert_eq!(
            at,
            [
                ("a", 2, 0),
                ("a", 2, 1),
                ("b", 2, 0),
                ("b", 2, 1),
                ("c", 1, 0)
            ]
        );
        assert_eq!(basis_table(&maps[..1], 1, 1, 0), ("a", 1, 0));
        let fixed = |w| basis_interleave(w, 5, SatVariant::Fixed);
        assert_eq!(
            [512, 1638, 1639, 2048, 4096, 8192, 16384].map(fixed),
            [5, 5, 4, 4, 2, 1, 1]
        );
        assert_eq!(basis_interleave(512, 5, SatVariant::Float), 1);
        assert_eq!(basis_interleave(512, 9, SatVariant::Fixed), 9);
    }
}
