//! The benchmark's memory check: the texture memory a case holds at a size, against the memory
//! budget a scene's frame is checked with, refused before any GPU work.

use super::cases::BenchCase;
use super::texels;
use crate::error::{Error, Result};

/// Texture memory case `case` holds at side `n`: its plan's slots and its imported textures
/// (the map the host would have rasterized).
pub fn case_bytes(case: &BenchCase, n: u32) -> Result<u64> {
    let built = (case.build)(n);
    let outputs: Vec<&str> = built.outputs.iter().map(String::as_str).collect();
    let plan = crate::graph::plan(&built.graph, &outputs)?;
    let imports: u64 = plan
        .resources
        .iter()
        .filter(|r| r.slot.is_none())
        .map(|r| r.bytes)
        .sum();
    Ok(plan.slot_bytes() + imports)
}

/// Refuses, before any GPU work, a case whose textures at one of `sizes` would pass the memory
/// `budget` ([`crate::limits::memory_budget`], as a scene's frame is checked): at 16384² CSSM's
/// nine tables alone are 36 GiB, which a CPU driver would try to take from system memory.
pub fn check_memory(cases: &[&BenchCase], sizes: &[u32], budget: u64) -> Result<()> {
    for &n in sizes {
        for case in cases {
            let need = case_bytes(case, n)?;
            if need > budget {
                let fix = "leave it out with --only, lower --sizes or raise the budget";
                return Err(past_budget(
                    &format!("`{}` at {n}²", case.name),
                    need,
                    budget,
                    fix,
                ));
            }
        }
    }
    Ok(())
}

/// [`check_memory`] for the yardstick [`measure_variants`](super::measure_variants) times at every size: a buffer copy
/// of two rgba32-sized buffers (8 GiB at 16384²).
pub(super) fn check_yardstick_memory(sizes: &[u32], budget: u64) -> Result<()> {
    for &n in sizes {
        let copies = 2 * texels(n) * 16;
        if copies > budget {
            let what = format!("the buffer copy at {n}² (every run's yardstick)");
            return Err(past_budget(
                &what,
                copies,
                budget,
                "lower --sizes or raise the budget",
            ));
        }
    }
    Ok(())
}

/// The error of [`check_memory`]: `what` needs `need` bytes, past `budget`; `fix` says what to do.
fn past_budget(what: &str, need: u64, budget: u64, fix: &str) -> Error {
    Error::Invalid(format!(
        "bench: {what} needs an estimated {}, more than the memory budget of {} ({}): {fix}",
        crate::graph::print::human_bytes(need),
        crate::graph::print::human_bytes(budget),
        crate::limits::MEMORY_BUDGET_ENV
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::select_cases;

    /// `shadowgraph bench` at its default sizes (up to 4096²) fits the default memory budget
    /// with every case and its yardstick, so its default run is never refused; at 16384² the
    /// buffer copy every run times (8 GiB) is refused under it, and so is CSSM with the CSM-Z
    /// search (nine tables, 36 GiB), naming the case, its estimate and the variable; a budget
    /// at the case's own estimate takes it. (Plans only, no GPU.)
    #[test]
    fn the_bench_checks_its_memory_against_the_budget() {
        let all = select_cases(&[]).expect("cases");
        let budget = crate::limits::DEFAULT_MEMORY_BUDGET;
        check_memory(&all, &[512, 1024, 2048, 4096], budget).expect("defaults fit");
        let csm_z = select_cases(&["csm_z".into()]).expect("csm_z");
        check_yardstick_memory(&[4096], budget).expect("the default sizes' copies fit");
        let e = check_yardstick_memory(&[16384], budget)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("buffer copy at 16384²") && e.contains("8.0 GiB"),
            "{e}"
        );
        let e = check_memory(&csm_z, &[16384], budget)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("csm_z") && e.contains("16384²") && e.contains("SHADOWGRAPH_MEMORY_BUDGET"),
            "{e}"
        );
        let need = case_bytes(csm_z[0], 16384).expect("estimate");
        // Nine rgba32uint tables of 16384² (the tile edges and carries on top).
        assert!(need >= 9 * 16384 * 16384 * 16, "{need}");
        check_memory(&csm_z, &[16384], need).expect("a budget at the estimate");
        assert!(check_memory(&csm_z, &[16384], need - 1).is_err());
    }
}
