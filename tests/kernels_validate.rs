//! Every WGSL file parses and validates with naga (no GPU needed); Rust mirrors of WGSL
//! structs match naga's layout.

use std::collections::BTreeSet;

use shadowgraph::low_level::exec::REDESIGNED_MODULES;
use shadowgraph::low_level::kernels::{self, KernelId, SOURCES, struct_size};
use shadowgraph::low_level::technique::shading_block;
use shadowgraph::low_level::wgsl_mirrors::LinearizeParams;
use shadowgraph::{
    BlurKernel, Filter, Light, LightGpu, LightKind, PcfKernel, SatVariant, Shadow, Soft, Storage,
    StorageFilter, Technique,
};

fn light(technique: Technique) -> Light {
    Light {
        kind: LightKind::Spot { fov_degrees: 60.0 },
        position: glam::Vec3::new(0.0, 5.0, 0.0),
        target: glam::Vec3::ZERO,
        near: 0.5,
        far: 20.0,
        size: 0.5,
        radiance: glam::Vec3::ONE,
        shadow_map: 64,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 1.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: shadowgraph::Cascades::SINGLE,
        },
    }
}

fn all_techniques() -> Vec<Technique> {
    vec![
        Technique::Hard,
        Technique::Pcf {
            radius: 2,
            kernel: PcfKernel::Box,
        },
        Technique::Pcf {
            radius: 1,
            kernel: PcfKernel::Tent,
        },
        Technique::Pcf {
            radius: 1,
            kernel: PcfKernel::Hardware,
        },
        Technique::Pcss {
            blocker_samples: 16,
            filter_samples: 32,
            max_search: 0.1,
        },
        Technique::Vsm {
            prefilter: StorageFilter {
                storage: Storage::F16,
                filter: Filter::Blur {
                    radius: 2.0,
                    sigma: 1.0,
                    kernel: BlurKernel::Box,
                },
            },
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Evsm {
            prefilter: StorageFilter {
                storage: Storage::F32,
                filter: Filter::None,
            },
            four: true,
            exp_pos: 40.0,
            exp_neg: 5.0,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        Technique::Esm {
            filter: Filter::Mips {
                width: 4.0,
                max_anisotropy: 0,
            },
            exponent: 80.0,
        },
        Technique::Msm {
            prefilter: StorageFilter {
                storage: Storage::Unorm16,
                filter: Filter::Mips {
                    width: 2.0,
                    max_anisotropy: 0,
                },
            },
            hausdorff: true,
            moment_bias: 6e-5,
            bleed: 0.0,
        },
        Technique::Csm {
            prefilter: StorageFilter {
                storage: Storage::F16,
                filter: Filter::None,
            },
            terms: 7,
            attenuation: 1.0,
            offset: 0.05,
            scale: 2.0,
        },
        Technique::Cssm {
            soft: soft(Storage::F32, SatVariant::Fixed),
            terms: 5,
            attenuation: 1.0,
            offset: 0.1,
            scale: 2.0,
            sharpen: 2.0,
            sharpen_falloff: 50.0,
            search: shadowgraph::CssmSearch::Moments,
            resolve: shadowgraph::CssmResolve::TwoDepthSearch,
        },
        Technique::Cssm {
            soft: soft(Storage::F16, SatVariant::Float),
            terms: 2,
            attenuation: 1.0,
            offset: 0.1,
            scale: 2.0,
            sharpen: 0.0,
            sharpen_falloff: 0.0,
            search: shadowgraph::CssmSearch::CsmZ,
            resolve: shadowgraph::CssmResolve::Sharpen,
        },
        Technique::Vssm {
            soft: soft(Storage::F32, SatVariant::Fixed),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Vssm {
            soft: soft(Storage::F16, SatVariant::Float),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::MsmSoft {
            soft: soft(Storage::Unorm16, SatVariant::Fixed),
            hausdorff: true,
            moment_bias: 6e-5,
            bleed: 0.0,
        },
        Technique::MsmSoft {
            soft: soft(Storage::F32, SatVariant::Float),
            hausdorff: false,
            moment_bias: 1e-5,
            bleed: 0.0,
        },
    ]
}

fn soft(storage: Storage, sums: SatVariant) -> Soft {
    Soft {
        storage,
        sums,
        max_search: 0.1,
    }
}

#[test]
fn every_file_in_kernels_is_registered() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels");
    let mut on_disk = BTreeSet::new();
    for sub in ["", "shared/"] {
        for e in std::fs::read_dir(dir.join(sub)).expect("kernels/ readable") {
            let p = e.expect("dir entry").path();
            if p.extension().is_some_and(|x| x == "wgsl") {
                let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
                on_disk.insert(format!("{sub}{stem}"));
            }
        }
    }
    let registered: BTreeSet<String> = SOURCES.iter().map(|s| s.name.to_string()).collect();
    assert_eq!(
        on_disk, registered,
        "kernels/ and kernels::SOURCES disagree"
    );
}

/// The ids `build.rs` generates match the folder as it is now (a stale build, or a file the
/// script skipped, fails here), and each id's source is its file's text, which naga parses
/// once its imports are resolved (`shade` with a generated block).
#[test]
fn every_kernel_file_has_an_id_whose_source_parses() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels");
    let mut on_disk = BTreeSet::new();
    for e in std::fs::read_dir(&dir).expect("kernels/ readable") {
        let p = e.expect("dir entry").path();
        if p.extension().is_some_and(|x| x == "wgsl") {
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            on_disk.insert(stem.to_string());
        }
    }
    let ids: BTreeSet<String> = KernelId::ALL.iter().map(|k| k.name().to_string()).collect();
    assert_eq!(on_disk, ids, "kernels/*.wgsl and KernelId::ALL disagree");
    let block = shading_block(&[light(Technique::Hard)]);
    let mut failures = Vec::new();
    for &id in KernelId::ALL {
        let file = std::fs::read_to_string(dir.join(format!("{}.wgsl", id.name())));
        assert_eq!(file.ok().as_deref(), Some(id.source()), "{id}: source");
        assert_eq!(KernelId::from_name(id.name()), Some(id));
        let generated = (id == KernelId::Shade).then_some(block.as_str());
        let parsed = kernels::resolve(id.name(), generated)
            .map_err(|e| e.to_string())
            .and_then(|wgsl| {
                naga::front::wgsl::parse_str(&wgsl).map_err(|e| e.emit_to_string(&wgsl))
            });
        if let Err(e) = parsed {
            failures.push(format!("{id}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn every_kernel_validates() {
    let mut failures = Vec::new();
    for s in SOURCES {
        // The shading kernel needs its generated block: validate it once per technique, and
        // with every technique at once.
        let blocks: Vec<Option<String>> = if s.name == "shade" {
            let mut b: Vec<Option<String>> = all_techniques()
                .into_iter()
                .map(|t| Some(shading_block(&[light(t)])))
                .collect();
            let lights: Vec<Light> = all_techniques().into_iter().map(light).collect();
            b.push(Some(shading_block(&lights)));
            b
        } else {
            vec![None]
        };
        // A module its importers complete (`// #completed-by-importer`, e.g.
        // shared/encode_blur: each kernel gives its encoding and `Params`) validates inside
        // each kernel that imports it, and at least one must.
        if s.text.contains("// #completed-by-importer") {
            // A redesigned module stands in for its shipped one (validated below in the
            // shipped one's importers).
            let name = REDESIGNED_MODULES
                .iter()
                .find(|m| m.1 == s.name)
                .map_or(s.name, |m| m.0);
            let import = format!("// #import {name}");
            if !SOURCES.iter().any(|k| k.text.contains(&import)) {
                failures.push(format!(
                    "{}: completed by importers, but none imports it",
                    s.name
                ));
            }
            continue;
        }
        for block in blocks {
            let result = kernels::resolve(s.name, block.as_deref())
                .and_then(|wgsl| kernels::reflect(s.name, &wgsl).map(|_| ()));
            if let Err(e) = result {
                failures.push(e.to_string());
            }
        }
    }
    // Every kernel importing a redesigned module's shipped one validates with the redesign in
    // its place, as the redesign layout compiles it on a device with the feature it needs.
    for (shipped, redesign, _) in REDESIGNED_MODULES {
        let text = kernels::source(redesign)
            .expect("redesigned module")
            .to_string();
        let extra = kernels::Replacements::from([(shipped.to_string(), text)]);
        let mut importers = 0;
        for k in SOURCES.iter().filter(|k| !k.name.starts_with("shared/")) {
            let plain = kernels::resolve(k.name, None);
            let Ok(wgsl) = kernels::resolve_in(k.name, None, Some(&extra)) else {
                continue;
            };
            if plain.is_ok_and(|p| p != wgsl) {
                importers += 1;
                if let Err(e) = kernels::reflect(k.name, &wgsl) {
                    failures.push(format!("{} with {redesign}: {e}", k.name));
                }
            }
        }
        if importers == 0 {
            failures.push(format!("{redesign}: no kernel imports {shipped}"));
        }
    }
    assert!(
        failures.is_empty(),
        "{} kernel(s) failed:\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

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

#[test]
fn missing_import_and_missing_block_are_named_errors() {
    assert!(kernels::resolve("nonexistent", None).is_err());
    let e = kernels::resolve("shade", None).unwrap_err().to_string();
    assert!(e.contains("shade") && e.contains("generated"), "{e}");
}

#[test]
fn rust_mirrors_match_naga_layouts() {
    let shade = kernels::resolve("shade", Some(&shading_block(&[light(Technique::Hard)]))).unwrap();
    let (m, _) = kernels::reflect("shade", &shade).unwrap();
    assert_eq!(
        struct_size(&m, "Light"),
        Some(size_of::<LightGpu>() as u32),
        "LightGpu vs struct Light"
    );
    assert_eq!(
        struct_size(&m, "Frame"),
        Some(size_of::<shadowgraph::low_level::wgsl_mirrors::FrameGpu>() as u32),
        "FrameGpu vs struct Frame"
    );
    use shadowgraph::low_level::filter::BlurParams;
    use shadowgraph::low_level::technique::CsmSatParams;
    use shadowgraph::low_level::wgsl_mirrors::{
        CsmParams, ExpParams, MsmParams, SecondDepthParams, VsmParams,
    };
    for (kernel, rust) in [
        ("second_depth", size_of::<SecondDepthParams>()),
        ("csm", size_of::<CsmParams>()),
        ("csm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("csm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("csm_sat_tiles", size_of::<CsmSatParams>()),
        ("csm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("msm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("msm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("msm_sat_tiles", size_of::<CsmSatParams>()),
        ("msm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("vsm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("vsm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("vsm_sat_tiles", size_of::<CsmSatParams>()),
        ("vsm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("evsm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("evsm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("evsm_sat_tiles", size_of::<CsmSatParams>()),
        ("evsm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("esm_sat_tile_sums", size_of::<CsmSatParams>()),
        ("esm_sat_tile_sums_f32", size_of::<CsmSatParams>()),
        ("esm_sat_tiles", size_of::<CsmSatParams>()),
        ("esm_sat_tiles_f32", size_of::<CsmSatParams>()),
        ("vsm", size_of::<VsmParams>()),
        ("evsm", size_of::<ExpParams>()),
        ("esm", size_of::<ExpParams>()),
        ("msm", size_of::<MsmParams>()),
        // The encodings fused into the blur: the encoding's parameters, then the blur's.
        ("vsm_blur", size_of::<VsmParams>() + size_of::<BlurParams>()),
        (
            "vsm_blur_row",
            size_of::<VsmParams>() + size_of::<BlurParams>(),
        ),
        (
            "evsm_blur",
            size_of::<ExpParams>() + size_of::<BlurParams>(),
        ),
        ("msm_blur", size_of::<MsmParams>() + size_of::<BlurParams>()),
        (
            "msm_blur_row",
            size_of::<MsmParams>() + size_of::<BlurParams>(),
        ),
        (
            "evsm_blur_row",
            size_of::<ExpParams>() + size_of::<BlurParams>(),
        ),
    ] {
        let wgsl = kernels::resolve(kernel, None).unwrap();
        let (m, _) = kernels::reflect(kernel, &wgsl).unwrap();
        assert_eq!(
            struct_size(&m, "Params").or(struct_size(&m, "CsmSatParams")),
            Some(rust as u32),
            "Rust params vs {kernel}'s Params"
        );
        assert_eq!(
            struct_size(&m, "DepthParams"),
            Some(size_of::<LinearizeParams>() as u32),
            "LinearizeParams vs {kernel}'s DepthParams"
        );
    }
}

#[test]
fn shading_block_contains_only_the_techniques_used() {
    let b = shading_block(&[light(Technique::Hard)]);
    assert!(
        b.contains("vis_hard") && !b.contains("vis_pcss") && !b.contains("vis_pcf"),
        "{b}"
    );
}

#[test]
fn storage_format_variants_validate() {
    // The executor re-declares `dst` for the bound format; every format a technique can bind
    // must give a valid kernel.
    let mut failures = Vec::new();
    let all: &[&str] = &[
        "r32float",
        "rg32float",
        "rgba32float",
        "rgba16float",
        "rgba16unorm",
    ];
    for (kernel, declared, formats) in [
        ("vsm", "rg32float", &["rg32float", "rgba16float"][..]),
        ("blur", "rg32float", all),
        ("blur_log", "rg32float", &["r32float"][..]),
        ("blur_log_wide", "rg32float", &["r32float"][..]),
        ("msm", "rgba32float", &["rgba16float", "rgba16unorm"][..]),
        (
            "csm",
            "rgba32float",
            &["r32float", "rg32float", "rgba16float"][..],
        ),
        ("mips", "rgba32float", all),
        ("mips_log", "rgba32float", &["r32float"][..]),
        ("mips_spd", "rgba32float", all),
        ("mips_spd_log", "rgba32float", &["r32float"][..]),
        ("sat_tile_sums", "rgba32uint", &["r32uint", "rg32uint"][..]),
        (
            "sat_tile_sums_f32",
            "rgba32uint",
            &["r32uint", "rg32uint"][..],
        ),
        ("sat_carries", "rgba32uint", &["r32uint", "rg32uint"][..]),
        ("sat_tiles", "rgba32uint", &["r32uint", "rg32uint"][..]),
        (
            "sat_tiles_f32",
            "rgba32float",
            &["r32float", "rg32float"][..],
        ),
        // The depth-sourced tables: edges of the widest table's channels (`sat::layers`),
        // VSM's and EVSM2's two-channel tables, ESM's one-channel table, CSM's at M = 1.
        ("csm_sat_tile_sums", "rgba32uint", &["rg32uint"][..]),
        ("csm_sat_tiles", "rgba32uint", &["rg32uint"][..]),
        ("csm_sat_tiles_f32", "rgba32float", &["rg32float"][..]),
        ("vsm_sat_tile_sums", "rgba32uint", &["rg32uint"][..]),
        ("vsm_sat_tile_sums_f32", "rgba32uint", &["rg32uint"][..]),
        ("vsm_sat_tiles", "rgba32uint", &["rg32uint"][..]),
        ("vsm_sat_tiles_f32", "rgba32float", &["rg32float"][..]),
        ("evsm_sat_tile_sums", "rgba32uint", &["rg32uint"][..]),
        ("evsm_sat_tiles", "rgba32uint", &["rg32uint"][..]),
        ("evsm_sat_tiles_f32", "rgba32float", &["rg32float"][..]),
        ("esm_sat_tile_sums", "rgba32uint", &["r32uint"][..]),
        ("esm_sat_tile_sums_f32", "rgba32uint", &["r32uint"][..]),
        ("esm_sat_tiles", "rgba32uint", &["r32uint"][..]),
        ("esm_sat_tiles_f32", "rgba32float", &["r32float"][..]),
    ] {
        let base = kernels::resolve(kernel, None).unwrap();
        for f in formats {
            let mut wgsl = base.clone();
            let mips = (0..7).map(|k| format!("dst{k}"));
            let sat = ["col_part", "row_part", "col_carry", "row_carry"].map(String::from);
            for var in ["dst".to_string()].into_iter().chain(mips).chain(sat) {
                wgsl = wgsl.replace(
                    &format!("var {var}: texture_storage_2d<{declared},"),
                    &format!("var {var}: texture_storage_2d<{f},"),
                );
            }
            if let Err(e) = kernels::reflect(kernel, &wgsl) {
                failures.push(format!("{kernel}@{f}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The packed variant (`exec::packed`) of every kernel that writes or reads a two-moment
/// representation in f16 (`graph::PACKED_F16X2`, an r32uint texture bound to a float binding)
/// validates: the encodings, the fused blurs, the blur passes, the mip chain and the summed-area
/// tables' tile passes, each re-declared and rewritten as the executor does.
#[test]
fn packed_f16_variants_validate() {
    let packed = shadowgraph::low_level::graph::texture_format(shadowgraph::PACKED_F16X2);
    let mut failures = Vec::new();
    let mut rewritten = 0;
    for kernel in [
        "vsm",
        "evsm",
        "vsm_blur",
        "vsm_blur_row",
        "evsm_blur",
        "evsm_blur_row",
        "blur",
        "mips",
        "mips_spd",
        "sat_tile_sums",
        "sat_tile_sums_f32",
        "sat_tiles",
        "sat_tiles_f32",
    ] {
        // The depth the encodings read stays float; every other float texture is packed.
        let src = !kernel.starts_with("vsm") && !kernel.starts_with("evsm");
        let mut bound: Vec<(String, wgpu::TextureFormat)> =
            (0..7).map(|k| (format!("dst{k}"), packed)).collect();
        bound.push(("dst".into(), packed));
        if src {
            bound.push(("src".into(), packed));
        }
        if kernel.starts_with("sat") {
            bound.retain(|(b, _)| b == "src");
        }
        match shadowgraph::low_level::exec::specialized_source(kernel, &bound) {
            Ok(wgsl) => {
                rewritten += usize::from(wgsl.contains("pack_f16x2("));
                if let Err(e) = kernels::reflect(kernel, &wgsl) {
                    failures.push(format!("{kernel}: {e}"));
                }
            }
            Err(e) => failures.push(format!("{kernel}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(rewritten, 13, "every variant packs or unpacks");
}

/// Every compute kernel fits WebGPU's default limits (what `wgpu::Limits::default()` asks
/// for), so a host's ordinary device runs the stage: workgroup shape and memory (16 KiB),
/// bindings. The known exception, the mip chain: a dispatch binds seven storage textures (level
/// 0 and six levels, past the default four) and keeps 21840 bytes of levels in workgroup memory
/// (past the default 16 KiB; desktop adapters offer 32–64 KiB). A device with less is refused
/// by name before anything is created (`tests/plugin_errors.rs`); docs/PLUGIN.md says so.
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
        let needs = shadowgraph::low_level::limits::kernel_needs(&module, &refl, &defaults).expect("needs");
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

/// A `const NAME: u32` of a kernel, from naga's IR (following a constant defined as another).
fn wgsl_const(module: &naga::Module, name: &str) -> Option<u32> {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))?;
    let mut init = c.init;
    loop {
        match module.global_expressions[init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => return Some(v),
            naga::Expression::Constant(h) => init = module.constants[h].init,
            _ => return None,
        }
    }
}

/// The blur passes' geometry that `filter::add_filter` dispatches by is the kernels' own: a
/// column invocation of `blur` writes `BLUR_COL_PER` rows, one of `blur_log` `PER`.
#[test]
fn blur_dispatch_constants_match_the_wgsl() {
    use shadowgraph::low_level::filter::{BLUR_COL_PER, BLUR_GROUP, BLUR_PER_INVOCATION};
    for (kernel, col_per) in [
        ("blur", BLUR_COL_PER),
        ("blur_log", BLUR_PER_INVOCATION),
        ("blur_log_wide", BLUR_PER_INVOCATION),
    ] {
        let wgsl = kernels::resolve(kernel, None).expect("resolve");
        let (module, r) = kernels::reflect(kernel, &wgsl).expect("reflect");
        assert_eq!(
            wgsl_const(&module, "PER"),
            Some(BLUR_PER_INVOCATION),
            "{kernel}: PER"
        );
        assert_eq!(
            wgsl_const(&module, "COL_PER"),
            Some(col_per),
            "{kernel}: COL_PER"
        );
        assert_eq!(
            r.workgroup_size,
            Some([BLUR_GROUP, 1, 1]),
            "{kernel}: workgroup"
        );
    }
}

/// The peel pass discards by the margin the f64 reference of the second depth
/// (`truth::peel`) peels by: `PEEL_EPSILON` in `shadow_peel.wgsl` is `wgsl_mirrors`'s.
#[test]
fn peel_epsilon_matches_the_wgsl() {
    let wgsl = kernels::resolve("shadow_peel", None).expect("resolve");
    let (module, _) = kernels::reflect("shadow_peel", &wgsl).expect("reflect");
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some("PEEL_EPSILON"))
        .expect("PEEL_EPSILON in shadow_peel.wgsl");
    let value = match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::F32(v)) => v,
        ref e => panic!("PEEL_EPSILON is {e:?}, not an f32 literal"),
    };
    assert_eq!(value, shadowgraph::low_level::wgsl_mirrors::PEEL_EPSILON);
}

/// `blur_log`'s span, past which only `blur_log_wide` is exact, is the planner's
/// `LOG_BLUR_SPAN` (`BlurMode::log_sum_exp` picks the kernel by it), and `blur_log` has no
/// per-output path (`WIDE` false) where `blur_log_wide` has one.
#[test]
fn log_blur_span_matches_the_wgsl() {
    for (kernel, wide) in [("blur_log", false), ("blur_log_wide", true)] {
        let wgsl = kernels::resolve(kernel, None).expect("resolve");
        let (module, _) = kernels::reflect(kernel, &wgsl).expect("reflect");
        let literal = |name: &str| {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("{name} in {kernel}"));
            module.global_expressions[c.init].clone()
        };
        assert!(
            matches!(literal("SPAN"), naga::Expression::Literal(naga::Literal::F32(v))
                if v == shadowgraph::low_level::filter::LOG_BLUR_SPAN),
            "{kernel}: SPAN"
        );
        assert!(
            matches!(literal("WIDE"), naga::Expression::Literal(naga::Literal::Bool(w)) if w == wide),
            "{kernel}: WIDE"
        );
    }
    use shadowgraph::low_level::filter::BlurMode;
    assert_eq!(BlurMode::log_sum_exp(80.0), BlurMode::LogSumExp);
    assert_eq!(BlurMode::log_sum_exp(80.5), BlurMode::LogSumExpWide);
}

#[test]
fn encode_blur_dispatch_constants_match_the_wgsl() {
    use shadowgraph::low_level::filter::{
        ENCODE_BLUR_TILE_RADIUS, encode_blur_cpu_rows, encode_blur_row, encode_blur_row_kernel,
        encode_blur_tile,
    };
    use shadowgraph::low_level::kernels::KernelId;
    // The row kernels where their rows are full, else the tile kernels' shorter rows.
    for (kernel, width, row) in [
        (KernelId::VsmBlur, 1023, KernelId::VsmBlur),
        (KernelId::VsmBlur, 1024, KernelId::VsmBlurRow),
        (KernelId::EvsmBlur, 511, KernelId::EvsmBlur),
        (KernelId::MsmBlur, 512, KernelId::MsmBlurRow),
        (KernelId::EvsmBlur, 4096, KernelId::EvsmBlurRow),
        (KernelId::Blur, 4096, KernelId::Blur),
    ] {
        assert_eq!(
            encode_blur_row_kernel(kernel, width),
            row,
            "{kernel:?} at {width}"
        );
    }
    for kernel in [
        KernelId::VsmBlur,
        KernelId::VsmBlurRow,
        KernelId::EvsmBlur,
        KernelId::EvsmBlurRow,
        KernelId::MsmBlur,
        KernelId::MsmBlurRow,
    ] {
        let name = kernel.name();
        let wgsl = kernels::resolve(name, None).expect("resolve");
        let (module, r) = kernels::reflect(name, &wgsl).expect("reflect");
        let tile = encode_blur_tile(kernel);
        for (constant, rust) in [
            ("TILE", tile),
            ("CPU_TILE_ROWS", encode_blur_cpu_rows(kernel)),
            ("ROW", encode_blur_row(kernel)),
            ("TILE_RADIUS", ENCODE_BLUR_TILE_RADIUS),
        ] {
            assert_eq!(
                wgsl_const(&module, constant),
                Some(rust),
                "{name}: {constant}"
            );
        }
        // One invocation per output of a row; a tile's encoded texels in at most six blocks of
        // WG_SIZE (`encode_tile`). Its blur: with two channels in runs of RUN = 4
        // (four named sums), one run an invocation along x (TILE / RUN a row of the encoded
        // tile) and along y; with four, one output an invocation, the horizontal sums in at
        // most four blocks of WG_SIZE (`blur_tile_single`'s h0 … h3).
        let wg = r.workgroup_size.expect("workgroup size")[0];
        assert_eq!(wg, 256, "{name}: workgroup");
        // A CPU driver's layout: CPU_LANES invocations walk the tile in strips (and run the
        // row path's WG_SIZE invocations' work in turn).
        let lanes = wgsl_const(&module, "CPU_LANES").expect("CPU_LANES");
        assert_eq!(
            r.cpu_workgroup_size,
            Some([lanes, 1, 1]),
            "{name}: CPU workgroup"
        );
        assert!(lanes < wg && wg % lanes == 0, "{name}: CPU_LANES");
        // The row: ROW_RUN outputs an invocation, every invocation busy (2 with two channels,
        // `blur_row_pairs`; 1 with four).
        let row = encode_blur_row(kernel);
        let row_run = wgsl_const(&module, "ROW_RUN").expect("ROW_RUN");
        assert_eq!(row, row_run * wg, "{name}: ROW = ROW_RUN · WG_SIZE");
        let enc = tile + 2 * ENCODE_BLUR_TILE_RADIUS;
        assert!(enc * enc <= 6 * wg, "{name}: encoded tile");
        let run = wgsl_const(&module, "RUN").expect("RUN");
        let channels = wgsl_const(&module, "CHANNELS").expect("CHANNELS");
        match channels {
            2 => {
                // `vsm_blur_row`'s runs of 4 (`blur_row_quads`), `vsm_blur`'s of 2
                // (`blur_row_pairs`).
                let want = if kernel == KernelId::VsmBlurRow { 4 } else { 2 };
                assert_eq!(row_run, want, "{name}: ROW_RUN");
                assert_eq!(run, 4, "{name}: RUN (the sums s0 … s3)");
                assert_eq!(tile % run, 0, "{name}: runs per line");
                assert!(tile / run * enc <= wg, "{name}: runs along x");
                assert!(tile / run * tile <= wg, "{name}: runs along y");
            }
            _ => {
                // The row kernels' runs of 2 (`blur_row_pairs`), else one output an invocation.
                let row_kernel = matches!(kernel, KernelId::EvsmBlurRow | KernelId::MsmBlurRow);
                assert_eq!(row_run, if row_kernel { 2 } else { 1 }, "{name}: ROW_RUN");
                assert_eq!(run, 1, "{name}: RUN (one output an invocation)");
                assert!(tile * enc <= 4 * wg, "{name}: horizontal sums");
            }
        }
        // Workgroup memory: the encoded tile with its halo and the fallback's encoded row
        // (each encoding reads its depths straight from the texture), no more.
        let sh = wgsl_const(&module, "SH_TEXELS").expect("SH_TEXELS");
        let max_radius = wgsl_const(&module, "MAX_RADIUS").expect("MAX_RADIUS");
        let widest_row = [
            KernelId::VsmBlurRow,
            KernelId::EvsmBlurRow,
            KernelId::MsmBlurRow,
        ]
        .into_iter()
        .chain([kernel])
        .filter(|k| encode_blur_tile(*k) == tile)
        .map(encode_blur_row)
        .max()
        .unwrap();
        assert_eq!(
            sh,
            (enc * enc).max(widest_row + 2 * max_radius),
            "{name}: SH_TEXELS (the encoded tile or the widest encoded row sharing the module)"
        );
        assert!(
            sh * 4 * channels <= 16384,
            "{name}: 16 KiB of workgroup memory"
        );
    }
}
