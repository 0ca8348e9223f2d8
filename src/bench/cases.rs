//! The benchmark's case list: every graph kernel it times ([`CASES`]), each a name and the
//! graph that runs it, and the technique settings the cases are built with (the registry's
//! entries with the scenes' values over their defaults).

use super::csm_chain;
use super::graphs::{
    BenchGraph, chain_graph, light_graph, linearize_graph, old_chain, sat_graph, sat_graph_with,
    stage_graph, unfused,
};
use crate::model::ParamValue;
use crate::model::{Storage, Technique};
use crate::technique;
use crate::technique::params::storage_name;
use crate::{model::SatVariant, sat};

/// One kernel to benchmark: adding a kernel to the benchmark is one entry of [`CASES`].
pub struct BenchCase {
    /// Name in the report.
    pub name: &'static str,
    /// The graph at size `n`.
    pub build: fn(u32) -> BenchGraph,
}

/// Every benchmarked graph kernel.
pub const CASES: &[BenchCase] = &[
    BenchCase {
        name: "linearize",
        build: linearize_graph,
    },
    BenchCase {
        name: "vsm",
        build: |n| stage_graph(light_graph(n, vsm()), "light0.depth", "light0.vsm"),
    },
    BenchCase {
        name: "evsm4",
        build: |n| stage_graph(light_graph(n, evsm4()), "light0.depth", "light0.evsm"),
    },
    BenchCase {
        name: "esm",
        build: |n| stage_graph(light_graph(n, esm()), "light0.depth", "light0.esm"),
    },
    BenchCase {
        name: "blur rg32f r4",
        build: |n| {
            stage_graph(
                unfused(n, vsm(), "light0.vsm"),
                "light0.vsm",
                "light0.vsm.blur_v",
            )
        },
    },
    BenchCase {
        name: "blur rg32f r32",
        build: |n| {
            let graph = unfused(n, vsm_blur(32.0), "light0.vsm");
            stage_graph(graph, "light0.vsm", "light0.vsm.blur_v")
        },
    },
    BenchCase {
        name: "blur log r4",
        build: |n| stage_graph(light_graph(n, esm()), "light0.esm", "light0.esm.blur_v"),
    },
    // ESM past c = 80: `blur_log_wide`, with the per-output path for texels spread wider.
    BenchCase {
        name: "blur log r4 wide (c = 200)",
        build: |n| {
            stage_graph(
                light_graph(n, esm_wide()),
                "light0.esm",
                "light0.esm.blur_v",
            )
        },
    },
    // Depth → blurred moments: the encoding fused into the blur (76856d8), and the chain it
    // replaced (encode, blur_h, blur_v: the `(old)` rows) timed beside it.
    BenchCase {
        name: "vsm_blur r4",
        build: |n| chain_graph(n, vsm(), &["light0.vsm.blur"]),
    },
    BenchCase {
        name: "vsm+blur r4 (old)",
        build: |n| old_chain(n, vsm(), "light0.vsm"),
    },
    // Two f16 moments packed in one r32uint word (4 B/texel): against the f32 rows above.
    BenchCase {
        name: "vsm_blur r4 f16 (packed)",
        build: |n| chain_graph(n, vsm_f16(), &["light0.vsm.blur"]),
    },
    BenchCase {
        name: "vsm_blur r32 (2 passes)",
        build: |n| chain_graph(n, vsm_blur(32.0), &["light0.vsm.blur"]),
    },
    BenchCase {
        name: "vsm+blur r32 (old)",
        build: |n| old_chain(n, vsm_blur(32.0), "light0.vsm"),
    },
    BenchCase {
        name: "evsm_blur 4 r4",
        build: |n| chain_graph(n, evsm4(), &["light0.evsm.blur"]),
    },
    BenchCase {
        name: "evsm4+blur r4 (old)",
        build: |n| old_chain(n, evsm4(), "light0.evsm"),
    },
    BenchCase {
        name: "msm_blur r4",
        build: |n| chain_graph(n, msm(Storage::F32), &["light0.msm.blur"]),
    },
    // Past the tile's radius: the row kernels (`msm_blur_row` from 512² on) and `blur` along y.
    BenchCase {
        name: "msm_blur r32 (2 passes)",
        build: |n| chain_graph(n, msm_blur(32.0), &["light0.msm.blur"]),
    },
    BenchCase {
        name: "msm+blur r4 (old)",
        build: |n| old_chain(n, msm(Storage::F32), "light0.msm"),
    },
    BenchCase {
        name: "msm",
        build: |n| {
            stage_graph(
                light_graph(n, msm(Storage::F32)),
                "light0.depth",
                "light0.msm",
            )
        },
    },
    BenchCase {
        name: "msm f16 quantized",
        build: |n| {
            stage_graph(
                light_graph(n, msm(Storage::F16)),
                "light0.depth",
                "light0.msm",
            )
        },
    },
    BenchCase {
        name: "csm (2 terms)",
        build: |n| stage_graph(light_graph(n, csm()), "light0.depth", "light0.csm0"),
    },
    // Depth → encoded maps, whatever the dispatches (linearize fused into the encodings, CSM
    // maps four a dispatch since 2026-11-23): timed against the chains of earlier builds.
    BenchCase {
        name: "chain vsm (depth → moments)",
        build: |n| chain_graph(n, vsm(), &["light0.vsm"]),
    },
    BenchCase {
        name: "chain msm f16 (depth → moments)",
        build: |n| chain_graph(n, msm(Storage::F16), &["light0.msm"]),
    },
    BenchCase {
        name: "chain csm 8 terms (depth → 4 maps)",
        build: |n| {
            let maps = ["light0.csm0", "light0.csm1", "light0.csm2", "light0.csm3"];
            chain_graph(n, csm_terms(8), &maps)
        },
    },
    // CSSM's prefilter: the layered tables (basis computed in their tile passes) against the
    // chain before them, until the comparison is recorded.
    // The soft techniques' whole prefilter at their defaults: the soft table build.
    BenchCase {
        name: "chain vssm (depth → table)",
        build: |n| chain_graph(n, named("vssm", &[]), &["light0.vsm.sat"]),
    },
    BenchCase {
        name: "chain msm_soft (depth → table)",
        build: |n| chain_graph(n, named("msm_soft", &[]), &["light0.msm.sat"]),
    },
    // The exponential encodings through a table at the scenes' exponents
    // (`scenes/techniques/evsm4_sat.toml`, `esm_sat.toml`): computed in the table's passes.
    BenchCase {
        name: "chain evsm4 sat (depth → table)",
        build: |n| chain_graph(n, exp_sat("evsm4"), &["light0.evsm.sat"]),
    },
    BenchCase {
        name: "chain esm sat (depth → table)",
        build: |n| chain_graph(n, exp_sat("esm"), &["light0.esm.sat"]),
    },
    BenchCase {
        name: "chain cssm 8 terms (depth → 5 tables)",
        build: csm_chain::layered,
    },
    BenchCase {
        name: "chain cssm 8 terms csm_z (depth → 9 tables)",
        build: csm_chain::layered_csm_z,
    },
    BenchCase {
        name: "chain cssm 8 terms (9 maps + 27 passes, old)",
        build: csm_chain::maps_then_tables,
    },
    BenchCase {
        name: "mips rgba32f",
        build: |n| stage_graph(light_graph(n, msm_mips()), "light0.msm", "light0.msm.mips"),
    },
    BenchCase {
        name: "sat fixed",
        build: |n| sat_graph(n, SatVariant::Fixed),
    },
    BenchCase {
        name: "sat float",
        build: |n| sat_graph(n, SatVariant::Float),
    },
    // The first design, timed beside the tiled passes until their comparison is recorded.
    BenchCase {
        name: "sat fixed (5-pass, old)",
        build: |n| sat_graph_with(n, SatVariant::Fixed, sat::five_pass::add_sat_five_pass),
    },
];

