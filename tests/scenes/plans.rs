//! What the renderer plans and reuses: pipelines and textures across renders, the device limit,
//! only the nodes a technique needs.

use super::*;

#[test]
fn repeated_renders_reuse_pipelines_and_textures() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let scene =
        Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_lights.toml")).unwrap();
    let mut counts = Vec::new();
    for _ in 0..4 {
        renderer
            .render(&g.device, &g.queue, &scene, RenderOptions::default())
            .unwrap();
        counts.push((
            renderer.executor.texture_count(),
            renderer.executor.kernels.len(),
        ));
    }
    assert!(
        counts.windows(2).all(|w| w[0] == w[1]),
        "pool or cache grew: {counts:?}"
    );
}

#[test]
fn shadow_map_past_the_device_limit_is_a_clear_error() {
    let g = common::gpu();
    let max = g.device.limits().max_texture_dimension_2d;
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_on_plane.toml"),
    )
    .unwrap();
    let mut scene = Scene::parse(Path::new("limit.toml"), &text).unwrap();
    scene.lights[0].shadow_map = max + 1;
    let mut renderer = Renderer::new(&g.device);
    match renderer.render(&g.device, &g.queue, &scene, RenderOptions::default()) {
        Err(e @ Error::SceneLimit { .. }) => {
            let m = e.to_string();
            assert!(
                m.starts_with("limit.toml:")
                    && m.contains("light[0].shadow_map")
                    && m.contains(&max.to_string()),
                "{m}"
            );
        }
        Err(e) => panic!("expected a limit error, got {e}"),
        Ok(_) => panic!(
            "a {}² shadow map rendered on a device limited to {max}",
            max + 1
        ),
    }
}

#[test]
fn plan_contains_only_what_techniques_need() {
    let two =
        Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_lights.toml")).unwrap();
    let sp = shadowgraph::low_level::render::plan_lights(&two.lights).unwrap();
    for (i, l) in two.lights.iter().enumerate() {
        let steps: Vec<&str> = sp
            .plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .map(|s| s.node.kernel.as_str())
            .collect();
        let hardware = matches!(
            l.shadow.technique,
            Technique::Pcf {
                kernel: PcfKernel::Hardware,
                ..
            }
        );
        // The hardware comparison sampler reads the rasterized depth: no kernel at all.
        assert_eq!(
            steps,
            if hardware { vec![] } else { vec!["linearize"] },
            "light {i}"
        );
    }
}

