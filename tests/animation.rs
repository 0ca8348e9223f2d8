//! Animated scenes (`[animation]`): keyframes interpolate as written, bad animations are one
//! line naming the file, the key and its line, a cached light notices the animation moving it,
//! and the temporal error (`evaluate::temporal`) has its known answers on lavapipe: 0 for a
//! still animation, and for a light stepping by a quarter of a map texel a frame, the hard
//! shadow's edge jumps from texel to texel while a wide VSM blur slides with it.

mod common;

use std::path::Path;

use glam::Vec3;
use shadowgraph::low_level::evaluate::temporal::{
    TemporalError, animation_temporal_error, animation_truths, animation_visibility,
};
use shadowgraph::low_level::render::{RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::truth::{Emitter, TruthOptions};

/// A directional light over a sphere floating above a plane, 48×36 pixels; `shadow` is its
/// `[light.shadow]` body, `light` extra light keys, `animation` the `[animation]` text.
fn text(shadow: &str, light: &str, animation: &str) -> String {
    format!(
        r#"
[output]
width = 48
height = 36

[camera]
position = [0.0, 5.0, 4.5]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 45.0

[[light]]
kind = "directional"
position = [0.0, 8.0, 2.0]
target = [0.0, 0.0, 0.0]
extent = 3.0
near = 1.0
far = 15.0
size = 0.3
shadow_map = 32
{light}

[light.shadow]
{shadow}

[[object]]
shape = "plane"
size = [8.0, 8.0]

[[object]]
shape = "sphere"
radius = 0.7
translate = [0.0, 1.0, 0.0]

{animation}
"#
    )
}

fn parse(text: &str) -> Result<Scene, String> {
    Scene::parse(Path::new("anim.toml"), text).map_err(|e| e.to_string())
}

const HARD: &str = "technique = \"hard\"\nbias = 0.01";

/// Over 6 frames the light (position and target together) moves 0.234 units along x: a
/// quarter of a texel (6 units / 32 texels) a frame.
const QUARTER_TEXEL_STEPS: &str = r#"
[animation]
frames = 6

[[animation.track]]
animate = "light[0].position"
keys = [{ frame = 0, value = [0.0, 8.0, 2.0] }, { frame = 5, value = [0.234375, 8.0, 2.0] }]

[[animation.track]]
animate = "light[0].target"
keys = [{ frame = 0, value = [0.0, 0.0, 0.0] }, { frame = 5, value = [0.234375, 0.0, 0.0] }]
"#;

#[test]
fn keyframes_interpolate_linearly_and_hold_at_the_ends() {
    let anim = r#"
[animation]
frames = 9

[[animation.track]]
animate = "camera.position"
keys = [
  { frame = 2, value = [0.0, 5.0, 4.5] },
  { frame = 6, value = [1.0, 6.0, 4.5] },
]

[[animation.track]]
animate = "object[1].translate"
keys = [{ frame = 0, value = [0.0, 1.0, 0.0] }, { frame = 8, value = [2.0, 1.0, -1.0] }]
"#;
    let s = parse(&text(HARD, "", anim)).expect("scene");
    assert_eq!(s.frames(), 9);
    let sphere0: Vec<Vec3> = s.objects[1].mesh.positions.clone();
    for f in 0..9 {
        let at = s.at_frame(f).expect("frame");
        // Camera: held at the first key before frame 2, then linear to frame 6, then held.
        let t = ((f64::from(f) - 2.0) / 4.0).clamp(0.0, 1.0);
        let want = [t, 5.0 + t, 4.5];
        let got = at.camera.position.as_dvec3().to_array();
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-6,
                "frame {f}: {got:?} vs {want:?}"
            );
        }
        // The sphere moves by the track's value less its own `translate`; the plane stays.
        let by = [2.0 * f64::from(f) / 8.0, 0.0, -f64::from(f) / 8.0];
        for (p, p0) in at.objects[1].mesh.positions.iter().zip(&sphere0) {
            let d = (*p - *p0).as_dvec3().to_array();
            for k in 0..3 {
                assert!(
                    (d[k] - by[k]).abs() < 1e-5,
                    "frame {f}: moved by {d:?}, not {by:?}"
                );
            }
        }
        assert_eq!(at.objects[0].mesh.positions, s.objects[0].mesh.positions);
    }
    let e = s.at_frame(9).expect_err("frame 9 of 9").to_string();
    assert!(e.contains("frame 9") && e.contains("anim.toml:"), "{e}");
}

