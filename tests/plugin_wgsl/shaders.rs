//! The exported library and every host block validate with naga; exported names are prefixed.

use super::*;

fn every_technique() -> Vec<Technique> {
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Box,
    };
    vec![
        Technique::Hard,
        Technique::Pcf {
            radius: 2,
            kernel: PcfKernel::Tent,
        },
        Technique::Pcf {
            radius: 0,
            kernel: PcfKernel::Hardware,
        },
        Technique::Pcss {
            blocker_samples: 16,
            filter_samples: 32,
            max_search: 0.1,
        },
        PrefilterConfig::vsm(64).technique,
        PrefilterConfig::vsm(64)
            .with_storage(Storage::F16)
            .with_filter(blur)
            .technique,
        PrefilterConfig::evsm2(64).technique,
        PrefilterConfig::evsm4(64)
            .with_storage(Storage::F16)
            .technique,
        PrefilterConfig::esm(64).with_filter(Filter::None).technique,
        PrefilterConfig::cssm(64, 5, 0.5).technique,
        PrefilterConfig::vssm(64, 0.5)
            .with_soft(shadowgraph::SatVariant::Float, 0.2)
            .technique,
        PrefilterConfig::msm_soft(64, 0.5)
            .with_storage(Storage::Unorm16)
            .technique,
    ]
}

#[test]
fn exported_library_is_current() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(wgsl::LIBRARY_PATH);
    let generated = wgsl::library().expect("library resolves");
    if std::env::var_os("SHADOWGRAPH_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().expect("parent")).expect("mkdir");
        std::fs::write(&path, &generated).expect("write the exported WGSL");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale: regenerate with `SHADOWGRAPH_BLESS=1 cargo test --release --test \
         plugin_wgsl`",
        wgsl::LIBRARY_PATH
    );
    assert!(!generated.contains("#import"), "imports left unresolved");
}

/// What a host writes around the committed file: its own bindings, a `Light` uniform and a
/// fragment shader calling the visibility functions.
const HOST_SHADER: &str = "
@group(0) @binding(0) var<uniform> shadow_light: sg_Light;
@group(1) @binding(0) var vsm_map: texture_2d<f32>;
@group(1) @binding(1) var esm_map: texture_2d<f32>;
@group(1) @binding(2) var raw_depth: texture_depth_2d;
@group(1) @binding(3) var shadow_cmp: sampler_comparison;

@fragment
fn fs_main(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> @location(0) vec4<f32> {
    let s = sg_light_sample(shadow_light, p, normalize(n));
    var v = vec3<f32>(1.0);
    if s.inside {
        v = vec3<f32>(sg_vis_vsm(vsm_map, shadow_light, s), sg_vis_esm(esm_map, shadow_light, s),
                      sg_vis_pcf_hardware(raw_depth, shadow_cmp, shadow_light, s));
    }
    return vec4<f32>(v, 1.0);
}
";

#[test]
fn host_shader_including_the_library_validates() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(wgsl::LIBRARY_PATH);
    let library = std::fs::read_to_string(path).expect("exported WGSL present");
    let host = format!("{library}{HOST_SHADER}");
    let module = kernels::validate("host", &host).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        kernels::struct_size(&module, "sg_Light"),
        Some(size_of::<LightGpu>() as u32),
        "LightGpu vs the exported struct Light"
    );
    for name in [
        "vis_hard",
        "vis_pcf",
        "vis_pcss",
        "vis_vsm",
        "vis_evsm",
        "vis_esm",
        "vis_vssm_fixed",
        "vis_vssm_float",
        "vis_msm_soft_fixed",
        "vis_msm_soft_float",
    ] {
        assert!(
            library.contains(&format!("//   fn sg_{name}(")),
            "{name} undocumented"
        );
    }
}

