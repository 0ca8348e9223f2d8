//! Reflected bindings, workgroup sizes and dispatches, and the default limits.

use super::*;

#[test]
fn compute_kernels_reflect_bindings_and_workgroup_size() {
    let wgsl = kernels::resolve("linearize", None).unwrap();
    let (_, r) = kernels::reflect("linearize", &wgsl).unwrap();
    let names: Vec<&str> = r.bindings.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["src", "dst", "params", "stats"]);
    assert_eq!(r.workgroup_size, Some([16, 16, 1]));
    assert_eq!(r.cpu_workgroup_size, r.workgroup_size, "one layout");
    assert!(matches!(
        r.binding("src").unwrap().ty,
        wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            ..
        }
    ));
}

/// A workgroup size that is an `override` of the layout (`GPU_LAYOUT`): reflection gives each
/// layout's, naga's evaluation of the overrides, and one whose value is unknown is an error
/// naming the kernel.
#[test]
fn workgroup_sizes_that_depend_on_the_layout_are_each_layouts() {
    let wgsl = "override GPU_LAYOUT: bool = false;\n\
                override N: u32 = select(4u, 64u, GPU_LAYOUT);\n\
                @compute @workgroup_size(N, 2)\nfn main() {}\n";
    let (_, r) = kernels::reflect("sized", wgsl).unwrap();
    assert_eq!(r.workgroup_size, Some([64, 2, 1]));
    assert_eq!(r.cpu_workgroup_size, Some([4, 2, 1]));
    assert_eq!(r.largest_workgroup(), Some([64, 2, 1]));
    assert_eq!(r.clone().in_layout(false).workgroup_size, Some([4, 2, 1]));
    assert_eq!(r.in_layout(true).workgroup_size, Some([64, 2, 1]));
    // The fused blurs: 256 invocations a tile on a GPU, CPU_LANES on a CPU driver.
    let wgsl = kernels::resolve("vsm_blur", None).unwrap();
    let (_, r) = kernels::reflect("vsm_blur", &wgsl).unwrap();
    assert_eq!(r.workgroup_size, Some([256, 1, 1]));
    assert_eq!(r.cpu_workgroup_size, Some([8, 1, 1]));
    let unknown = "override N: u32;\n@compute @workgroup_size(N)\nfn main() {}\n";
    let e = kernels::reflect("unsized", unknown)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unsized") && e.contains("workgroup size"), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// `const TEXELS_X` (texels an invocation covers along x) widens a workgroup's columns in the
/// dispatch, exactly; without it a workgroup covers its `@workgroup_size`; a value that is not a
/// u32 literal in 1..=64 is refused by name. Only the shading kernel declares it (the graph's
/// kernels size their dispatches by their nodes' own geometry, which does not read it).
#[test]
fn texels_x_widens_the_dispatch() {
    let kernel = |decl: &str| {
        format!(
            "{decl}\n@group(0) @binding(0) var dst: texture_storage_2d<r32float, write>;\n\
             @compute @workgroup_size(8, 4)\nfn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
             textureStore(dst, id.xy, vec4<f32>(1.0));\n}}\n"
        )
    };
    let groups = |decl: &str| {
        let (_, r) = kernels::reflect("t", &kernel(decl)).expect("reflect");
        (r.texels_x, r.groups_for(100, 17))
    };
    assert_eq!(groups(""), (1, [13, 5, 1]));
    assert_eq!(groups("const TEXELS_X: u32 = 1u;"), (1, [13, 5, 1]));
    // 100 columns in workgroups of 8 · 4 = 32: 4; 17 rows in 4s: 5.
    assert_eq!(groups("const TEXELS_X: u32 = 4u;"), (4, [4, 5, 1]));
    assert_eq!(groups("const TEXELS_X: u32 = 64u;"), (64, [1, 5, 1]));
    for bad in [
        "const TEXELS_X: u32 = 0u;",
        "const TEXELS_X: u32 = 65u;",
        "const TEXELS_X: f32 = 2.0;",
    ] {
        let e = kernels::reflect("t", &kernel(bad)).unwrap_err().to_string();
        assert!(e.contains("TEXELS_X") && e.contains("1..=64"), "{bad}: {e}");
    }
    for name in SOURCES
        .iter()
        .map(|s| s.name)
        .filter(|n| !n.starts_with("shared/"))
    {
        // The shading kernel resolves only with its generated block; every other kernel does.
        let Ok(wgsl) = kernels::resolve(name, None) else {
            assert_eq!(name, "shade");
            continue;
        };
        // Graph kernels covering several texels an invocation (their nodes dispatched by
        // texels, which follow it): the four-texel copies in every layout, the encodings in the
        // redesign layout only (an override of the layout).
        let (_, r) = kernels::reflect(name, &wgsl).expect("reflect");
        let want = match name {
            "copy_texture_x4" | "copy_texture_u32_x4" => [4, 4, 4],
            "vsm" | "esm" | "evsm" | "msm" | "csm" | "linearize" => [1, 1, 4],
            _ => [1, 1, 1],
        };
        let got = [r.texels_x, r.other_texels_x.cpu, r.other_texels_x.redesign];
        assert_eq!(
            got, want,
            "{name}: TEXELS_X in the gpu, cpu, redesign layouts"
        );
    }
    // An override of the layout, evaluated in each (the dispatch follows the layout's).
    let layered = "override GPU_LAYOUT: bool = false;\noverride REDESIGN: bool = false;\n\
                   override TEXELS_X: u32 = select(select(1u, 2u, GPU_LAYOUT), 4u, REDESIGN);";
    let wgsl = kernel(layered).replace(
        "textureStore(dst, id.xy, vec4<f32>(1.0));",
        "textureStore(dst, id.xy * TEXELS_X, vec4<f32>(1.0));",
    );
    let (_, r) = kernels::reflect("t", &wgsl).expect("reflect");
    assert_eq!((r.texels_x, r.groups_for(100, 17)), (2, [7, 5, 1]));
    let cpu = r.clone().in_layout(false);
    assert_eq!((cpu.texels_x, cpu.groups_for(100, 17)), (1, [13, 5, 1]));
    let redesign = r.in_redesign();
    assert_eq!(
        (redesign.texels_x, redesign.groups_for(100, 17)),
        (4, [4, 5, 1])
    );
}

