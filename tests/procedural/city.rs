//! `scenes/city.toml`: a 4 × 4 grid of city blocks, each a kerbed slab with four buildings of
//! random heights (a few towers, some with a setback storey), under one large directional
//! light.

use super::{Rng, Sun, Toml, num, v3};

/// Blocks per side, a block's side and the street width.
const BLOCKS: usize = 4;
const BLOCK: f64 = 8.0;
const STREET: f64 = 2.6;

/// Facade colours: concrete, sandstone, brick, blue glass, pale stone.
const PALETTE: [[f64; 3]; 5] = [
    [0.7, 0.7, 0.68],
    [0.78, 0.68, 0.52],
    [0.66, 0.4, 0.32],
    [0.45, 0.55, 0.66],
    [0.85, 0.82, 0.76],
];

/// The scene file.
pub fn scene() -> String {
    let mut t = Toml::new(
        &[
            "Demonstrates a wide depth range under one large directional light: a city of 4 x 4 \
             blocks with buildings 1.5 to 19 units tall seen from above one corner, the nearest \
             street 44 units from the camera and the farthest 91.",
            "One 1024^2 map covers the whole city and its shadows (5.5 cm texels), so near \
             buildings get no finer shadows than far ones; the frustum is fitted to the city, \
             not to the view. `city_street.toml` is the same city from the street, in cascades.",
        ],
        [0.12, 0.12, 0.14],
        (480, 360),
        [0.6, 0.7, 0.85],
        ([36.0, 33.0, 44.0], [1.0, 0.0, -1.0], 45.0),
    );
    sun(
        &mut t,
        1024,
        vec![
            "technique = \"msm\"".into(),
            "format = \"f16\"                        # 16-bit quantized moments over a wide depth range"
                .into(),
            "filter = \"sat\"".into(),
            "filter_width = 3.0".into(),
            "bias = 0.001".into(),
        ],
    );
    city(t)
}

/// `scenes/city_street.toml`: the same city seen from a street corner, the nearest facade a
/// few units from the camera and the far side of the city 60 away, under the same sun in four
/// cascades of 512² (the memory of one 1024² map).
pub fn street_scene() -> String {
    let mut t = Toml::new(
        &[
            "Demonstrates cascaded shadow maps: the city of `city.toml` seen from a street corner at \
             head height, the view running from ~1 unit to ~70 across the city.",
            "Four 512^2 cascades (the memory of one 1024^2 map) split the camera's view range with \
             the practical split (lambda 0.7) and blend over the last 10% of each; with \
             `cascades = 1` the one map spans the whole city (5.5 cm texels at 1024^2).",
        ],
        [0.12, 0.12, 0.14],
        (480, 360),
        [0.6, 0.7, 0.85],
        ([0.8, 2.5, 26.0], [-2.5, 1.0, -20.0], 60.0),
    );
    sun(
        &mut t,
        512,
        vec![
            "technique = \"pcf\"".into(),
            "radius = 1".into(),
            "bias = 0.001".into(),
            "cascades = 4".into(),
            "cascade_lambda = 0.7".into(),
            "cascade_blend = 0.1".into(),
        ],
    );
    city(t)
}

/// The sun both views share, with a `map`² map and these `[light.shadow]` lines.
fn sun(t: &mut Toml, map: u32, shadow: Vec<String>) {
    t.sun(&Sun {
        comment: vec![
            "Sun 45 degrees up, from the left and in front: shadows as long as the buildings are"
                .into(),
            "tall, toward the back right. Depths along the light run from ~28 (tower tops) to ~86"
                .into(),
            "(the ground's far corner). 2 units wide at 60 units (1.9 degrees): a tower's shadow"
                .into(),
            "tip, 27 units along the light from its roof, blurs over ~0.9 units.".into(),
        ],
        target: [0.0, 0.0, 0.0],
        azimuth: 155.0,
        elevation: 45.0,
        distance: 60.0,
        extent: 28.0,
        near: 25.0,
        far: 95.0,
        size: 2.0,
        color: [1.0, 0.96, 0.88],
        intensity: 1.2,
        shadow_map: map,
        shadow,
    });
}

/// The ground and the blocks.
fn city(mut t: Toml) -> String {
    let pitch = BLOCK + STREET;
    let span = BLOCKS as f64 * pitch - STREET;
    t.object(
        "plane",
        &[
            ("size", num(span + 16.0)),
            ("color", v3([0.34, 0.34, 0.36])),
        ],
    );
    let mut rng = Rng::new(0x0c17_b10c);
    for bi in 0..BLOCKS {
        for bj in 0..BLOCKS {
            let cx = -0.5 * span + 0.5 * BLOCK + bi as f64 * pitch;
            let cz = -0.5 * span + 0.5 * BLOCK + bj as f64 * pitch;
            block(&mut t, &mut rng, bi * BLOCKS + bj, [cx, cz]);
        }
    }
    t.finish()
}

/// Block `k` centred at (x, z): a kerb slab and four buildings, one per quarter.
fn block(t: &mut Toml, rng: &mut Rng, k: usize, [x, z]: [f64; 2]) {
    t.comment(&format!("Block {k}."));
    t.object(
        "box",
        &[
            ("size", v3([BLOCK, 0.15, BLOCK])),
            ("translate", v3([x, 0.075, z])),
            ("color", v3([0.62, 0.6, 0.58])),
        ],
    );
    let q = 0.25 * BLOCK;
    for (dx, dz) in [(-q, -q), (q, -q), (-q, q), (q, q)] {
        let w = rng.range(2.6, 3.5);
        let d = rng.range(2.6, 3.5);
        // Mostly low, a few towers: the square of a uniform number.
        let u = rng.unit();
        let h = 1.5 + 15.5 * u * u;
        let shade = rng.range(0.8, 1.0);
        let tint = PALETTE[(rng.next_u64() % PALETTE.len() as u64) as usize].map(|c| c * shade);
        let setback = h > 5.0 && rng.unit() < 0.6;
        let (bx, bz) = (x + dx + rng.range(-0.3, 0.3), z + dz + rng.range(-0.3, 0.3));
        t.object(
            "box",
            &[
                ("size", v3([w, h, d])),
                ("translate", v3([bx, 0.15 + 0.5 * h, bz])),
                ("color", v3(tint)),
            ],
        );
        if setback {
            let top = rng.range(1.5, 3.5);
            t.object(
                "box",
                &[
                    ("size", v3([0.6 * w, top, 0.6 * d])),
                    ("translate", v3([bx, 0.15 + h + 0.5 * top, bz])),
                    ("color", v3(tint.map(|c| 0.9 * c))),
                ],
            );
        }
    }
}
