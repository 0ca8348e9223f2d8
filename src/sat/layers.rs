//! Layered summed-area tables: the tables of several representations that tile kernels
//! compute on the fly from one shared source (the CSM and CSM-Z basis maps from the depth),
//! so the representations are never stored, built by one pass of each kind over all layers.
//!
//! [`add_layered_sat`] adds, for `L` tables of a `width × height` source:
//!
//! 1. `<prefix>.sat.tile_sums`: the source kernel's pass 1 over `L` workgroups along z (one
//!    per layer); the edges of table z in band z of `.col_part` (`width × L·⌈height / TILE⌉`)
//!    and `.row_part` (`L·⌈width / TILE⌉ × height`), [`SizeRule::Stacked`].
//! 2. `<prefix>.sat.carries`: `sat_carries` over every band at once (`SatParams::layers = L`,
//!    workgroup z on band z), into `.col_carry` and `.row_carry`, shaped as the edges.
//! 3. `<prefix>.sat.<g>`: the source kernel's pass 3, [`LAYERED_SAT_OUTPUTS`] textures a
//!    dispatch (`dst0` … `dst3`, workgroup z on texture z, its tables one after another):
//!    what WebGPU's default limit of storage textures a stage allows every device.
//!
//! With [`LayeredSat::interleave`] `n` > 1 the tables are stored `n` to a texture,
//! interleaved along x ([`Graph::interleaved`], `<prefix>.sat.layers<s>`): texel (x, y) of
//! table k at (x·n + k mod n, y) of texture ⌊k / n⌋. A lookup that reads the same corner of
//! several tables (CSSM's filter reads five) then reads one run of memory instead of one
//! cache line a table; pass 3 writes `4·n` tables a dispatch, a workgroup all of a texture's
//! tables of its tile (one workgroup a table wrote every cache line `n` times, each time after
//! the others had left it: 1.7× slower pass 3 on llvmpipe). Only tables read with loads can
//! be interleaved (a filtered fetch would blend neighbouring tables).
//!
//! That is `2 + ⌈L / 4n⌉` dispatches. Per texel: the source read `2L` times (once a layer per
//! tile pass; both sweeps of pass 3 share a tile), each table written once, and the stacked
//! edges and carries (`8·L / TILE` texels of 4 B a channel of the widest table). Each table is
//! exactly the one [`super::add_sat`] builds of the representation the kernel computes: the tile passes share
//! their scans with `sat_tile_sums` / `sat_tiles` (`kernels/shared/sat_tile_*.wgsl`), so in
//! fixed point a table is bit-identical to the integer reference of the codes the kernel
//! computes.

use super::{SAT_TILE, SatCoding, SatParams, carries_dispatch, named, sat_name};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::SatVariant;

/// Tables one pass-3 dispatch of a layered table writes (`dst0` … `dst3`).
pub const LAYERED_SAT_OUTPUTS: u32 = 4;

/// The layered tables a node builder asks for.
pub struct LayeredSat<'a> {
    /// The resource the tile kernels read (bound as `src`).
    pub source: &'a str,
    /// Prefix of the intermediates' and nodes' names (`<prefix>.sat.tile_sums`, …).
    pub prefix: &'a str,
    /// Per layer, the representation's name (the table is `<name>.sat`, [`sat_name`]) and
    /// its channels (1–4; the table's format).
    pub tables: &'a [(String, u32)],
    /// The kernels of pass 1 and pass 3 for the coding's variant.
    pub kernels: [KernelId; 2],
    /// The tile kernels' parameters for layers `first .. first + count`, given the tables'
    /// [`SatParams`] (its `layers` set to every layer), which they must start with.
    pub params: &'a dyn Fn(SatParams, u32, u32) -> Vec<u8>,
    /// The tables' coding (the same for every layer).
    pub coding: SatCoding,
    /// Tables a texture, interleaved along x (1: a texture each). The kernels' parameters
    /// carry it to pass 3's stores.
    pub interleave: u32,
}

