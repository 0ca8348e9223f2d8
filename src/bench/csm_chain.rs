//! CSSM's prefilter at M = 8 as the shipped graph builds it — one layered table whose tile
//! passes compute the basis from the depth ([`crate::sat::layers`]): five tables with the
//! default moment search, nine with the paper's CSM-Z search — and as builds before it did:
//! `csm` storing the nine basis maps four a dispatch, then three table passes per map. The old
//! chain stays a bench case until the comparison is recorded.

use super::cases::named;
use super::graphs::{BenchGraph, bench_light, shading_chain};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::{CssmSearch, ParamValue, Storage, Technique};
use crate::sat::{SatCoding, add_sat};
use crate::technique::{self, csm_maps, csm_z_channels, csm_z_maps, moments_format};
use crate::wgsl_mirrors::{CSM_OUTPUTS, CsmParams, LinearizeParams};

/// Terms of the CSSM chains timed.
const TERMS: u32 = 8;

fn cssm(search: CssmSearch) -> Technique {
    named(
        "cssm",
        &[
            ("terms", ParamValue::Int(TERMS)),
            ("blocker_search", ParamValue::Choice(search.name())),
        ],
    )
}

fn layered_of(n: u32, search: CssmSearch) -> BenchGraph {
    shading_chain(n, cssm(search))
}

/// The shipped chain with the moment search: its five tables interleaved in one texture up
/// to 1638², four and one at 2048² (`technique::basis_interleave`): 3 dispatches up to 4096².
pub(super) fn layered(n: u32) -> BenchGraph {
    layered_of(n, CssmSearch::Moments)
}

/// The shipped chain with the CSM-Z search: nine tables, interleaved as many as fit in 8192
/// texels a texture (all nine up to 910²): 3 dispatches up to 2048².
pub(super) fn layered_csm_z(n: u32) -> BenchGraph {
    layered_of(n, CssmSearch::CsmZ)
}

/// The chain before the layered tables: `csm` writes the nine basis maps (rgba32float, the
/// last r32float) four a dispatch from the depth, and each map gets the three passes of
/// [`add_sat`]: 30 dispatches.
pub(super) fn maps_then_tables(n: u32) -> BenchGraph {
    let light = bench_light(n, cssm(CssmSearch::CsmZ));
    let coding = technique::sat_coding(&light)
        .ok()
        .flatten()
        .unwrap_or_else(|| SatCoding::fixed(64 * 64, [-1.0; 4], [1.0; 4]).expect("valid coding"));
    let mut graph = Graph::default();
    let depth = graph.import("light0.depth", wgpu::TextureFormat::R32Float, n, n, Some(0));
    let z_channels = csm_z_channels(TERMS);
    let maps: Vec<(String, u32)> = (0..csm_maps(TERMS))
        .map(|k| (format!("light0.csm{k}"), 4))
        .chain(
            (0..csm_z_maps(TERMS))
                .map(|k| (format!("light0.csm_z{k}"), (z_channels - 4 * k).min(4))),
        )
        .collect();
    let mut outputs = Vec::new();
    for (g, group) in maps.chunks(CSM_OUTPUTS as usize).enumerate() {
        let mut written = Vec::new();
        for (name, channels) in group {
            let size = SizeRule::Reduced {
                of: depth.clone(),
                shift: 0,
            };
            let format = moments_format(Storage::F32, *channels);
            written.push(graph.resource(name.clone(), format, size, Some(0)));
        }
        let params = CsmParams {
            depth: LinearizeParams::new(&light),
            first_map: g as u32 * CSM_OUTPUTS,
            maps: group.len() as u32,
            terms: TERMS,
            moments: 0,
        };
        graph.node(Node {
            name: format!("light0.csm.{g}"),
            kernel: KernelId::Csm,
            inputs: vec![("src".into(), depth.clone())],
            outputs: (0..written.len())
                .map(|j| (format!("dst{j}"), written[j].clone()))
                .collect(),
            params: bytemuck::bytes_of(&params).to_vec(),
            dispatch: Dispatch::Texels(written[0].clone()),
            light: Some(0),
        });
        outputs.extend(written.iter().map(|m| add_sat(&mut graph, 0, m, &coding)));
    }
    BenchGraph { graph, outputs }
}
