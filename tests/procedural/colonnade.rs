//! `scenes/colonnade.toml`: two rows of columns on a stepped platform under architraves and a
//! pergola of thin slats, lit by a low sun from the side.

use super::{Sun, Toml, num, v3};

/// Columns per row, their spacing along x, and the rows' z.
const COLUMNS: usize = 8;
const SPACING: f64 = 1.8;
const ROWS: [f64; 2] = [-1.8, 1.8];
/// Top of the platform.
const FLOOR: f64 = 0.35;
/// Shaft height and radius.
const SHAFT: (f64, f64) = (3.0, 0.22);
/// Pergola slats: count and spacing along x.
const SLATS: usize = 17;
const SLAT_SPACING: f64 = 0.8;

/// The scene file.
pub fn scene() -> String {
    let mut t = Toml::new(
        &[
            "Demonstrates long thin occluders under a grazing light: a colonnade whose columns and \
             pergola slats throw shadows 2.6 times their height across a stepped platform and the \
             ground, sharp at the column bases (contact shadows) and soft where the slats' lattice \
             lands 11 units away.",
        ],
        [0.1, 0.1, 0.13],
        (480, 360),
        [0.86, 0.72, 0.58],
        ([-3.0, 9.0, 20.0], [4.0, 0.0, 2.8], 54.0),
    );
    t.sun(&Sun {
        comment: vec![
            "A low sun 21 degrees up, from behind and to the left: shadows run 2.6 times an object's"
                .into(),
            "height to the front right. 0.8 units wide at 40 units (1.1 degrees): the slats' shadows,"
                .into(),
            "12 units along the light from the slats, blur over ~0.25 units; the columns' are sharp"
                .into(),
            "at their feet. The slats also stripe the columns' lit sides.".into(),
        ],
        target: [4.0, 0.0, 2.5],
        azimuth: -135.0,
        elevation: 21.0,
        distance: 40.0,
        extent: 14.0,
        near: 20.0,
        far: 62.0,
        size: 0.8,
        color: [1.0, 0.86, 0.7],
        intensity: 1.3,
        shadow_map: 1024,
        shadow: vec![
            "technique = \"pcss\"".into(),
            "blocker_samples = 16".into(),
            "filter_samples = 32".into(),
            "bias = 0.002".into(),
            "slope_bias = 1.0".into(),
        ],
    });
    t.object(
        "plane",
        &[
            ("size", "[40.0, 40.0]".into()),
            ("color", v3([0.72, 0.68, 0.6])),
        ],
    );
    let length = (COLUMNS - 1) as f64 * SPACING;
    t.comment("The platform: two steps.");
    // (width, depth, bottom, top): the upper step's top is the floor.
    for (w, d, lo, hi) in [
        (length + 3.4, 7.0, 0.0, 0.2),
        (length + 2.6, 6.2, 0.2, FLOOR),
    ] {
        t.object(
            "box",
            &[
                ("size", v3([w, hi - lo, d])),
                ("translate", v3([0.0, 0.5 * (lo + hi), 0.0])),
                ("color", v3([0.82, 0.8, 0.74])),
            ],
        );
    }
    for (r, &z) in ROWS.iter().enumerate() {
        for c in 0..COLUMNS {
            let x = -0.5 * length + c as f64 * SPACING;
            column(&mut t, r * COLUMNS + c, x, z);
        }
    }
    let top = FLOOR + 0.2 + SHAFT.0 + 0.2;
    t.comment("Architraves along the rows.");
    for &z in &ROWS {
        t.object(
            "box",
            &[
                ("size", v3([length + 0.9, 0.45, 0.6])),
                ("translate", v3([0.0, top + 0.225, z])),
                ("color", v3([0.85, 0.82, 0.75])),
            ],
        );
    }
    t.comment("Pergola slats across the rows: long thin occluders.");
    let span = (SLATS - 1) as f64 * SLAT_SPACING;
    for s in 0..SLATS {
        let x = -0.5 * span + s as f64 * SLAT_SPACING;
        t.object(
            "box",
            &[
                ("size", v3([0.1, 0.12, ROWS[1] - ROWS[0] + 1.4])),
                ("translate", v3([x, top + 0.45 + 0.06, 0.0])),
                ("color", v3([0.6, 0.45, 0.32])),
            ],
        );
    }
    t.finish()
}

/// Column `k` at (x, z): a square plinth, a cylinder shaft, a square capital.
fn column(t: &mut Toml, k: usize, x: f64, z: f64) {
    let (h, r) = SHAFT;
    t.comment(&format!("Column {k}."));
    t.object(
        "box",
        &[
            ("size", v3([0.66, 0.2, 0.66])),
            ("translate", v3([x, FLOOR + 0.1, z])),
            ("color", v3([0.8, 0.78, 0.72])),
        ],
    );
    t.object(
        "cylinder",
        &[
            ("radius", num(r)),
            ("height", num(h)),
            ("translate", v3([x, FLOOR + 0.2 + 0.5 * h, z])),
            ("color", v3([0.9, 0.88, 0.82])),
        ],
    );
    t.object(
        "box",
        &[
            ("size", v3([0.62, 0.2, 0.62])),
            ("translate", v3([x, FLOOR + 0.2 + h + 0.1, z])),
            ("color", v3([0.8, 0.78, 0.72])),
        ],
    );
}