/// Every compute kernel fits WebGPU's default limits (what `wgpu::Limits::default()` asks
/// for), so a host's ordinary device runs the stage: workgroup shape and memory (16 KiB),
/// bindings. The known exception, the mip chain: a dispatch binds seven storage textures (level
/// 0 and six levels, past the default four) and keeps 21840 bytes of levels in workgroup memory
/// (past the default 16 KiB; desktop adapters offer 32–64 KiB). A device with less is refused
/// by name before anything is created (`tests/plugin_errors/`); docs/PLUGIN.md says so.
#[test]
fn compute_kernels_fit_webgpu_default_limits() {
    let defaults = wgpu::Limits::default();
    let mut over = Vec::new();
    let mut checked = 0;
    for &id in KernelId::ALL {
        if id == KernelId::Shade {
            continue; // the shading kernel, checked per scene with its generated block
        }
        let wgsl = kernels::resolve(id.name(), None).expect("resolves");
        let (module, refl) = kernels::reflect(id.name(), &wgsl).expect("reflects");
        if refl.workgroup_size.is_none() {
            continue;
        }
        checked += 1;
        let needs =
            shadowgraph::low_level::limits::kernel_needs(&module, &refl, &defaults).expect("needs");
        for n in needs.iter().filter(|n| n.over()) {
            // (`mips_spd`, `mips_spd_log`: the chain's redesign, the same bindings.)
            let known = matches!(id.name(), "mips" | "mips_log" | "mips_spd" | "mips_spd_log")
                && matches!(
                    (n.limit_name, n.requested),
                    ("max_storage_textures_per_shader_stage", 7)
                        | ("max_compute_workgroup_storage_size", 21840)
                );
            if !known {
                over.push(format!("{id}: {n:?}"));
            }
        }
    }
    assert!(checked >= 20, "only {checked} compute kernels reflected");
    assert!(
        over.is_empty(),
        "past WebGPU's defaults:\n{}",
        over.join("\n")
    );
}
