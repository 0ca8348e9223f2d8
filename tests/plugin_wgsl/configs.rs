//! `PrefilterConfig` follows the scene file's rules and defaults.

use super::*;

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

fn evsm(mut c: PrefilterConfig, pos: f32, neg: f32) -> PrefilterConfig {
    if let Technique::Evsm {
        exp_pos, exp_neg, ..
    } = &mut c.technique
    {
        (*exp_pos, *exp_neg) = (pos, neg);
    }
    c
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
