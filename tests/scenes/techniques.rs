//! Every registered technique renders every bundled scene.

use super::*;

/// Every technique (with each filter; the soft ones on a light 0.3 units wide where the scene's
/// light has no size) on every bundled scene, at a reduced size: no NaN or Inf,
/// visibility in [0, 1] and some shadow cast (some pixel below 0.95: a thin pole on a 512² map
/// seen in 120×90 pixels casts little).
#[test]
fn every_technique_renders_every_bundled_scene() {
    use shadowgraph::{BlurKernel, Filter, Storage, StorageFilter};
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    let pre = |storage, filter| StorageFilter { storage, filter };
    let sat = Filter::Sat {
        width: 4.5,
        variant: shadowgraph::SatVariant::Fixed,
    };
    let sat_float = Filter::Sat {
        width: 2.0,
        variant: shadowgraph::SatVariant::Float,
    };
    let sat_limit =
        shadowgraph::low_level::technique::sat_exponent_limit(&sat, false).expect("sat limit");
    let soft = |storage, sums| shadowgraph::Soft {
        storage,
        sums,
        max_search: shadowgraph::low_level::model::DEFAULT_MAX_SEARCH,
    };
    let techniques = [
        Technique::Hard,
        Technique::Pcf {
            radius: 1,
            kernel: PcfKernel::Hardware,
        },
        Technique::Pcss {
            blocker_samples: 8,
            filter_samples: 16,
            max_search: 0.05,
        },
        Technique::Vsm {
            prefilter: pre(
                Storage::F16,
                Filter::Mips {
                    width: 2.0,
                    max_anisotropy: 0,
                },
            ),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Evsm {
            prefilter: pre(Storage::F32, blur),
            four: true,
            exp_pos: 40.0,
            exp_neg: 5.0,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        // Two f16 moments packed in r32uint words, blurred (the fused kernel) and read by the
        // shading through `sample_map_packed`.
        Technique::Evsm {
            prefilter: pre(Storage::F16, blur),
            four: false,
            exp_pos: 5.0,
            exp_neg: 5.0,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        Technique::Esm {
            filter: Filter::Mips {
                width: 3.0,
                max_anisotropy: 0,
            },
            exponent: 80.0,
        },
        Technique::Msm {
            prefilter: pre(Storage::F32, blur),
            hausdorff: false,
            moment_bias: 1e-5,
            bleed: 0.0,
        },
        Technique::Msm {
            prefilter: pre(
                Storage::F16,
                Filter::Mips {
                    width: 1.5,
                    max_anisotropy: 0,
                },
            ),
            hausdorff: true,
            moment_bias: 5e-4,
            bleed: 0.0,
        },
        Technique::Csm {
            prefilter: pre(Storage::F32, blur),
            terms: 9,
            attenuation: 1.0,
            offset: 0.05,
            scale: 2.0,
        },
        Technique::Vsm {
            prefilter: pre(Storage::F32, sat_float),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Evsm {
            prefilter: pre(Storage::F16, sat),
            four: false,
            exp_pos: sat_limit,
            exp_neg: sat_limit,
            bleed: 0.0,
            min_variance: 1e-4,
        },
        Technique::Esm {
            filter: sat,
            exponent: 4.0 * sat_limit,
        },
        Technique::Msm {
            prefilter: pre(Storage::F16, sat),
            hausdorff: false,
            moment_bias: 5e-4,
            bleed: 0.0,
        },
        Technique::Csm {
            prefilter: pre(Storage::F32, sat),
            terms: 5,
            attenuation: 1.0,
            offset: 0.1,
            scale: 2.0,
        },
        Technique::Cssm {
            soft: soft(Storage::F32, shadowgraph::SatVariant::Fixed),
            terms: 3,
            attenuation: 1.0,
            offset: 0.5 / 3.0,
            scale: 2.0,
            sharpen: shadowgraph::low_level::model::DEFAULT_SHARPEN,
            sharpen_falloff: shadowgraph::low_level::model::DEFAULT_SHARPEN_FALLOFF,
            search: shadowgraph::CssmSearch::CsmZ,
            resolve: shadowgraph::CssmResolve::TwoDepth,
        },
        Technique::Vssm {
            soft: soft(Storage::F16, shadowgraph::SatVariant::Float),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::MsmSoft {
            soft: soft(Storage::F16, shadowgraph::SatVariant::Fixed),
            hausdorff: false,
            moment_bias: 5e-4,
            bleed: 0.0,
        },
    ];
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for entry in std::fs::read_dir(&root).expect("scenes/") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let base = Scene::load(&path).expect("scene");
        for t in techniques {
            let mut scene = base.clone();
            (scene.width, scene.height) = (120, 90);
            for l in &mut scene.lights {
                l.shadow.technique = t;
                // A technique that refuses cascades (`params::cascade_support`): one map.
                if shadowgraph::low_level::technique::params::cascade_support(&t).is_err() {
                    l.shadow.cascades = shadowgraph::Cascades::SINGLE;
                }
                l.shadow_map = l.shadow_map.min(512);
                // PCSS and the soft techniques model an area light (scenes require a size).
                if t.soft().is_some() && l.size <= 0.0 {
                    l.size = 0.3;
                }
            }
            let what = format!("{} with {}", path.display(), t.name());
            let frame = renderer
                .render(
                    &g.device,
                    &g.queue,
                    &scene,
                    RenderOptions {
                        aux: false,
                        repeat: 1,
                        dump: false,
                    },
                )
                .unwrap_or_else(|e| panic!("{what}: {e}"));
            assert!(
                frame
                    .visibility
                    .iter()
                    .all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
                "{what}: visibility not finite in [0, 1]"
            );
            assert!(
                frame.visibility.iter().any(|&v| v < 0.95),
                "{what}: no shadow at all"
            );
        }
    }
}
