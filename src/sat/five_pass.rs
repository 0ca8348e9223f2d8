//! The five-pass summed-area table this project shipped first, kept as the baseline that
//! `shadowgraph bench` times the tiled passes of [`super::add_sat`] against (row `sat
//! (5-pass, old)`); it builds the same tables (a 4-channel table, whatever the input).
//!
//! 1. `sat_rows`: encode each texel and scan each row in blocks of [`SAT_BLOCK`] texels, one
//!    workgroup per block (Blelloch's tree over 256 invocations in workgroup memory); block
//!    totals to `.row_sums`.
//! 2. `sat_carry`: the exclusive prefix of each row's block totals (`.row_carry`).
//! 3. `sat_cols_reduce`: totals of blocks of [`SAT_BLOCK`] rows of the full row prefix.
//! 4. `sat_carry`: their exclusive prefix down each column (`.col_carry`).
//! 5. `sat_cols` / `sat_cols_f32`: scan each column block, add both carries, store the table.

use super::{SatCoding, SatVariant, format_channels, sat_name};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;

/// Texels per scanned block, one workgroup each (`BLOCK` = `WG_SIZE · ITEMS` in
/// `kernels/shared/sat_scan.wgsl`; a test checks them against each other).
pub const SAT_BLOCK: u32 = 1024;

/// Lines of block totals per `sat_carry` workgroup, one per invocation (its workgroup size).
pub const SAT_CARRY_LINES: u32 = 64;

impl SatVariant {
    /// The kernel of the five-pass table's last pass (the only one whose output type differs).
    fn five_pass_last_kernel(self) -> KernelId {
        match self {
            Self::Fixed => KernelId::SatCols,
            Self::Float => KernelId::SatColsF32,
        }
    }
}

/// Adds the five passes building the inclusive SAT of `input` (a float representation of
/// `light`, 1–4 channels, any size) coded as `coding`; returns the table's resource,
/// `<input>.sat` (`rgba32uint` or `rgba32float`, same size as `input`, always 4 channels).
///
/// Intermediates, all `rgba32uint` (the f32 variant carries f32 bits): `<input>.sat.rows`
/// (block-local row scans, input size), `.row_sums` and `.row_carry`
/// (`⌈width / SAT_BLOCK⌉ × height`), `.col_sums` and `.col_carry`
/// (`width × ⌈height / SAT_BLOCK⌉`), sized by [`SizeRule`]s so the planner follows the input.
pub fn add_sat_five_pass(
    graph: &mut Graph,
    light: usize,
    input: &str,
    coding: &SatCoding,
) -> String {
    let channels = graph.find(input).map_or(4, |r| format_channels(r.format));
    let name = sat_name(input);
    let u32x4 = wgpu::TextureFormat::Rgba32Uint;
    let same = SizeRule::Reduced {
        of: input.to_string(),
        shift: 0,
    };
    let blocks = |x, y| SizeRule::Blocks {
        of: input.to_string(),
        x,
        y,
    };
    let mut res = |suffix: &str, size: SizeRule| {
        graph.intermediate(format!("{name}.{suffix}"), u32x4, size, Some(light))
    };
    let rows = res("rows", same.clone());
    let row_sums = res("row_sums", blocks(SAT_BLOCK, 1));
    let row_carry = res("row_carry", blocks(SAT_BLOCK, 1));
    let col_sums = res("col_sums", blocks(1, SAT_BLOCK));
    let col_carry = res("col_carry", blocks(1, SAT_BLOCK));
    let out = graph.resource(name.clone(), coding.variant.format(4), same, Some(light));

    let names = SatNames {
        input,
        rows: &rows,
        row_sums: &row_sums,
        row_carry: &row_carry,
        col_sums: &col_sums,
        col_carry: &col_carry,
        out: &out,
    };
    for pass in passes(&names, coding.variant) {
        graph.node(Node {
            name: format!("{name}{}", pass.suffix),
            kernel: pass.kernel,
            inputs: named(pass.inputs),
            outputs: named(pass.outputs),
            params: bytemuck::bytes_of(&coding.params(channels, pass.axis)).to_vec(),
            dispatch: Dispatch::Blocks {
                of: pass.blocks_of.to_string(),
                x: pass.block[0],
                y: pass.block[1],
            },
            light: Some(light),
        });
    }
    out
}

/// The resources of one table.
struct SatNames<'a> {
    input: &'a str,
    rows: &'a str,
    row_sums: &'a str,
    row_carry: &'a str,
    col_sums: &'a str,
    col_carry: &'a str,
    out: &'a str,
}

/// One pass of [`add_sat`]: a node named `<table><suffix>` with one workgroup per `block` of
/// `blocks_of`.
struct Pass<'a> {
    suffix: &'a str,
    kernel: KernelId,
    inputs: Vec<(&'a str, &'a str)>,
    outputs: Vec<(&'a str, &'a str)>,
    axis: u32,
    blocks_of: &'a str,
    block: [u32; 2],
}

/// The five passes, in order (see the module documentation).
fn passes<'a>(n: &SatNames<'a>, variant: SatVariant) -> [Pass<'a>; 5] {
    let (b, lines) = (SAT_BLOCK, SAT_CARRY_LINES);
    [
        Pass {
            suffix: ".rows",
            kernel: KernelId::SatRows,
            inputs: vec![("src", n.input)],
            outputs: vec![("dst", n.rows), ("sums", n.row_sums)],
            axis: 0,
            blocks_of: n.input,
            block: [b, 1],
        },
        Pass {
            suffix: ".row_carry",
            kernel: KernelId::SatCarry,
            inputs: vec![("src", n.row_sums)],
            outputs: vec![("dst", n.row_carry)],
            axis: 0,
            blocks_of: n.row_sums,
            block: [0, lines],
        },
        Pass {
            suffix: ".col_sums",
            kernel: KernelId::SatColsReduce,
            inputs: vec![("src", n.rows), ("row_carry", n.row_carry)],
            outputs: vec![("dst", n.col_sums)],
            axis: 1,
            blocks_of: n.input,
            block: [1, b],
        },
        Pass {
            suffix: ".col_carry",
            kernel: KernelId::SatCarry,
            inputs: vec![("src", n.col_sums)],
            outputs: vec![("dst", n.col_carry)],
            axis: 1,
            blocks_of: n.col_sums,
            block: [lines, 0],
        },
        Pass {
            suffix: "",
            kernel: variant.five_pass_last_kernel(),
            inputs: vec![
                ("src", n.rows),
                ("row_carry", n.row_carry),
                ("col_carry", n.col_carry),
            ],
            outputs: vec![("dst", n.out)],
            axis: 1,
            blocks_of: n.input,
            block: [1, b],
        },
    ]
}

fn named(pairs: Vec<(&str, &str)>) -> Vec<(String, String)> {
    pairs
        .into_iter()
        .map(|(b, r)| (b.to_string(), r.to_string()))
        .collect()
}
