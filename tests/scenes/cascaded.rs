//! The cascaded street view with every technique that takes cascades.

use super::*;

/// Technique `name` with its registry defaults.
fn registered(name: &str) -> Technique {
    shadowgraph::low_level::technique::named(name, &[])
        .unwrap_or_else(|| panic!("{name} is registered"))
}

/// The cascaded street view with the other techniques that take cascades: each cascade's map
/// prefiltered by the same graph (hard; VSM blurred; MSM through a float table; ESM mipmapped,
/// isotropic and anisotropic;
/// PCSS and the soft techniques, each cascade with its guard band and `max_search`; the
/// second-depth techniques, each cascade peeled), every pixel against the f64 pick and
/// references (`cascades::check_light`).
#[test]
fn cascaded_techniques_match_the_references() {
    use shadowgraph::{BlurKernel, Filter, Storage, StorageFilter};
    let g = common::gpu();
    let e_trig = common::soft_maps::trig_error(&g);
    let mut renderer = Renderer::new(&g.device);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let mut scene = Scene::load(&path).expect("scene loads");
    let blur = Filter::Blur {
        radius: 2.0,
        sigma: 1.0,
        kernel: BlurKernel::Gaussian,
    };
    let table = Filter::Sat {
        width: 3.0,
        variant: shadowgraph::SatVariant::Float,
    };
    let pre = |storage, filter| StorageFilter { storage, filter };
    for t in [
        Technique::Hard,
        Technique::Vsm {
            prefilter: pre(Storage::F32, blur),
            bleed: 0.2,
            min_variance: 1e-5,
        },
        Technique::Msm {
            prefilter: pre(Storage::F32, table),
            hausdorff: false,
            moment_bias: 3e-5,
            bleed: 0.0,
        },
        Technique::Esm {
            filter: Filter::Mips {
                width: 2.0,
                max_anisotropy: 0,
            },
            exponent: 40.0,
        },
        // Anisotropic: each cascade's lookups follow the pixel's footprint in its own map.
        Technique::Esm {
            filter: Filter::Mips {
                width: 2.0,
                max_anisotropy: 8,
            },
            exponent: 40.0,
        },
        registered("pcss"),
        registered("vssm"),
        registered("msm_soft"),
        registered("cssm"),
        registered("midpoint"),
        registered("second_depth"),
    ] {
        scene.lights[0].shadow.technique = t;
        let frame = renderer
            .render(
                &g.device,
                &g.queue,
                &scene,
                RenderOptions {
                    aux: true,
                    repeat: 1,
                    dump: false,
                },
            )
            .unwrap_or_else(|e| panic!("{}: {e}", t.name()));
        let drawn = drawn_lights(&scene).expect("drawn lights");
        assert_eq!(drawn.lights.len(), 4, "{}: four cascades drawn", t.name());
        cascades::check_light(&scene, &frame, &drawn, 0, e_trig);
    }
}
