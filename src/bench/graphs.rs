//! The graphs the cases run: a light's shipped graph from its rasterized depth, cut to one
//! stage or kept whole as a chain, the unfused chains of earlier builds, and the summed-area
//! table's passes over an imported map.

use glam::Vec3;

use super::cases::named;
use crate::filter::{BlurMode, add_filter};
use crate::graph::Graph;
use crate::model::{Light, LightKind, Shadow, Technique};
use crate::technique;
use crate::{
    model::SatVariant,
    sat::{self, SatCoding},
};

/// The graph a case runs and the outputs that keep its nodes alive.
pub struct BenchGraph {
    /// The graph; its imports are R32Float textures the harness fills with random depths.
    pub graph: Graph,
    /// Resources requested from [`crate::graph::plan`].
    pub outputs: Vec<String>,
}

/// A light's shipped graph from its rasterized depth to `outputs` (the encoded maps). The
/// depth is imported as r32float (4 B a texel, as depth32float; the harness writes imports,
/// which a depth format forbids).
pub(super) fn chain_graph(n: u32, technique: Technique, outputs: &[&str]) -> BenchGraph {
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
    BenchGraph {
        graph,
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
    }
}

/// [`chain_graph`] up to the textures the shading reads (every table of CSSM's layered
/// tables, however many a texture holds).
pub(super) fn shading_chain(n: u32, technique: Technique) -> BenchGraph {
    let mut graph = Graph::default();
    let input = technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
    BenchGraph {
        graph,
        outputs: input.maps,
    }
}

/// A light's shipped graph at size `n`.
pub(super) fn light_graph(n: u32, technique: Technique) -> Graph {
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &bench_light(n, technique));
    graph
}

/// A light's graph with the unfused linear blur over its `encoded` map added
/// (`<encoded>.blur_h`, `<encoded>.blur_v`): the chain before the encoding was fused into the
/// blur, and the standalone blur passes other representations still use.
pub(super) fn unfused(n: u32, technique: Technique, encoded: &str) -> Graph {
    let filter = technique.filter();
    let mut graph = light_graph(n, technique);
    // The fused blur's nodes go: the fallback's `.blur_h` would clash with the unfused pass's.
    let fused = format!("{encoded}.blur");
    graph.nodes.retain(|node| !node.name.starts_with(&fused));
    graph.resources.retain(|r| !r.name.starts_with(&fused));
    if let Some(f) = filter {
        add_filter(&mut graph, 0, encoded, &f, BlurMode::Linear);
    }
    graph
}

/// The unfused chain depth → `encoded` → `.blur_h` → `.blur_v` (see [`unfused`]), its depth
/// an r32float import as in [`chain_graph`].
pub(super) fn old_chain(n: u32, technique: Technique, encoded: &str) -> BenchGraph {
    let mut graph = unfused(n, technique, encoded);
    for r in graph.resources.iter_mut().filter(|r| r.imported) {
        r.format = wgpu::TextureFormat::R32Float;
    }
    BenchGraph {
        graph,
        outputs: vec![format!("{encoded}.blur_v")],
    }
}

/// The stages of `graph` between `input` (made an import, its producers dropped by the
/// planner) and `output`: one kernel or a filter's passes, timed alone.
pub(super) fn stage_graph(mut graph: Graph, input: &str, output: &str) -> BenchGraph {
    for r in graph.resources.iter_mut().filter(|r| r.name == input) {
        r.imported = true;
    }
    graph
        .nodes
        .retain(|node| node.outputs.iter().all(|(_, r)| r != input));
    BenchGraph {
        graph,
        outputs: vec![output.to_string()],
    }
}

/// The SAT passes of [`sat::add_sat`] over an imported `n`² VSM-shaped (Rg32Float) map; fixed
/// point for lookups of up to 64 × 64 texels of values in [0, 1].
pub(super) fn sat_graph(n: u32, variant: SatVariant) -> BenchGraph {
    sat_graph_with(n, variant, sat::add_sat)
}

/// [`sat_graph`] with another builder of the table's passes (the five-pass baseline).
pub(super) fn sat_graph_with(
    n: u32,
    variant: SatVariant,
    add: fn(&mut Graph, usize, &str, &SatCoding) -> String,
) -> BenchGraph {
    let mut graph = Graph::default();
    let input = graph.import("light0.vsm", wgpu::TextureFormat::Rg32Float, n, n, Some(0));
    let (lo, hi) = ([0.0; 4], [1.0; 4]);
    let coding = match variant {
        SatVariant::Fixed => SatCoding::fixed(sat::lookup_area(64.0, 64.0), lo, hi),
        SatVariant::Float => SatCoding::float(lo, hi),
    };
    // The arguments are valid constants; a unit scale would only change the values summed,
    // not the work timed.
    let coding = coding.unwrap_or(SatCoding {
        variant,
        offset: [0.5; 4],
        scale: [1.0; 4],
        limit: [1.0; 4],
    });
    let output = add(&mut graph, 0, &input, &coding);
    BenchGraph {
        graph,
        outputs: vec![output],
    }
}

/// The shipped node of [`technique::add_light_nodes`] for a spot light (the perspective path,
/// the more expensive one), reading a Depth32Float import as the renderer's does.
pub(super) fn linearize_graph(n: u32) -> BenchGraph {
    let light = bench_light(n, named("hard", &[]));
    let mut graph = Graph::default();
    technique::add_light_nodes(&mut graph, 0, &light);
    BenchGraph {
        graph,
        outputs: vec![technique::linear_name(0)],
    }
}

/// A spot light with an `n`² map and `technique`.
pub(super) fn bench_light(n: u32, technique: Technique) -> Light {
    Light {
        kind: LightKind::Spot { fov_degrees: 60.0 },
        position: Vec3::new(0.0, 10.0, 0.0),
        target: Vec3::ZERO,
        near: 0.1,
        far: 100.0,
        size: 0.0,
        radiance: Vec3::ONE,
        shadow_map: n,
        shadow: Shadow {
            technique,
            bias: 0.0,
            slope_bias: 0.0,
            normal_bias: 0.0,
            receiver_plane: 0.0,
            cascades: crate::model::Cascades::SINGLE,
        },
    }
}