/// Adds the passes of `sat`'s tables to `graph` for `light`; returns the textures that hold
/// them, in layer order (empty for no layers): a table each, or with `sat.interleave` n > 1
/// ⌈L / n⌉ textures of n tables (the last of the rest), table k in texture ⌊k / n⌋ at slot
/// k mod n.
pub fn add_layered_sat(graph: &mut Graph, light: usize, sat: &LayeredSat<'_>) -> Vec<String> {
    let layers = sat.tables.len() as u32;
    if layers == 0 {
        return Vec::new();
    }
    let source = sat.source.to_string();
    // The edges and carries hold as many channels as the widest table (two for VSM's moments).
    let channels = sat.tables.iter().map(|(_, c)| *c).max().unwrap_or(4);
    let mut sat_params = sat.coding.params(channels, 0);
    sat_params.layers = layers;
    let words = SatVariant::Fixed.format(channels);
    let stem = format!("{}.sat", sat.prefix);
    let mut edges = |suffix: &str, x: u32, y: u32, across: u32, down: u32| {
        let size = SizeRule::Stacked {
            of: source.clone(),
            x,
            y,
            across,
            down,
        };
        // Read by the tables' own passes alone, with `textureLoad`.
        graph.intermediate(format!("{stem}.{suffix}"), words, size, Some(light))
    };
    let col_part = edges("col_part", 1, SAT_TILE, 1, layers);
    let row_part = edges("row_part", SAT_TILE, 1, layers, 1);
    let col_carry = edges("col_carry", 1, SAT_TILE, 1, layers);
    let row_carry = edges("row_carry", SAT_TILE, 1, layers, 1);
    let per = sat.interleave.max(1) as usize;
    let tables: Vec<String> = if per == 1 {
        sat.tables
            .iter()
            .map(|(name, channels)| {
                let same = SizeRule::Reduced {
                    of: source.clone(),
                    shift: 0,
                };
                let format = sat.coding.variant.format(*channels);
                graph.resource(sat_name(name), format, same, Some(light))
            })
            .collect::<Vec<_>>()
    } else {
        // A texture's format holds its widest table; narrower ones leave channels unused.
        sat.tables
            .chunks(per)
            .enumerate()
            .map(|(s, group)| {
                let widest = group.iter().map(|(_, c)| *c).max().unwrap_or(4);
                let format = sat.coding.variant.format(widest);
                let names = group.iter().map(|(name, _)| sat_name(name)).collect();
                graph.interleaved(
                    format!("{stem}.layers{s}"),
                    format,
                    &source,
                    names,
                    Some(light),
                )
            })
            .collect()
    };
    // Fixed-point tables are only loaded, never filtered (their lookups' `textureLoad`).
    if sat.coding.variant == crate::model::SatVariant::Fixed {
        for t in &tables {
            graph.mark_unfiltered(t);
        }
    }
    let tiles = |count: u32| Dispatch::Layers {
        base: Box::new(Dispatch::Blocks {
            of: source.clone(),
            x: SAT_TILE,
            y: SAT_TILE,
        }),
        layers: count,
    };
    let mut node = |suffix: &str, kernel, inputs, outputs, params, dispatch| {
        graph.node(Node {
            name: format!("{stem}{suffix}"),
            kernel,
            inputs,
            outputs,
            params,
            dispatch,
            light: Some(light),
        });
    };
    node(
        ".tile_sums",
        sat.kernels[0],
        named(vec![("src", sat.source)]),
        named(vec![("col_part", &col_part), ("row_part", &row_part)]),
        (sat.params)(sat_params, 0, layers),
        tiles(layers),
    );
    node(
        ".carries",
        KernelId::SatCarries,
        named(vec![("col_part", &col_part), ("row_part", &row_part)]),
        named(vec![("col_carry", &col_carry), ("row_carry", &row_carry)]),
        bytemuck::bytes_of(&sat_params).to_vec(),
        carries_dispatch(&source, Some(layers)),
    );
    for (g, group) in tables.chunks(LAYERED_SAT_OUTPUTS as usize).enumerate() {
        let first = g as u32 * LAYERED_SAT_OUTPUTS * per as u32;
        let count = (layers - first).min(LAYERED_SAT_OUTPUTS * per as u32);
        let dst = group
            .iter()
            .enumerate()
            .map(|(j, t)| (format!("dst{j}"), t.clone()))
            .collect();
        node(
            &format!(".{g}"),
            sat.kernels[1],
            named(vec![
                ("src", sat.source),
                ("col_carry", &col_carry),
                ("row_carry", &row_carry),
            ]),
            dst,
            (sat.params)(sat_params, first, count),
            if per == 1 {
                tiles(count)
            } else {
                Dispatch::Interleaved {
                    base: Box::new(Dispatch::Blocks {
                        of: source.clone(),
                        x: SAT_TILE,
                        y: SAT_TILE,
                    }),
                    layers: count,
                }
            },
        );
    }
    tables
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::plan;

    /// Five layers (four of four channels, the last of one) of a ragged 200 × 130 source, fixed
    /// point, `interleave` tables a texture, the first and count of each dispatch's tables
    /// after its `SatParams`: the graph and the textures.
    fn five_layers(interleave: u32) -> (Graph, Vec<String>) {
        let mut g = Graph::default();
        g.import("d", wgpu::TextureFormat::R32Float, 200, 130, Some(0));
        let tables: Vec<(String, u32)> = (0..5)
            .map(|k| (format!("t{k}"), if k == 4 { 1 } else { 4 }))
            .collect();
        let params = |s: SatParams, first: u32, count: u32| {
            let mut b = bytemuck::bytes_of(&s).to_vec();
            b.extend([first, count].iter().flat_map(|v| v.to_le_bytes()));
            b
        };
        let sat = LayeredSat {
            source: "d",
            prefix: "l",
            tables: &tables,
            kernels: [KernelId::CsmSatTileSums, KernelId::CsmSatTiles],
            params: &params,
            coding: SatCoding::fixed(64, [-1.0; 4], [1.0; 4]).unwrap(),
            interleave,
        };
        let out = add_layered_sat(&mut g, 0, &sat);
        (g, out)
    }

    /// Five layers of a ragged 200 × 130 source: the stacked edges' sizes, the passes, their
    /// workgroups along z and each pass-3 dispatch's tables.
    #[test]
    fn layered_sat_plans_stacked_edges_and_four_tables_a_dispatch() {
        let (g, out) = five_layers(1);
        assert_eq!(out, ["t0.sat", "t1.sat", "t2.sat", "t3.sat", "t4.sat"]);
        let names: Vec<&str> = out.iter().map(String::as_str).collect();
        let p = plan(&g, &names).unwrap();
        let kernels: Vec<&str> = p.steps.iter().map(|s| s.node.kernel.as_str()).collect();
        assert_eq!(
            kernels,
            [
                "csm_sat_tile_sums",
                "sat_carries",
                "csm_sat_tiles",
                "csm_sat_tiles"
            ]
        );
        let size = |n: &str| p.resource(n).map(|r| (r.width, r.height));
        // 7 × 5 tiles of 32: five bands of 5 rows (col_*) and of 7 columns (row_*).
        assert_eq!(size("l.sat.col_part"), Some((200, 25)));
        assert_eq!(size("l.sat.row_carry"), Some((35, 130)));
        let format = |n: &str| p.resource(n).map(|r| r.resource.format);
        assert_eq!(format("t0.sat"), Some(wgpu::TextureFormat::Rgba32Uint));
        assert_eq!(format("t4.sat"), Some(wgpu::TextureFormat::R32Uint));
        let groups: Vec<Option<[u32; 3]>> = p
            .steps
            .iter()
            .map(|s| s.node.dispatch.groups(size, [64, 1, 1]))
            .collect();
        assert_eq!(
            groups,
            [
                Some([7, 5, 5]),
                Some([4, 2, 5]),
                Some([7, 5, 4]),
                Some([7, 5, 1])
            ]
        );
        // Every pass codes alike; `sat_carries` sees every layer; pass 3 its first table.
        let sat_params = |k: usize| -> SatParams {
            *bytemuck::from_bytes(&p.steps[k].node.params[..std::mem::size_of::<SatParams>()])
        };
        assert!((0..4).all(|k| sat_params(k).layers == 5));
        let first = |k: usize| p.steps[k].node.params[std::mem::size_of::<SatParams>()];
        assert_eq!((first(2), first(3)), (0, 4));
        let outputs: Vec<&str> = p.steps[3]
            .node
            .outputs
            .iter()
            .map(|o| o.1.as_str())
            .collect();
        assert_eq!(outputs, ["t4.sat"]);
    }

    /// Five layers two a texture: three textures (two, two, one table) as wide as their
    /// tables side by side, each naming its tables, one pass-3 dispatch with the five layers
    /// of a tile side by side along x.
    #[test]
    fn interleaved_layers_share_textures_and_one_dispatch() {
        let (g, out) = five_layers(2);
        assert_eq!(out, ["l.sat.layers0", "l.sat.layers1", "l.sat.layers2"]);
        let names: Vec<&str> = out.iter().map(String::as_str).collect();
        let p = plan(&g, &names).unwrap();
        let kernels: Vec<&str> = p.steps.iter().map(|s| s.node.kernel.as_str()).collect();
        assert_eq!(
            kernels,
            ["csm_sat_tile_sums", "sat_carries", "csm_sat_tiles"]
        );
        let size = |n: &str| p.resource(n).map(|r| (r.width, r.height));
        assert_eq!(size("l.sat.layers0"), Some((400, 130)));
        assert_eq!(size("l.sat.layers2"), Some((200, 130)));
        let layers = |n: &str| p.resource(n).map(|r| r.resource.layers.clone());
        assert_eq!(
            layers("l.sat.layers1"),
            Some(vec!["t2.sat".into(), "t3.sat".into()])
        );
        assert_eq!(layers("l.sat.layers2"), Some(vec!["t4.sat".into()]));
        // The widest table's format; the last texture holds only the one-channel table.
        let format = |n: &str| p.resource(n).map(|r| r.resource.format);
        assert_eq!(
            format("l.sat.layers0"),
            Some(wgpu::TextureFormat::Rgba32Uint)
        );
        assert_eq!(format("l.sat.layers2"), Some(wgpu::TextureFormat::R32Uint));
        let groups = p.steps[2].node.dispatch.groups(size, [64, 1, 1]);
        assert_eq!(groups, Some([35, 5, 1]));
        let outputs: Vec<&str> = p.steps[2]
            .node
            .outputs
            .iter()
            .map(|o| o.1.as_str())
            .collect();
        assert_eq!(outputs, names);
    }

    #[test]
    fn zero_layers_is_a_plan_error_and_no_layers_no_nodes() {
        let mut g = Graph::default();
        g.import("d", wgpu::TextureFormat::R32Float, 8, 8, Some(0));
        let params = |s: SatParams, _: u32, _: u32| bytemuck::bytes_of(&s).to_vec();
        let sat = LayeredSat {
            source: "d",
            prefix: "l",
            tables: &[],
            kernels: [KernelId::CsmSatTileSums, KernelId::CsmSatTiles],
            params: &params,
            coding: SatCoding::float([0.0; 4], [1.0; 4]).unwrap(),
            interleave: 1,
        };
        assert!(add_layered_sat(&mut g, 0, &sat).is_empty());
        assert!(g.nodes.is_empty());
        let tables = [("t".to_string(), 4)];
        let sat = LayeredSat {
            tables: &tables,
            ..sat
        };
        let out = add_layered_sat(&mut g, 0, &sat);
        let mut p = plan(&g, &[out[0].as_str()]).unwrap();
        assert!(p.check().is_ok());
        p.steps[0].node.dispatch = Dispatch::Layers {
            base: Box::new(Dispatch::Groups([1, 1, 1])),
            layers: 0,
        };
        assert!(p.check().is_err());
    }
}
