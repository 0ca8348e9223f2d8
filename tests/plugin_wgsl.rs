//! The plug-in stage without a GPU: the exported WGSL is current and compiles inside a host's
//! shader (naga), the host block of every technique validates, and configurations follow the
//! scene file's rules and defaults.

use std::path::Path;

use shadowgraph::low_level::kernels;
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{
    BlurKernel, CssmResolve, CssmSearch, Filter, LightGpu, PcfKernel, PrefilterConfig, StageError,
    Storage, StorageFilter, Technique, wgsl,
};

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

/// A one-light scene whose `[light.shadow]` table holds `keys`.
fn scene_with(technique: &str, keys: &str, light_size: f32) -> shadowgraph::Result<Scene> {
    let text = format!(
        "[output]\nwidth = 8\nheight = 8\n[camera]\nposition = [0.0, 2.0, 5.0]\n\
         target = [0.0, 0.0, 0.0]\nfov_y_degrees = 40.0\n[[light]]\nkind = \"directional\"\n\
         position = [1.0, 5.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nextent = 2.0\nsize = {light_size}\n\
         shadow_map = 64\n[light.shadow]\ntechnique = \"{technique}\"\n{keys}\n\
         [[object]]\nshape = \"plane\"\nsize = 1.0\n"
    );
    Scene::parse(Path::new("rules.toml"), &text)
}

#[test]
fn constructors_have_the_scene_defaults() {
    for (name, config, light_size) in [
        ("vsm", PrefilterConfig::vsm(64), 0.0),
        ("evsm2", PrefilterConfig::evsm2(64), 0.0),
        ("evsm4", PrefilterConfig::evsm4(64), 0.0),
        ("esm", PrefilterConfig::esm(64), 0.0),
        ("cssm", PrefilterConfig::cssm(64, 8, 0.5), 0.5),
        ("vssm", PrefilterConfig::vssm(64, 0.5), 0.5),
        ("msm_soft", PrefilterConfig::msm_soft(64, 0.5), 0.5),
        ("msm", PrefilterConfig::msm(64), 0.0),
    ] {
        let scene = scene_with(name, "", light_size).expect("scene");
        let from_scene = PrefilterConfig::from_light(&scene.lights[0]);
        let (validated, _) = config.validated().expect("defaults are valid");
        assert_eq!(validated, from_scene, "{name}");
    }
}

fn vsm(bleed: f32, min_variance: f32) -> PrefilterConfig {
    let mut c = PrefilterConfig::vsm(64);
    c.technique = Technique::Vsm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: Filter::Blur {
                radius: 2.0,
                sigma: 1.0,
                kernel: BlurKernel::Gaussian,
            },
        },
        bleed,
        min_variance,
    };
    c
}

fn evsm(mut c: PrefilterConfig, pos: f32, neg: f32) -> PrefilterConfig {
    if let Technique::Evsm {
        exp_pos, exp_neg, ..
    } = &mut c.technique
    {
        (*exp_pos, *exp_neg) = (pos, neg);
    }
    c
}

fn esm(c: f32) -> PrefilterConfig {
    let mut config = PrefilterConfig::esm(64);
    if let Technique::Esm { exponent, .. } = &mut config.technique {
        *exponent = c;
    }
    config
}

fn pcss() -> PrefilterConfig {
    PrefilterConfig::new(
        Technique::Pcss {
            blocker_samples: 16,
            filter_samples: 32,
            max_search: 0.1,
        },
        64,
    )
}

/// CSSM's config with sharpening strength `a` (moment bias as a scene's default for the
/// storage).
fn cssm_sharpen(mut c: PrefilterConfig, a: f32) -> PrefilterConfig {
    if let Technique::Cssm { sharpen, .. } = &mut c.technique {
        *sharpen = a;
    }
    c
}