#[test]
fn bad_animations_name_the_key_and_line() {
    let track = |keys: &str| {
        format!(
            "[animation]\nframes = 4\n\n[[animation.track]]\nanimate = \"light[0].position\"\nkeys = [{keys}]\n"
        )
    };
    let cases = [
        ("[animation]\nframes = 0\n".to_string(), "frames = 0", "`animation.frames`"),
        ("[animation]\nframes = -3\n".to_string(), "frames = -3", "`animation.frames`"),
        (track("{ frame = 0, value = [nan, 8.0, 2.0] }"), "keys = ", "keys[0].value"),
        (track("{ frame = 0, value = [0.0, inf, 2.0] }"), "keys = ", "keys[0].value"),
        (track("{ frame = 4, value = [0.0, 8.0, 2.0] }"), "keys = ", "keys[0].frame"),
        (
            track("{ frame = 2, value = [0.0, 8.0, 2.0] }, { frame = 1, value = [1.0, 8.0, 2.0] }"),
            "keys = ",
            "keys[1].frame",
        ),
        (track(""), "keys = ", "`animation.track[0].keys`"),
        (
            track("{ frame = 0, value = [0.0, 8.0, 2.0] }, { frame = 2, value = [0.0, -8.0, -2.0] }"),
            "animate = ",
            "light[0].target",
        ),
        (
            "[animation]\nframes = 2\n\n[[animation.track]]\nanimate = \"light[3].position\"\nkeys = [{ frame = 0, value = [0.0, 1.0, 0.0] }]\n".to_string(),
            "animate = ",
            "`animation.track[0].animate`",
        ),
        (
            "[animation]\nframes = 2\n\n[[animation.track]]\nanimate = \"object[1].rotate\"\nkeys = [{ frame = 0, value = [0.0, 1.0, 0.0] }]\n".to_string(),
            "animate = ",
            "`animation.track[0].animate`",
        ),
    ];
    for (anim, line_start, key) in cases {
        let t = text(HARD, "", &anim);
        let line = 1 + t
            .lines()
            .position(|l| l.starts_with(line_start))
            .expect("line");
        let e = parse(&t)
            .err()
            .unwrap_or_else(|| panic!("accepted:\n{anim}"));
        assert!(!e.contains('\n'), "more than one line: {e}");
        assert!(
            e.starts_with(&format!("anim.toml:{line}:")),
            "wrong place for {key}: {e}"
        );
        assert!(e.contains(key), "`{key}` missing: {e}");
    }
}

#[test]
fn a_static_light_notices_the_animation_moving_it() {
    let g = common::gpu();
    // Moves over frames 0–2, then holds.
    let anim = r#"
[animation]
frames = 5

[[animation.track]]
animate = "light[0].position"
keys = [{ frame = 0, value = [0.0, 8.0, 2.0] }, { frame = 2, value = [0.5, 8.0, 2.0] }]
"#;
    let s = parse(&text(HARD, "update = \"static\"", anim)).expect("scene");
    let mut r = Renderer::new(&g.device);
    let drawn: Vec<bool> = (0..s.frames())
        .map(|f| {
            let frame = r
                .render_frame(&g.device, &g.queue, &s, f, RenderOptions::default())
                .expect("render");
            frame.recorded[0].contains(&"light0.shadow_raster".to_string())
        })
        .collect();
    assert_eq!(drawn, [true, true, true, false, false]);
}

/// The temporal error of `shadow` over `animation`, against a 16-sample truth at 512².
fn temporal(g: &shadowgraph::low_level::gpu::Gpu, shadow: &str, animation: &str) -> TemporalError {
    let s = parse(&text(shadow, "", animation)).expect("scene");
    let mut r = Renderer::new(&g.device);
    let opts = TruthOptions {
        emitter: Emitter::Stratified { k: 16, seed: 1 },
        resolution: Some(512),
    };
    let truths = animation_truths(&mut r, &g.device, &g.queue, &s, &opts).expect("truth");
    let vis = animation_visibility(&mut r, &g.device, &g.queue, &s).expect("render");
    animation_temporal_error(&truths, &vis).expect("temporal error")
}

#[test]
fn hard_shadows_flicker_under_sub_texel_steps_and_a_wide_blur_does_not() {
    let g = common::gpu();
    let vsm = "technique = \"vsm\"\nfilter = \"blur\"\nfilter_radius = 4\nbias = 0.002";
    let still = "[animation]\nframes = 3\n";
    for shadow in [HARD, vsm] {
        let e = temporal(&g, shadow, still);
        assert_eq!(e.pairs, 2);
        assert!(e.pixels > 0, "no penumbra pixels");
        assert_eq!(e.mean_abs, 0.0, "a still animation flickers: {e:?}");
    }
    let hard = temporal(&g, HARD, QUARTER_TEXEL_STEPS);
    let soft = temporal(&g, vsm, QUARTER_TEXEL_STEPS);
    eprintln!("hard {hard:?}\nvsm {soft:?}");
    assert!(hard.pixels > 50 && soft.pixels > 50, "{hard:?} {soft:?}");
    assert!(
        hard.mean_abs > 3.0 * soft.mean_abs,
        "hard {} vs VSM blur {}",
        hard.mean_abs,
        soft.mean_abs
    );
}

#[test]
fn the_bundled_animated_scenes_move_what_they_say() {
    let g = common::gpu();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    // (scene, its frames, per frame whether light 0's map is redrawn)
    let cases: [(&str, u32, &[bool]); 2] = [
        ("colonnade_sun.toml", 8, &[true; 8]),
        (
            "moving_object.toml",
            9,
            &[true, true, true, true, true, true, true, false, false],
        ),
    ];
    for (name, frames, redrawn) in cases {
        let mut s = Scene::load(root.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.frames(), frames, "{name}");
        // What is redrawn does not depend on the image size.
        (s.width, s.height) = (32, 24);
        let mut r = Renderer::new(&g.device);
        let got: Vec<bool> = (0..frames)
            .map(|f| {
                let frame = r
                    .render_frame(&g.device, &g.queue, &s, f, RenderOptions::default())
                    .unwrap_or_else(|e| panic!("{name} frame {f}: {e}"));
                frame.recorded[0].contains(&"light0.shadow_raster".to_string())
            })
            .collect();
        assert_eq!(got, redrawn, "{name}");
    }
}
