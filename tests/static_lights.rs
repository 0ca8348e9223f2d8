//! Cached lights (`update` of a `[[light]]`): a light whose map is `"static"` is rasterized and
//! prefiltered on its first frame only, one with `update = 2` every other frame, and either is
//! redrawn on the frame it moves, its technique changes or its casters move. Dispatches are
//! counted by the executor itself (`Executor::dispatch_count`) and compared with the plan's,
//! exactly; raster passes by the frame's record of its passes. Every frame's visibility is
//! compared with the same scene rendered with every light redrawn every frame, bit for bit:
//! the same kernels over the same inputs on the same device give the same bits.

mod common;

use std::path::Path;

use shadowgraph::low_level::graph::Dispatch;
use shadowgraph::low_level::render::{Frame, RenderOptions, Renderer, plan_lights};
use shadowgraph::low_level::scene::Scene;

/// Two spot lights over a box on a plane. Light 0 is redrawn every frame (and moved by
/// `moving_z`); light 1 is the cached one (`update`, moved by `x`, its `[light.shadow]` body
/// `technique`); `box_x` moves the box. Both use ESM with a two-pass blur at the same map
/// size: the planner, which reuses a texture once its last reader ran, puts light 1's blurred
/// map in the texture of light 0's horizontal pass, which a frame redrawing light 0 alone
/// would overwrite (unless the cached map has a texture of its own).
struct Setup<'a> {
    update: &'a str,
    x: f32,
    technique: &'a str,
    moving_z: f32,
    box_x: f32,
}

impl Setup<'_> {
    fn text(&self) -> String {
        let moving = ESM;
        format!(
            r#"
[output]
width = 40
height = 30

[camera]
position = [0.0, 4.0, 6.0]
target = [0.0, 0.5, 0.0]
fov_y_degrees = 50.0

[[light]]
kind = "spot"
position = [2.0, 5.0, {z}]
target = [0.0, 0.0, 0.0]
fov_degrees = 70.0
near = 1.0
far = 15.0
shadow_map = 64
intensity = 0.5

[light.shadow]
{moving}

[[light]]
kind = "spot"
position = [{x}, 6.0, 1.0]
target = [0.0, 0.0, 0.0]
fov_degrees = 70.0
near = 1.0
far = 15.0
shadow_map = 64
{update}

[light.shadow]
{technique}

[[object]]
shape = "plane"
size = [8.0, 8.0]

[[object]]
shape = "box"
size = 1.0
translate = [{bx}, 0.6, 0.0]
"#,
            x = self.x,
            update = self.update,
            technique = self.technique,
            z = self.moving_z,
            bx = self.box_x,
        )
    }

    fn scene(&self) -> Scene {
        Scene::parse(Path::new("static.toml"), &self.text()).expect("scene")
    }

    /// The same scene with every light redrawn every frame.
    fn uncached(&self) -> Scene {
        let text = self.text().replace(self.update, "");
        Scene::parse(Path::new("static.toml"), &text).expect("scene")
    }
}

/// ESM filtered by a blur of radius 9 (a horizontal and a vertical pass).
const ESM: &str = "technique = \"esm\"\nfilter = \"blur\"\nfilter_radius = 9\nbias = 0.002";

/// The moving light is light 0, the cached one light 1.
const MOVING: usize = 0;
const CACHED: usize = 1;