#[test]
fn configs_follow_the_scene_rules() {
    // (scene technique, its keys, light size, the same as a config): both accept (with the
    // same technique after clamping, and as many warnings) or both reject, naming the key.
    let pcf33 = Technique::Pcf {
        radius: 33,
        kernel: PcfKernel::Box,
    };
    let cases: Vec<(&str, &str, f32, PrefilterConfig)> = vec![
        ("vsm", "bleed_reduction = 0.99", 0.0, vsm(0.99, 1e-5)),
        ("vsm", "bleed_reduction = 1.0", 0.0, vsm(1.0, 1e-5)),
        ("vsm", "min_variance = 1.5", 0.0, vsm(0.2, 1.5)),
        (
            "vsm",
            "filter_radius = 32",
            0.0,
            PrefilterConfig::vsm(64).with_blur(32.0),
        ),
        (
            "vsm",
            "filter_radius = 33",
            0.0,
            PrefilterConfig::vsm(64).with_blur(33.0),
        ),
        (
            "vsm",
            "filter = \"none\"\nformat = \"f16\"",
            0.0,
            PrefilterConfig::vsm(64)
                .with_filter(Filter::None)
                .with_storage(Storage::F16),
        ),
        (
            "evsm2",
            "exponent_pos = 50.0",
            0.0,
            evsm(PrefilterConfig::evsm2(64), 50.0, 5.0),
        ),
        (
            "evsm4",
            "format = \"f16\"\nexponent_neg = 10.0",
            0.0,
            evsm(
                PrefilterConfig::evsm4(64).with_storage(Storage::F16),
                40.0,
                10.0,
            ),
        ),
        (
            "evsm2",
            "exponent_pos = 0.001",
            0.0,
            evsm(PrefilterConfig::evsm2(64), 0.001, 5.0),
        ),
        ("esm", "exponent = 10000.0", 0.0, esm(1e4)),
        ("esm", "exponent = 10001.0", 0.0, esm(10001.0)),
        (
            "hard",
            "bias = 2.0",
            0.0,
            PrefilterConfig::new(Technique::Hard, 64).with_bias(2.0),
        ),
        ("pcf", "radius = 33", 0.0, PrefilterConfig::new(pcf33, 64)),
        ("pcss", "", 0.0, pcss()),
        ("pcss", "", 0.5, pcss()),
        ("cssm", "", 0.0, PrefilterConfig::cssm(64, 8, 0.0)),
        ("vssm", "", 0.5, PrefilterConfig::vssm(64, 0.5)),
        (
            "cssm",
            "blocker_search = \"csm_z\"",
            0.5,
            PrefilterConfig::cssm(64, 8, 0.5).with_blocker_search(CssmSearch::CsmZ),
        ),
        (
            "cssm",
            "resolve = \"sharpen\"",
            0.5,
            PrefilterConfig::cssm(64, 8, 0.5).with_cssm_resolve(CssmResolve::Sharpen),
        ),
        (
            "cssm",
            "resolve = \"two_depth_search\"",
            0.5,
            PrefilterConfig::cssm(64, 8, 0.5).with_cssm_resolve(CssmResolve::TwoDepthSearch),
        ),
        (
            "cssm",
            "terms = 4\nsharpen = 100.5",
            0.5,
            cssm_sharpen(PrefilterConfig::cssm(64, 4, 0.5), 100.5),
        ),
        (
            "cssm",
            "terms = 4\nsharpen = 3.0",
            0.5,
            cssm_sharpen(PrefilterConfig::cssm(64, 4, 0.5), 3.0),
        ),
        (
            "msm_soft",
            "format = \"f16\"\nsat_sums = \"float\"\nmax_search = 0.3\nmoment_bias = 0.00001",
            0.5,
            PrefilterConfig::msm_soft(64, 0.5)
                .with_moment_bias(1e-5)
                .with_storage(Storage::F16)
                .with_soft(shadowgraph::SatVariant::Float, 0.3),
        ),
        // MSM's bias follows the storage's default unless set, and is checked as the key is.
        (
            "msm",
            "format = \"f16\"",
            0.0,
            PrefilterConfig::msm(64).with_storage(Storage::F16),
        ),
        (
            "msm",
            "format = \"unorm16\"",
            0.0,
            PrefilterConfig::msm(64).with_storage(Storage::Unorm16),
        ),
        (
            "msm_soft",
            "format = \"f16\"",
            0.5,
            PrefilterConfig::msm_soft(64, 0.5).with_storage(Storage::F16),
        ),
        (
            "msm",
            "moment_bias = 0.003",
            0.0,
            PrefilterConfig::msm(64).with_moment_bias(0.003),
        ),
        (
            "msm",
            "moment_bias = 0.6",
            0.0,
            PrefilterConfig::msm(64).with_moment_bias(0.6),
        ),
        (
            "msm_soft",
            "moment_bias = -0.001",
            0.5,
            PrefilterConfig::msm_soft(64, 0.5).with_moment_bias(-0.001),
        ),
        (
            "vssm",
            "max_search = 2.0",
            0.5,
            PrefilterConfig::vssm(64, 0.5).with_soft(shadowgraph::SatVariant::Fixed, 2.0),
        ),
    ];
    for (technique, keys, light_size, mut config) in cases {
        config.light_size = light_size;
        let scene = scene_with(technique, keys, light_size);
        let stage = config.validated();
        match (&scene, &stage) {
            (Ok(s), Ok((c, warnings))) => {
                assert_eq!(
                    c.technique, s.lights[0].shadow.technique,
                    "{technique} {keys}"
                );
                assert_eq!(
                    warnings.len(),
                    s.warnings.len(),
                    "{technique} {keys}: {warnings:?}"
                );
            }
            (Err(scene_err), Err(StageError::Config { field, .. })) => {
                let key = field.split(' ').next().unwrap_or_default();
                assert!(
                    scene_err.to_string().contains(key),
                    "{technique} {keys}: the stage names `{field}`, the scene says {scene_err}"
                );
            }
            _ => panic!(
                "{technique} {keys}: scene {:?} but stage {:?}",
                scene.as_ref().map(|_| ()),
                stage.map(|_| ())
            ),
        }
    }
}

