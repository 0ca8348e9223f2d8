//! The scene fuzzer (`tests/fuzz_support`) in `cargo test`: 3000 mutated scenes from a fixed
//! seed, loaded and planned in-process, every 80th accepted one rendered at 16×12 on the GPU.
//! No case may panic, print an error of more than one line or without its line, accept a
//! non-finite number, or render NaN. `cargo run --release --example fuzz_scenes` runs millions.

mod common;
mod fuzz_support;

#[test]
fn three_thousand_mutated_scenes() {
    let dir = std::env::temp_dir().join(format!("shadowgraph-fuzz-{}", std::process::id()));
    let opts = fuzz_support::Options {
        cases: 3000,
        seed: 0x5eed,
        first: 0,
        threads: 2,
        render_every: 80,
        dir: dir.clone(),
        progress: 0,
    };
    let s = fuzz_support::run(&opts, Some(common::gpu()));
    eprintln!("{s:?}");
    assert!(
        s.failures.is_empty(),
        "{} of {} cases failed (inputs in {}):\n{}",
        s.failures.len(),
        s.cases,
        dir.join("failures").display(),
        s.failures
            .iter()
            .take(20)
            .map(|(i, w)| format!("  case {i}: {w}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    // The mutations must reach both sides and the renderer, or the fuzzer tests nothing.
    assert_eq!(s.cases, 3000);
    assert!(s.accepted > 300 && s.refused > 1000, "{s:?}");
    assert!(s.rendered >= 4, "{s:?}");
    assert!(s.gltf_accepted >= 2 && s.gltf_refused >= 60, "{s:?}");
    std::fs::remove_dir_all(&dir).ok();
}