fn base(update: &'static str) -> Setup<'static> {
    Setup {
        update,
        x: -1.5,
        technique: ESM,
        moving_z: 1.5,
        box_x: 0.0,
    }
}

/// Dispatches of light `l`'s steps in the plan of `scene` (each step one, or its several).
fn dispatches(scene: &Scene, l: usize) -> u64 {
    let sp = plan_lights(&scene.lights).expect("plan");
    sp.plan
        .steps
        .iter()
        .filter(|s| s.node.light == Some(l))
        .map(|s| match &s.node.dispatch {
            Dispatch::Several(d) => d.len() as u64,
            _ => 1,
        })
        .sum()
}

/// Renders one frame of `scene`: the frame and the dispatches the executor recorded.
fn frame(r: &mut Renderer, g: &shadowgraph::low_level::gpu::Gpu, scene: &Scene) -> (Frame, u64) {
    let before = r.executor.dispatch_count();
    let f = r
        .render(&g.device, &g.queue, scene, RenderOptions::default())
        .expect("render");
    let n = r.executor.dispatch_count() - before;
    (f, n)
}

/// Light `l`'s passes in frame `k` of `f`.
fn passes_of(f: &Frame, k: usize, l: usize) -> Vec<String> {
    let prefix = format!("light{l}.");
    f.recorded[k]
        .iter()
        .filter(|p| p.starts_with(&prefix))
        .cloned()
        .collect()
}

/// Checks one frame: whether the cached light ran (its raster pass and exactly its
/// dispatches), that the moving light always did, and that the visibility is the uncached
/// render's.
fn check(
    cached: &mut Renderer,
    fresh: &mut Renderer,
    g: &shadowgraph::low_level::gpu::Gpu,
    s: &Setup,
    runs: bool,
    what: &str,
) {
    let scene = s.scene();
    let (f, n) = frame(cached, g, &scene);
    let (want, _) = frame(fresh, g, &s.uncached());
    let (dc, dm) = (dispatches(&scene, CACHED), dispatches(&scene, MOVING));
    assert!(dc >= 2 && dm >= 2, "{what}: too few steps planned");
    let expected = if runs { dc + dm } else { dm };
    assert_eq!(
        n, expected,
        "{what}: dispatches (the cached light's {dc}, the moving one's {dm})"
    );
    let pc = passes_of(&f, 0, CACHED);
    let raster = format!("light{CACHED}.shadow_raster");
    assert_eq!(
        pc.contains(&raster),
        runs,
        "{what}: the cached light's passes: {pc:?}"
    );
    if !runs {
        assert!(pc.is_empty(), "{what}: the cached light recorded {pc:?}");
    }
    let pm = passes_of(&f, 0, MOVING);
    assert!(
        pm.contains(&format!("light{MOVING}.shadow_raster")),
        "{what}: {pm:?}"
    );
    assert_eq!(f.visibility.len(), want.visibility.len());
    let differ = f
        .visibility
        .iter()
        .zip(&want.visibility)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(
        differ, 0,
        "{what}: visibility differs from a full redraw in {differ} values"
    );
}

#[test]
fn a_static_light_is_drawn_once() {
    let g = common::gpu();
    let (mut cached, mut fresh) = (Renderer::new(&g.device), Renderer::new(&g.device));
    let mut s = base("update = \"static\"");
    check(&mut cached, &mut fresh, &g, &s, true, "frame 1");
    for k in 2..=4 {
        // The other light moves every frame: its maps are redrawn into the plan's textures.
        s.moving_z = 1.5 + 0.3 * k as f32;
        check(
            &mut cached,
            &mut fresh,
            &g,
            &s,
            false,
            &format!("frame {k}"),
        );
    }
    // Frames of one call count too.
    let opts = RenderOptions {
        repeat: 3,
        ..Default::default()
    };
    let f = cached
        .render(&g.device, &g.queue, &s.scene(), opts)
        .expect("render");
    assert_eq!(f.recorded.len(), 3);
    for k in 0..3 {
        assert!(
            passes_of(&f, k, CACHED).is_empty(),
            "repeat frame {k}: {:?}",
            f.recorded[k]
        );
        assert!(!passes_of(&f, k, MOVING).is_empty());
    }
}

#[test]
fn an_every_two_light_is_drawn_on_alternate_frames() {
    let g = common::gpu();
    let (mut cached, mut fresh) = (Renderer::new(&g.device), Renderer::new(&g.device));
    let mut s = base("update = 2");
    for k in 1..=5 {
        s.moving_z = 1.5 + 0.3 * k as f32;
        check(
            &mut cached,
            &mut fresh,
            &g,
            &s,
            k % 2 == 1,
            &format!("frame {k}"),
        );
    }
}

#[test]
fn a_changed_light_or_caster_is_drawn_again() {
    let g = common::gpu();
    let (mut cached, mut fresh) = (Renderer::new(&g.device), Renderer::new(&g.device));
    let mut s = base("update = \"static\"");
    check(&mut cached, &mut fresh, &g, &s, true, "first frame");
    s.moving_z = 2.0;
    check(&mut cached, &mut fresh, &g, &s, false, "unchanged");
    s.x = -1.4;
    check(
        &mut cached,
        &mut fresh,
        &g,
        &s,
        true,
        "the cached light moved",
    );
    s.moving_z = 2.5;
    check(
        &mut cached,
        &mut fresh,
        &g,
        &s,
        false,
        "unchanged after the move",
    );
    s.technique = "technique = \"esm\"\nfilter = \"blur\"\nfilter_radius = 8\nbias = 0.002";
    check(&mut cached, &mut fresh, &g, &s, true, "its filter changed");
    check(
        &mut cached,
        &mut fresh,
        &g,
        &s,
        false,
        "unchanged after the filter",
    );
    s.box_x = 0.2;
    check(&mut cached, &mut fresh, &g, &s, true, "a caster moved");
    check(
        &mut cached,
        &mut fresh,
        &g,
        &s,
        false,
        "unchanged after the caster",
    );
}

#[test]
fn bad_update_values_name_the_key_and_line() {
    for bad in ["0", "-1", "1.5", "\"sometimes\"", "\"2\"", "true"] {
        let text = base("update = @@").text().replace("@@", bad);
        let line = 1 + text
            .lines()
            .position(|l| l.starts_with("update = "))
            .expect("update line");
        let e = Scene::parse(Path::new("static.toml"), &text)
            .err()
            .unwrap_or_else(|| panic!("`update = {bad}` was accepted"))
            .to_string();
        assert!(!e.contains('\n'), "more than one line: {e}");
        assert!(
            e.starts_with(&format!("static.toml:{line}:")),
            "`update = {bad}`: wrong place: {e}"
        );
        assert!(
            e.contains(&format!("`light[{CACHED}].update`")),
            "key missing: {e}"
        );
    }
}