/// Two f16 moments (VSM, EVSM2) come packed in an r32uint texture: the host block binds it as
/// `texture_2d<u32>` and reads it through `sg_sample_map_packed`; four (EVSM4) stay
/// rgba16float, a `texture_2d<f32>`.
#[test]
fn host_block_binds_packed_f16_moments_as_u32() {
    for (config, packed) in [
        (PrefilterConfig::vsm(64).with_storage(Storage::F16), true),
        (PrefilterConfig::evsm2(64).with_storage(Storage::F16), true),
        (PrefilterConfig::evsm4(64).with_storage(Storage::F16), false),
        (PrefilterConfig::vsm(64), false),
    ] {
        let t = config.technique;
        let block = wgsl::host_block(&t, 0, 0).expect("host block");
        let bound = if packed {
            "var shadowgraph_map0: texture_2d<u32>;"
        } else {
            "var shadowgraph_map0: texture_2d<f32>;"
        };
        assert!(block.contains(bound), "{}: {block}", t.name());
        assert_eq!(
            block.contains("sg_sample_map_packed(shadowgraph_map0"),
            packed,
            "{}: {block}",
            t.name()
        );
    }
}

#[test]
fn host_block_of_every_technique_validates_with_its_bindings() {
    let mut failures = Vec::new();
    for t in every_technique() {
        let block = wgsl::host_block(&t, 2, 3).expect("host block");
        let host = format!(
            "{block}
@group(0) @binding(0) var<uniform> l: sg_Light;
@fragment
fn fs_main(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {{
    return vec4<f32>(shadowgraph_visibility(l, p, vec3<f32>(0.0, 1.0, 0.0)));
}}"
        );
        match kernels::reflect(t.name(), &host) {
            Err(e) => failures.push(format!("{}: {e}", t.name())),
            Ok((_, r)) => {
                let group2: Vec<(u32, String)> = r
                    .bindings
                    .iter()
                    .filter(|b| b.group == 2)
                    .map(|b| (b.binding, b.name.clone()))
                    .collect();
                // Maps from binding 3 on, consecutively (one or more), then the sampler.
                let maps = group2
                    .iter()
                    .filter(|(_, n)| n.starts_with("shadowgraph_map"))
                    .count();
                let mut expected: Vec<(u32, String)> = (0..maps)
                    .map(|k| (3 + k as u32, format!("shadowgraph_map{k}")))
                    .collect();
                if wgsl::needs_comparison_sampler(&t).expect("block") {
                    expected.push((3 + maps as u32, "shadowgraph_cmp_sampler".into()));
                }
                if wgsl::needs_filtering_sampler(&t).expect("block") {
                    let at = 3 + expected.len() as u32;
                    expected.push((at, "shadowgraph_sat_sampler".into()));
                }
                if maps == 0 || group2 != expected {
                    failures.push(format!("{}: bindings {group2:?}", t.name()));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Every technique's cascades block (`wgsl::cascades_block`, three cascades) validates in a
/// host fragment shader calling `shadowgraph_visibility_cascaded_sun` and its footprint
/// variant with its lights, and
/// binds cascade `c`'s maps and samplers at `first + c · per_light`, each cascade's names its
/// own (`shadowgraph_sun{c}_…`), exactly the layout entries `layout_entries` gives per light.
#[test]
fn cascades_block_of_every_technique_validates_with_its_bindings() {
    let mut failures = Vec::new();
    for t in every_technique() {
        let functions = wgsl::functions_for(&[t]).expect("functions");
        let block = wgsl::cascades_block(&t, "sun", 2, 3, 3).expect("cascades block");
        let host = format!(
            "{functions}{block}
@group(0) @binding(0) var<uniform> l: array<sg_Light, 3>;
@fragment
fn fs_main(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {{
    let n = vec3<f32>(0.0, 1.0, 0.0);
    let dx = dpdx(p);
    let dy = dpdy(p);
    return vec4<f32>(shadowgraph_visibility_cascaded_sun(l, p, n)
        + shadowgraph_visibility_footprint_cascaded_sun(l, p, n, dx, dy));
}}"
        );
        let per_light = wgsl::layout_entries(&t, 0, wgpu::ShaderStages::FRAGMENT)
            .expect("entries")
            .len() as u32;
        match kernels::reflect(t.name(), &host) {
            Err(e) => failures.push(format!("{}: {e}", t.name())),
            Ok((_, r)) => {
                let mut group2: Vec<(u32, String)> = r
                    .bindings
                    .iter()
                    .filter(|b| b.group == 2)
                    .map(|b| (b.binding, b.name.clone()))
                    .collect();
                group2.sort();
                let mut expected = Vec::new();
                for c in 0..3u32 {
                    let first = 3 + c * per_light;
                    for (b, e) in wgsl::layout_entries(&t, first, wgpu::ShaderStages::FRAGMENT)
                        .expect("entries")
                        .iter()
                        .enumerate()
                    {
                        assert_eq!(e.binding, first + b as u32);
                        expected.push(e.binding);
                    }
                }
                let bindings: Vec<u32> = group2.iter().map(|b| b.0).collect();
                let named = group2.iter().all(|(b, n)| {
                    let c = (b - 3) / per_light;
                    n.starts_with(&format!("shadowgraph_sun{c}_"))
                });
                if bindings != expected || !named {
                    failures.push(format!("{}: bindings {group2:?}", t.name()));
                }
            }
        }
    }
    assert!(wgsl::cascades_block(&Technique::Hard, "sun", 0, 0, 9).is_err());
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Every module-scope name the exported WGSL defines carries the `sg_` prefix (the functions a
/// host block generates carry `shadowgraph_`), so a host's own `struct Light`, `fn linstep` or
/// `fn texel_of` composes with it; a light name that is not an identifier's tail is refused.
#[test]
fn exported_names_are_prefixed() {
    let library = wgsl::library().expect("library");
    let module = kernels::validate("library", &library).expect("validates");
    let names: Vec<String> = module
        .types
        .iter()
        .filter_map(|(_, t)| t.name.clone())
        .chain(module.constants.iter().filter_map(|(_, c)| c.name.clone()))
        .chain(module.functions.iter().filter_map(|(_, f)| f.name.clone()))
        .collect();
    assert!(names.len() > 50, "{} names", names.len());
    let bare: Vec<&String> = names
        .iter()
        .filter(|n| !n.starts_with(wgsl::PREFIX))
        .collect();
    assert!(bare.is_empty(), "unprefixed: {bare:?}");
    let host = format!(
        "{library}
struct Light {{ a: f32 }}
struct LightSample {{ b: f32 }}
fn linstep(x: f32) -> f32 {{ return x; }}
fn texel_of(x: f32) -> f32 {{ return x; }}
fn vis_vsm(x: f32) -> f32 {{ return x; }}
@group(0) @binding(0) var<uniform> l: sg_Light;
@group(1) @binding(0) var map: texture_2d<f32>;
@fragment
fn fs_main(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {{
    let mine = linstep(texel_of(vis_vsm(Light(1.0).a + LightSample(2.0).b)));
    let s = sg_light_sample(l, p, vec3<f32>(0.0, 1.0, 0.0));
    return vec4<f32>(sg_vis_vsm(map, l, s), mine, 0.0, 1.0);
}}"
    );
    kernels::validate("host", &host).unwrap_or_else(|e| panic!("{e}"));
    // Several lights' blocks of several techniques after their functions, once.
    let (vsm, pcf) = (every_technique()[4], every_technique()[1]);
    let functions = wgsl::functions_for(&[vsm, pcf]).expect("functions");
    let blocks = [
        wgsl::light_block(&vsm, "sun", 1, 0).expect("sun"),
        wgsl::light_block(&vsm, "lamp2", 1, 1).expect("lamp2"),
        wgsl::light_block(&pcf, "torch", 1, 2).expect("torch"),
    ];
    let composed = format!(
        "{functions}{}
@group(0) @binding(0) var<uniform> l: sg_Light;
@fragment
fn fs_main(@location(0) p: vec3<f32>) -> @location(0) vec4<f32> {{
    let n = vec3<f32>(0.0, 1.0, 0.0);
    return vec4<f32>(shadowgraph_visibility_sun(l, p, n), shadowgraph_visibility_lamp2(l, p, n),
                     shadowgraph_visibility_torch(l, p, n), 1.0);
}}",
        blocks.concat()
    );
    let (_, r) = kernels::reflect("composed", &composed).unwrap_or_else(|e| panic!("{e}"));
    let maps: Vec<(u32, String)> = r
        .bindings
        .iter()
        .filter(|b| b.group == 1)
        .map(|b| (b.binding, b.name.clone()))
        .collect();
    assert_eq!(
        maps,
        vec![
            (0, "shadowgraph_sun_map0".to_string()),
            (1, "shadowgraph_lamp2_map0".to_string()),
            (2, "shadowgraph_torch_map0".to_string()),
        ]
    );
    for bad in ["sun light", "a-b", "x__y", "é"] {
        let e = wgsl::light_block(&vsm, bad, 1, 0).unwrap_err();
        assert!(e.to_string().contains(bad), "{bad}: {e}");
    }
}
