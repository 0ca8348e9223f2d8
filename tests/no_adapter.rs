//! With no matching adapter, `Gpu::new` is one clear error naming the lavapipe package.
//! (Its own test binary: it sets a process-wide environment variable.)

#[test]
fn no_matching_adapter_names_the_software_driver() {
    // SAFETY: this binary has exactly one test, so no other thread reads the environment.
    unsafe { std::env::set_var("WGPU_ADAPTER_NAME", "no adapter is called this") };
    match shadowgraph::low_level::gpu::Gpu::new() {
        Ok(g) => panic!("matched adapter {}", g.describe()),
        Err(e) => {
            let m = e.to_string();
            assert!(
                m.contains("mesa-vulkan-drivers") && m.contains("no adapter is called this"),
                "{m}"
            );
        }
    }
}
