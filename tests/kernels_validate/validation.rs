//! Every kernel validates with naga, with each technique's block and each storage variant.

use super::*;

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

/// The storage-buffer variant (`exec::buffers`) of every kernel that writes or reads an
/// intermediate the redesign layout keeps in a buffer validates, as the executor specializes
/// it: every technique's plan (its shading maps requested, 64² and 1024² maps), its slots
/// placed as `exec::buffer_slots` places them at WebGPU's default limits, each kernel the file
/// that layout compiles (`KernelLayout::kernel_source`), with the shipped modules and with the
/// redesigned ones a device with subgroups takes. With either, the blur's passes, the fused
/// blurs' row kernels (both kinds), the tables' carries and their tile passes (whose shipped
/// modules hand the carries to functions: specialized, `exec::monomorph`) are rewritten.
#[test]
fn storage_buffer_variants_validate() {
    use shadowgraph::low_level::exec::{KernelLayout, buffer_slots, specialized_buffer_source};
    use shadowgraph::low_level::graph::{Graph, plan, texture_format};
    let redesign = KernelLayout::Redesign;
    let modules: kernels::Replacements = redesign
        .module_sources(wgpu::Features::all())
        .into_iter()
        .map(|(shipped, module)| {
            let text = kernels::source(module).expect("redesigned module");
            (shipped.to_string(), text.to_string())
        })
        .collect();
    let limits = wgpu::Limits::default();
    let mut failures = Vec::new();
    let mut rewritten = [BTreeSet::new(), BTreeSet::new()];
    let mut techniques = all_techniques();
    // The fused blurs' two-pass fallback (past their tile's radius 7).
    for radius in [3.0, 12.0] {
        let filter = Filter::Blur {
            radius,
            sigma: radius / 2.0,
            kernel: BlurKernel::Gaussian,
        };
        let prefilter = StorageFilter {
            storage: Storage::F32,
            filter,
        };
        techniques.push(Technique::Vsm {
            prefilter,
            bleed: 0.2,
            min_variance: 1e-5,
        });
        techniques.push(Technique::Msm {
            prefilter,
            hausdorff: false,
            moment_bias: 6e-5,
            bleed: 0.0,
        });
    }
    // 64²: the fused kernels' own rows; 1024²: their `*_blur_row` kernels' full rows.
    let lights = techniques.into_iter().flat_map(|t| {
        [64, 1024].map(|side| Light {
            shadow_map: side,
            ..light(t)
        })
    });
    for light in lights {
        let technique = &light.shadow.technique;
        let mut graph = Graph::default();
        let input = shadowgraph::low_level::technique::add_light_nodes(&mut graph, 0, &light);
        let outputs: Vec<&str> = input.maps.iter().map(String::as_str).collect();
        let Ok(plan) = plan(&graph, &outputs) else {
            failures.push(format!("{technique:?}: no plan"));
            continue;
        };
        for (k, with) in [None, Some(&modules)].into_iter().enumerate() {
            let held = match buffer_slots(&plan, redesign, &limits, with, true) {
                Ok(h) => h,
                Err(e) => {
                    failures.push(format!("{technique:?}: {e}"));
                    continue;
                }
            };
            let in_buffer = |r: &str| {
                let p = plan.resource(r)?;
                held[p.slot?].then_some([p.width, p.height])
            };
            for step in &plan.steps {
                let node = &step.node;
                let slots = node.inputs.iter().chain(&node.outputs);
                let buffers: Vec<(String, [u32; 2])> = slots
                    .clone()
                    .filter_map(|(b, r)| in_buffer(r).map(|wh| (b.clone(), wh)))
                    .collect();
                if buffers.is_empty() {
                    continue;
                }
                let formats: Vec<(String, wgpu::TextureFormat)> = slots
                    .filter_map(|(b, r)| {
                        let f = plan.resource(r)?.resource.format;
                        Some((b.clone(), texture_format(f)))
                    })
                    .collect();
                let kernel = redesign.kernel_source(node.kernel.name());
                match specialized_buffer_source(kernel, &formats, &buffers, with) {
                    Ok(wgsl) => {
                        rewritten[k].insert(kernel.to_string());
                        if let Err(e) = kernels::reflect(kernel, &wgsl) {
                            failures.push(format!("{technique:?} {kernel}: {e}"));
                        }
                    }
                    Err(e) => failures.push(format!("{technique:?} {kernel}: {e}")),
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let both = [
        "blur",
        "vsm_blur",
        "msm_blur",
        "vsm_blur_row",
        "msm_blur_row",
    ];
    let tables = ["sat_carries_scan", "vsm_sat_tile_sums", "vsm_sat_tiles"];
    for set in &rewritten {
        for k in both.iter().chain(&tables) {
            assert!(set.contains(*k), "{k} rewritten: {set:?}");
        }
    }
}