/// The blocker kernels are planned only for lights that ask for soft shadows: every bundled
/// and technique scene's lights, and one plan mixing CSM, CSSM, VSM, VSSM and MSM lights.
/// A CSSM light plans the tables of its ⌈M/2⌉ basis maps and ⌈(2M + 1)/4⌉ CSM-Z maps as one
/// layered table (2 + ⌈maps / 4⌉ passes, the maps never stored), and nothing else; VSSM and soft MSM plan exactly the
/// encoding of their hard counterparts and one table.
#[test]
fn blocker_kernels_are_planned_only_for_soft_lights() {
    let mut lights: Vec<shadowgraph::Light> = Vec::new();
    for path in scenes() {
        lights.extend(Scene::load(&path).expect("scene").lights);
    }
    let soft_scene = |name: &str| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/techniques/{name}"));
        Scene::load(path).expect("scene").lights.remove(0)
    };
    let mut csm = soft_scene("csm_sat.toml");
    csm.shadow_map = 64;
    lights.extend([
        csm,
        soft_scene("cssm.toml"),
        soft_scene("vsm_sat.toml"),
        soft_scene("vssm.toml"),
        soft_scene("msm_sat.toml"),
        soft_scene("msm_soft.toml"),
    ]);
    let sp = shadowgraph::low_level::render::plan_lights(&lights).expect("plan");
    for (i, l) in lights.iter().enumerate() {
        let mut kernels: Vec<&str> = sp
            .plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .map(|s| s.node.kernel.as_str())
            .collect();
        let what = format!("light {i} ({})", l.shadow.technique.name());
        // CSM-Z maps or their tables written (`light{i}.csm_z<k>` or `light{i}.csm_z<k>.sat`,
        // tables interleaved in one texture by the names of the tables it holds).
        let written: Vec<String> = sp
            .plan
            .steps
            .iter()
            .filter(|s| s.node.light == Some(i))
            .flat_map(|s| &s.node.outputs)
            .flat_map(|(_, r)| match sp.plan.resource(r) {
                Some(p) if !p.resource.layers.is_empty() => p.resource.layers.clone(),
                _ => vec![r.clone()],
            })
            .collect();
        let blocker = written
            .iter()
            .filter(|r| {
                let r = r.strip_suffix(".sat").unwrap_or(r);
                r.rsplit('.')
                    .next()
                    .is_some_and(|n| n.starts_with("csm_z") || n == "csm_moments")
            })
            .count();
        let expected: Option<Vec<&str>> = match l.shadow.technique {
            Technique::Cssm {
                soft,
                terms,
                search,
                ..
            } => {
                let basis = shadowgraph::low_level::technique::csm_maps(terms) as usize;
                let z = match search {
                    shadowgraph::CssmSearch::CsmZ => {
                        shadowgraph::low_level::technique::csm_z_maps(terms) as usize
                    }
                    shadowgraph::CssmSearch::Moments => 1,
                };
                assert_eq!(blocker, z, "{what}: the blocker search's tables");
                // One layered table (`sat::layers`): the edges of every layer from the depth,
                // the carries, and four textures a dispatch, fixed-point tables as many a
                // texture as fit; no basis map stored.
                let per = shadowgraph::low_level::sat::layers::LAYERED_SAT_OUTPUTS as usize;
                let tables = (basis + z) as u32;
                let interleave = shadowgraph::low_level::technique::basis_interleave(
                    l.map_dims().0,
                    tables,
                    soft.sums,
                );
                let textures = (basis + z).div_ceil(interleave as usize);
                let (sums, tiles) = match soft.sums {
                    shadowgraph::SatVariant::Fixed => ("csm_sat_tile_sums", "csm_sat_tiles"),
                    shadowgraph::SatVariant::Float => {
                        ("csm_sat_tile_sums_f32", "csm_sat_tiles_f32")
                    }
                };
                let mut v = vec![sums, "sat_carries"];
                v.extend(vec![tiles; textures.div_ceil(per)]);
                Some(v)
            }
            // The moments computed in the table's own tile passes (one layer, no map).
            Technique::Vssm { soft, .. } => Some(match soft.sums {
                shadowgraph::SatVariant::Fixed => {
                    vec!["vsm_sat_tile_sums", "sat_carries", "vsm_sat_tiles"]
                }
                shadowgraph::SatVariant::Float => {
                    vec!["vsm_sat_tile_sums_f32", "sat_carries", "vsm_sat_tiles_f32"]
                }
            }),
            Technique::MsmSoft { soft, .. } => Some(match soft.sums {
                shadowgraph::SatVariant::Fixed => {
                    vec!["msm_sat_tile_sums", "sat_carries", "msm_sat_tiles"]
                }
                shadowgraph::SatVariant::Float => {
                    vec!["msm_sat_tile_sums_f32", "sat_carries", "msm_sat_tiles_f32"]
                }
            }),
            _ => None,
        };
        match expected {
            Some(mut e) => {
                kernels.sort_unstable();
                e.sort_unstable();
                assert_eq!(kernels, e, "{what}");
            }
            None => assert_eq!(blocker, 0, "{what} plans blocker kernels"),
        }
    }
    assert!(
        lights
            .iter()
            .any(|l| matches!(l.shadow.technique, Technique::Csm { .. }))
            && lights
                .iter()
                .any(|l| matches!(l.shadow.technique, Technique::Cssm { .. })),
        "the mixed plan lacks CSM or CSSM"
    );
}