/// Technique `name` of the registry with `values` over its defaults (the scene file's).
pub(super) fn named(name: &str, values: &[(&'static str, ParamValue)]) -> Technique {
    technique::named(name, values).expect("bench cases name registered techniques and keys")
}

/// The Gaussian blur of radius 4 (σ = 2) the chains are timed with.
const BLUR4: [(&str, ParamValue); 2] = [
    ("filter_radius", ParamValue::Float(4.0)),
    ("filter_sigma", ParamValue::Float(2.0)),
];

fn vsm() -> Technique {
    vsm_blur(4.0)
}

/// VSM with a Gaussian blur of `radius` taps each side (σ = radius / 2).
fn vsm_blur(radius: f32) -> Technique {
    named(
        "vsm",
        &[
            ("filter_radius", ParamValue::Float(radius)),
            ("filter_sigma", ParamValue::Float(radius / 2.0)),
        ],
    )
}

/// [`vsm`] with f16 moments (stored packed, two in a 32-bit word).
fn vsm_f16() -> Technique {
    named(
        "vsm",
        &[
            ("filter_radius", ParamValue::Float(4.0)),
            ("filter_sigma", ParamValue::Float(2.0)),
            ("format", ParamValue::Choice("f16")),
        ],
    )
}

fn evsm4() -> Technique {
    named("evsm4", &BLUR4)
}

/// `evsm4` (c⁺ = c⁻ = 6, what its table keeps accurate for a 4-texel box) or `esm` (c = 20)
/// through a fixed-point summed-area table, as the scenes `evsm4_sat` and `esm_sat`.
fn exp_sat(name: &str) -> Technique {
    let sat = [
        ("filter", ParamValue::Choice("sat")),
        ("filter_width", ParamValue::Float(4.0)),
    ];
    if name == "esm" {
        named(
            name,
            &[sat[0], sat[1], ("exponent", ParamValue::Float(20.0))],
        )
    } else {
        let c = ParamValue::Float(6.0);
        named(
            name,
            &[sat[0], sat[1], ("exponent_pos", c), ("exponent_neg", c)],
        )
    }
}

fn msm(storage: Storage) -> Technique {
    let format = ("format", ParamValue::Choice(storage_name(storage)));
    named("msm", &[format, BLUR4[0], BLUR4[1]])
}

/// MSM (f32) with a Gaussian blur of `radius` taps each side (σ = radius / 2).
fn msm_blur(radius: f32) -> Technique {
    named(
        "msm",
        &[
            ("filter_radius", ParamValue::Float(radius)),
            ("filter_sigma", ParamValue::Float(radius / 2.0)),
        ],
    )
}

fn msm_mips() -> Technique {
    named(
        "msm",
        &[
            ("filter", ParamValue::Choice("mips")),
            ("filter_width", ParamValue::Float(1.0)),
            ("moment_bias", ParamValue::Float(1e-5)),
        ],
    )
}

fn csm() -> Technique {
    csm_terms(2)
}

fn esm() -> Technique {
    named("esm", &BLUR4)
}

fn esm_wide() -> Technique {
    named(
        "esm",
        &[BLUR4[0], BLUR4[1], ("exponent", ParamValue::Float(200.0))],
    )
}

/// CSM with `terms` terms (offset 0.25 whatever M: the bench times the series, not its fit).
fn csm_terms(terms: u32) -> Technique {
    let values = [
        ("terms", ParamValue::Int(terms)),
        ("offset", ParamValue::Float(0.25)),
    ];
    named("csm", &[values[0], values[1], BLUR4[0], BLUR4[1]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::plan_bytes;

    /// The bytes of a SAT are its three passes' (two reads of the representation, one write
    /// of the table, the tiles' edges and carries), the five-pass baseline's as before, a
    /// blur's both passes with their halos.
    #[test]
    fn case_bytes_follow_the_cost_model() {
        let n = 512;
        let bytes = |name: &str| {
            let case = CASES.iter().find(|c| c.name == name).unwrap();
            let built = (case.build)(n);
            let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
            plan_bytes(&crate::graph::plan(&built.graph, &outputs).unwrap()).unwrap()
                / f64::from(n * n)
        };
        // rg32float moments in twice (2 × 8) and an rg32uint table out (8); a SAT_TILE² tile's last
        // row and column (2 × 8/64), read and written again as carries, and read once more.
        assert_eq!(
            bytes("sat fixed"),
            8.0 + 8.0 + 8.0 + 4.0 * 2.0 * 8.0 / f64::from(crate::sat::SAT_TILE)
        );
        // The first design: rg32float moments in (8), row scans out (16) and a block total per
        // row (1/32), their carries (2 × 2/32), the row scans again with a row carry per texel
        // (32) and column totals (1/32), the scans a third time with carries (32 + 1/32) and
        // the rgba32uint table (16).
        assert_eq!(
            bytes("sat fixed (5-pass, old)"),
            8.0 + 16.0 + 32.0 + 32.0 + 16.0 + 7.0 / 32.0
        );
        // Two passes of radius 4, 8 B out each: a row workgroup reads its 512 texels and 4 on
        // either side (520/512 × 8 B), a column workgroup 64 columns of 32 + 8 texels
        // (BLUR_COL_PER rows an invocation: 40/32 × 8 B).
        assert_eq!(
            bytes("blur rg32f r4"),
            520.0 / 512.0 * 8.0 + 8.0 + 40.0 / 32.0 * 8.0 + 8.0
        );
        // Depth (4 B) in, linear depth (4 B) out.
        assert_eq!(bytes("linearize"), 8.0);
    }
}
