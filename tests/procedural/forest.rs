//! `scenes/forest.toml`: trees on a jittered grid, each a cylinder trunk under the glTF canopy
//! of leaf cards, plus fallen logs and rocks; a high sun behind and to the left.

use super::{Rng, Sun, Toml, num, v3};

/// Grid cells per side, and the cell's size.
const CELLS: usize = 6;
const CELL: f64 = 2.9;

/// The canopies' colour (the forest's test tells them from the trunks by it).
pub const CANOPY_COLOR: [f64; 3] = [0.3, 0.5, 0.22];

/// The scene file.
pub fn scene() -> String {
    let mut t = Toml::new(
        &[
            "Demonstrates depth complexity: a forest whose canopies are thin overlapping leaf cards \
             (a glTF mesh), so light passes several layers at many depths: VSM and ESM bleed light \
             under the canopies, CSM rings, and the soft techniques must find many blockers.",
        ],
        [0.1, 0.11, 0.1],
        (480, 360),
        [0.62, 0.72, 0.82],
        ([2.0, 13.0, 22.0], [0.0, 0.0, 0.5], 45.0),
    );
    t.sun(&Sun {
        comment: vec![
            "Sun 55 degrees up, behind and to the left: dappled light, shadows toward the camera."
                .into(),
            "A 1.5-unit-wide area light 30 units away (2.9 degrees): the shadows of leaves 3 units up"
                .into(),
            "have penumbrae ~0.2 units wide; trunk shadows harden at their feet.".into(),
        ],
        target: [0.0, 0.0, 0.0],
        azimuth: -120.0,
        elevation: 55.0,
        distance: 30.0,
        extent: 12.5,
        near: 15.0,
        far: 45.0,
        size: 1.5,
        color: [1.0, 0.95, 0.85],
        intensity: 1.1,
        shadow_map: 1024,
        shadow: vec![
            "technique = \"pcss\"".into(),
            "blocker_samples = 16".into(),
            "filter_samples = 32".into(),
            "bias = 0.002".into(),
        ],
    });
    t.object(
        "plane",
        &[
            ("size", "[24.0, 24.0]".into()),
            ("color", v3([0.4, 0.42, 0.26])),
        ],
    );
    let mut rng = Rng::new(0x00f0_7e57);
    let half = 0.5 * CELLS as f64 * CELL;
    let mut tree = 0;
    for i in 0..CELLS {
        for j in 0..CELLS {
            // A clearing in the middle and a few gaps.
            let skip = rng.unit() < 0.15 || (i, j) == (2, 3);
            let x = -half + (i as f64 + 0.5) * CELL + rng.range(-0.9, 0.9);
            let z = -half + (j as f64 + 0.5) * CELL + rng.range(-0.9, 0.9);
            let s = rng.range(0.8, 1.25);
            let spin = rng.range(0.0, 360.0);
            let lean = rng.range(0.85, 1.0);
            if skip {
                continue;
            }
            tree_at(&mut t, tree, [x, z], s, spin, lean);
            tree += 1;
        }
    }
    logs_and_rocks(&mut t, &mut rng);
    t.finish()
}

/// Tree `k`: a trunk of height 2.4·`s` and the canopy on top, scaled by `s` (its height by
/// `s`·`lean`) and turned `spin` degrees.
fn tree_at(t: &mut Toml, k: usize, [x, z]: [f64; 2], s: f64, spin: f64, lean: f64) {
    let h = 2.4 * s;
    t.comment(&format!("Tree {k}."));
    t.object(
        "cylinder",
        &[
            ("radius", num(0.1 * s)),
            ("height", num(h)),
            ("translate", v3([x, 0.5 * h, z])),
            ("color", v3([0.36, 0.26, 0.18])),
        ],
    );
    t.object(
        "mesh",
        &[
            ("path", "\"meshes/canopy.gltf\"".into()),
            ("translate", v3([x, h - 0.05, z])),
            ("rotate_degrees", v3([0.0, spin, 0.0])),
            ("scale", v3([s, s * lean, s])),
            ("color", v3(CANOPY_COLOR)),
        ],
    );
}

/// Two fallen logs (contact shadows along their length) and a few flattened rocks.
fn logs_and_rocks(t: &mut Toml, rng: &mut Rng) {
    t.comment("Fallen logs.");
    for (x, z, yaw) in [(-1.2, 2.6, 20.0), (3.4, -1.0, -65.0)] {
        t.object(
            "cylinder",
            &[
                ("radius", "0.16".into()),
                ("height", "2.6".into()),
                ("translate", v3([x, 0.16, z])),
                ("rotate_degrees", v3([90.0, yaw, 0.0])),
                ("color", v3([0.4, 0.3, 0.2])),
            ],
        );
    }
    t.comment("Rocks.");
    for _ in 0..4 {
        let (x, z) = (rng.range(-6.0, 6.0), rng.range(-6.0, 6.0));
        let r = rng.range(0.25, 0.45);
        t.object(
            "sphere",
            &[
                ("radius", num(r)),
                ("translate", v3([x, 0.3 * r, z])),
                ("scale", v3([1.0, 0.6, 0.8])),
                ("color", v3([0.5, 0.5, 0.48])),
            ],
        );
    }
}
