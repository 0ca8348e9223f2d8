//! Second-depth shadow maps (`midpoint`, `second_depth`): the peeled second depth the GPU
//! rasterizes against the f64 ray cast of every surface along each texel's ray
//! (`truth::peel`), the map the shading reads against the f64 reference of its kernel
//! (`cpu::second_depth`) on the GPU's own depths, and the non-watertight fallback: a scene
//! with no second surface anywhere shades exactly as `hard` with the same constant bias.
//! (The visibility of the bundled scenes against `cpu::vis_hard` on that map is in
//! tests/scenes.rs.)

mod common;

use std::path::Path;

use shadowgraph::cpu;
use shadowgraph::render::{Frame, RenderOptions, Renderer};
use shadowgraph::scene::Scene;
use shadowgraph::technique::{self, SecondDepthParams};
use shadowgraph::truth::peel::{PeeledTexel, peeled_depths};

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Renders `scene` keeping every resource of its plan (imports too: both depth maps).
fn dump(renderer: &mut Renderer, g: &shadowgraph::gpu::Gpu, scene: &Scene) -> Frame {
    let opts = RenderOptions {
        aux: false,
        repeat: 1,
        dump: true,
    };
    renderer
        .render(&g.device, &g.queue, scene, opts)
        .expect("renders")
}

/// The texels of resource `name` of a dumped frame (one channel).
fn resource<'a>(frame: &'a Frame, name: &str) -> &'a [f32] {
    let r = frame
        .resources
        .iter()
        .find(|r| r.levels[0].resource == name)
        .unwrap_or_else(|| panic!("{name} not in the plan"));
    assert_eq!(r.levels[0].channels, 1, "{name}: channels");
    &r.levels[0].data
}

/// Both rasterized depths equal the ray cast's where a texel is no edge case (its jittered rays
/// meet the same triangles): within 10⁻⁶ (f32 transforms and interpolation of depths in
/// [0, 1], a few ULPs of 2⁻²⁴ each) plus the depth's slope per texel times 1/128 (the
/// rasterizer snaps vertices to 1/256 of a texel, twice that for margin). At least 95% of the
/// texels are robust. Then the map the shading reads is the kernel's f64 reference on those
/// depths, within 10⁻⁶ (f32 linearization).
#[test]
fn peeled_depth_and_map_match_the_references() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    for name in [
        "scenes/techniques/midpoint.toml",
        "scenes/techniques/second_depth.toml",
    ] {
        let scene = scene(name);
        let light = &scene.lights[0];
        assert_eq!(
            light.shadow.slope_bias, 0.0,
            "{name}: the reference has no slope bias"
        );
        let frame = dump(&mut renderer, &g, &scene);
        let z1 = resource(&frame, &technique::depth_name(0));
        let z2 = resource(&frame, &technique::second_depth_name(0));
        let reference = peeled_depths(&scene, light);
        assert_eq!(reference.len(), z1.len(), "{name}: texels");
        let robust: Vec<usize> = (0..reference.len())
            .filter(|&i| reference[i].robust)
            .collect();
        assert!(
            robust.len() * 100 >= reference.len() * 95,
            "{name}: only {} of {} texels robust",
            robust.len(),
            reference.len()
        );
        let second = robust.iter().filter(|&&i| reference[i].z2 < 1.0).count();
        assert!(
            second * 4 > robust.len(),
            "{name}: a second surface behind only {second} texels"
        );
        let tol: Vec<f64> = robust
            .iter()
            .map(|&i| 1e-6 + reference[i].slope / 128.0)
            .collect();
        for (what, gpu, of) in [
            ("first depth", z1, (|t| t.z1) as fn(&PeeledTexel) -> f64),
            ("second depth", z2, |t| t.z2),
        ] {
            let got: Vec<f32> = robust.iter().map(|&i| gpu[i]).collect();
            let want: Vec<f64> = robust.iter().map(|&i| of(&reference[i])).collect();
            common::assert_within(&format!("{name}: {what}"), &got, &want, &tol);
        }
        let params = SecondDepthParams {
            depth: technique::LinearizeParams::new(light),
            mode: u32::from(name.contains("second_depth")),
            fallback_bias: light.shadow.bias,
            _pad: [0; 2],
        };
        let map = resource(&frame, "light0.second_depth");
        let want = cpu::second_depth::second_depth(z1, z2, &params);
        common::assert_close(&format!("{name}: map"), map, &want, 1e-6, 0.0);
    }
}

/// Planes have no second surface: on a ground plane with a plane floating above it,
/// `midpoint` and `second_depth` hold the first depth plus the constant bias (f32, exactly the
/// kernel's sum) wherever nothing lies behind the first surface, and their visibility equals
/// `hard`'s with that bias pixel for pixel: there the same comparison of the same f32 values;
/// where the floating plane is in front of the ground, both shadow the ground and light the
/// floating plane (its receivers lie far in front of the midpoint and of the ground).
#[test]
fn without_a_second_surface_they_shade_as_hard_with_the_bias() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let mut base = scene("scenes/techniques/midpoint.toml");
    // The ground as one plane, and the floating plane: nothing is closed.
    base.objects.retain(|o| o.mesh.indices.len() == 6);
    assert_eq!(base.objects.len(), 1, "the floating plane");
    let mut ground = base.objects[0].clone();
    ground.mesh.positions = vec![
        glam::Vec3::new(-7.0, 0.0, -7.0),
        glam::Vec3::new(7.0, 0.0, -7.0),
        glam::Vec3::new(7.0, 0.0, 7.0),
        glam::Vec3::new(-7.0, 0.0, 7.0),
    ];
    ground.mesh.normals = vec![glam::Vec3::Y; 4];
    ground.mesh.indices = vec![0, 1, 2, 0, 2, 3];
    base.objects.push(ground);
    let opts = RenderOptions::default();
    let mut hard = base.clone();
    hard.lights[0].shadow.technique = shadowgraph::scene::Technique::Hard;
    let want = renderer
        .render(&g.device, &g.queue, &hard, opts)
        .expect("hard renders");
    let shadowed = want.visibility.iter().filter(|&&v| v < 0.5).count();
    assert!(
        shadowed > 100,
        "the plane casts a shadow ({shadowed} pixels)"
    );
    for name in ["midpoint", "second_depth"] {
        let mut scene = base.clone();
        scene.lights[0].shadow.technique = technique::named(name, &[]).expect(name);
        let frame = dump(&mut renderer, &g, &scene);
        let z2 = resource(&frame, &technique::second_depth_name(0));
        let seconds = z2.iter().filter(|&&z| z < 1.0).count();
        // Where the floating plane is in front of the ground, the ground is its second surface.
        let z1 = resource(&frame, &technique::depth_name(0));
        let map = resource(&frame, "light0.second_depth");
        let bias = scene.lights[0].shadow.bias;
        let fallback = (0..z1.len()).filter(|&i| z2[i] >= 1.0).count();
        assert!(
            seconds > 100 && fallback > z1.len() / 2,
            "{name}: {seconds} texels have a second surface"
        );
        // Orthographic: the linear depth is the depth-buffer value itself.
        for i in (0..z1.len()).filter(|&i| z2[i] >= 1.0) {
            assert_eq!(map[i], z1[i] + bias, "{name}: texel {i} is not z1 + {bias}");
        }
        let got = renderer
            .render(&g.device, &g.queue, &scene, opts)
            .expect("renders");
        let differ = (0..got.visibility.len())
            .filter(|&i| got.visibility[i] != want.visibility[i])
            .count();
        assert_eq!(differ, 0, "{name}: {differ} pixels differ from hard");
    }
}