#[test]
fn settings_that_do_not_apply_are_named() {
    let e = PrefilterConfig::esm(64)
        .with_storage(Storage::F16)
        .validated()
        .unwrap_err();
    assert!(
        matches!(&e, StageError::Config { field, .. } if field == "format"),
        "{e}"
    );
    assert!(e.to_string().contains("esm"), "{e}");
    let e = PrefilterConfig::new(Technique::Hard, 64)
        .with_blur(2.0)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("filter"), "{e}");
    let e = PrefilterConfig::vsm(64)
        .with_moment_bias(1e-4)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("moment_bias"), "{e}");
    let e = PrefilterConfig::vssm(64, 0.5)
        .with_blocker_search(CssmSearch::CsmZ)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("blocker_search"), "{e}");
    let e = PrefilterConfig::vsm(0).validated().unwrap_err();
    assert!(e.to_string().contains("size"), "{e}");
    let e = PrefilterConfig::vsm(64)
        .with_receiver_plane(0.01)
        .validated()
        .unwrap_err();
    assert!(
        matches!(&e, StageError::Config { field, .. } if field == "receiver_plane"),
        "{e}"
    );
    let hardware = Technique::Pcf {
        radius: 1,
        kernel: PcfKernel::Hardware,
    };
    let e = PrefilterConfig::new(hardware, 64)
        .with_receiver_plane(0.01)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("bias_mode"), "{e}");
    let e = PrefilterConfig::new(Technique::Hard, 64)
        .with_receiver_plane(2.0)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("receiver_plane_cap"), "{e}");
    PrefilterConfig::new(Technique::Hard, 64)
        .with_receiver_plane(0.01)
        .validated()
        .expect("hard takes the receiver-plane bias");
    let e = PrefilterConfig::vsm(64)
        .with_soft(shadowgraph::SatVariant::Float, 0.1)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("sat_sums"), "{e}");
    let e = PrefilterConfig::vssm(64, 0.5)
        .with_blur(2.0)
        .validated()
        .unwrap_err();
    assert!(e.to_string().contains("filter"), "{e}");
    // A scene's prefilter field set by hand is still checked.
    let mut c = PrefilterConfig::vsm(64);
    c.technique = Technique::Vsm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: Filter::Blur {
                radius: 2.0,
                sigma: 0.0,
                kernel: BlurKernel::Gaussian,
            },
        },
        bleed: 0.2,
        min_variance: 1e-5,
    };
    let e = c.validated().unwrap_err();
    assert!(e.to_string().contains("filter_sigma"), "{e}");
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
