//! `scenes/meshes/canopy.gltf` + `canopy.bin`: a tree's canopy of leaf cards. One mesh (a
//! clump of 14 thin quads with their normals, u16 indices) instanced by 11 nodes in a small
//! hierarchy — translation/rotation/scale nodes, one node given as a matrix, one mirrored — so
//! the bundled file exercises the loader's node transforms. The origin is where the trunk
//! ends; the canopy spans about ±1.1 across and −0.45 to 1.6 up.

use glam::{DMat4, DQuat, DVec3};
use serde_json::json;

use super::Rng;

/// Leaf cards in a clump.
pub const CARDS: usize = 14;
/// Clump nodes.
pub const CLUMPS: usize = 11;
/// Half the card's length and width.
const CARD_HALF: [f64; 2] = [0.24, 0.15];

/// A clump node: its parent group (0 lower ring, 1 upper ring) and local transform.
pub struct Clump {
    /// Group node it hangs from.
    pub group: usize,
    /// Scale.
    pub scale: [f64; 3],
    /// Unit quaternion (x, y, z, w), rounded to 6 decimals.
    pub rotation: [f64; 4],
    /// Translation.
    pub translation: [f64; 3],
    /// Written as a `matrix` instead of TRS.
    pub as_matrix: bool,
}

/// Translation of the two group nodes under the root.
pub const GROUPS: [[f64; 3]; 2] = [[0.0, 0.3, 0.0], [0.0, 0.95, 0.0]];

/// Rounds to 1/1024 (exact in f32).
fn grid(x: f64) -> f64 {
    (x * 1024.0).round() / 1024.0
}

/// Rounds to 6 decimals.
fn six(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The clump mesh in its own frame: positions (on the 1/1024 grid), unit normals, u16
/// indices (two counter-clockwise triangles a card, seen from its normal).
pub fn clump() -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u16>) {
    let mut rng = Rng::new(0x00ca_709e);
    let (mut pos, mut nrm, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for c in 0..CARDS {
        let centre = loop {
            let p = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            if p.length_squared() <= 1.0 {
                break p * DVec3::new(0.5, 0.32, 0.5);
            }
        };
        // Mostly facing up (so they shade the ground), tilted up to 55 degrees.
        let tilt = rng.range(0.0, 55.0).to_radians();
        let azimuth = rng.range(0.0, 360.0).to_radians();
        let spin = rng.range(0.0, 180.0).to_radians();
        let normal = DVec3::new(
            tilt.sin() * azimuth.cos(),
            tilt.cos(),
            tilt.sin() * azimuth.sin(),
        );
        let (a, b) = normal.any_orthonormal_pair();
        let u = a * spin.cos() + b * spin.sin();
        let v = normal.cross(u);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(s, t)| centre + u * (s * CARD_HALF[0]) + v * (t * CARD_HALF[1]))
            .map(|p| DVec3::new(grid(p.x), grid(p.y), grid(p.z)));
        let n = (corners[1] - corners[0])
            .cross(corners[3] - corners[0])
            .normalize();
        let base = (4 * c) as u16;
        for p in corners {
            pos.push(p.as_vec3().to_array());
            nrm.push(n.as_vec3().to_array());
        }
        idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    (pos, nrm, idx)
}

/// The clump nodes: five around the lower ring (one mirrored), four around the upper ring, a
/// top clump given as a matrix, one hanging below.
pub fn clumps() -> Vec<Clump> {
    let mut rng = Rng::new(0x000c_1ab5);
    let mut out = Vec::new();
    let ring = |group: usize, k: usize, n: usize, r: f64, rng: &mut Rng| {
        let a = (k as f64 + rng.range(-0.2, 0.2)) * std::f64::consts::TAU / n as f64;
        let q = DQuat::from_rotation_y(rng.range(0.0, std::f64::consts::TAU))
            * DQuat::from_rotation_x(rng.range(-0.3, 0.3));
        let s = rng.range(0.85, 1.15);
        Clump {
            group,
            scale: [s, rng.range(0.8, 1.1), s].map(six),
            rotation: q.to_array().map(six),
            translation: [r * a.cos(), rng.range(-0.15, 0.15), r * a.sin()].map(grid),
            as_matrix: false,
        }
    };
    for k in 0..5 {
        out.push(ring(0, k, 5, 0.62, &mut rng));
    }
    out[2].scale[0] = -out[2].scale[0];
    for k in 0..4 {
        out.push(ring(1, k, 4, 0.45, &mut rng));
    }
    out.push(Clump {
        group: 1,
        scale: [0.9, 1.0, 0.9],
        rotation: DQuat::from_rotation_y(0.7).to_array().map(six),
        translation: [0.0, 0.45, 0.0],
        as_matrix: true,
    });
    out.push(Clump {
        group: 0,
        scale: [0.8, 0.7, 0.8],
        rotation: [0.0, 0.0, 0.0, 1.0],
        translation: [0.05, -0.4, -0.05],
        as_matrix: false,
    });
    out
}

/// A clump's own transform; as written to the file when it is a matrix (6 decimals).
pub fn local(c: &Clump) -> DMat4 {
    let m = DMat4::from_scale_rotation_translation(
        DVec3::from_array(c.scale),
        DQuat::from_array(c.rotation).normalize(),
        DVec3::from_array(c.translation),
    );
    if c.as_matrix {
        DMat4::from_cols_array(&m.to_cols_array().map(six))
    } else {
        m
    }
}

/// A clump's matrix from the root down (root → group → clump), as the generator means it.
pub fn world(c: &Clump) -> DMat4 {
    DMat4::from_translation(DVec3::from_array(GROUPS[c.group])) * local(c)
}

/// The `.gltf` JSON and its `.bin` buffer.
pub fn files() -> (String, Vec<u8>) {
    let (pos, nrm, idx) = clump();
    let mut bin: Vec<u8> = Vec::new();
    for p in pos.iter().chain(&nrm) {
        for x in p {
            bin.extend(x.to_le_bytes());
        }
    }
    for i in &idx {
        bin.extend(i.to_le_bytes());
    }
    let (vbytes, ibytes) = (12 * pos.len(), 2 * idx.len());
    let bound = |f: fn(f32, f32) -> f32, start: f32| -> Vec<f32> {
        (0..3)
            .map(|k| pos.iter().map(|p| p[k]).fold(start, f))
            .collect()
    };
    let (min, max) = (
        bound(f32::min, f32::INFINITY),
        bound(f32::max, f32::NEG_INFINITY),
    );
    let clumps = clumps();
    let mut nodes = vec![
        json!({"name": "canopy", "children": [1, 2]}),
        json!({"name": "lower", "translation": GROUPS[0], "children": []}),
        json!({"name": "upper", "translation": GROUPS[1], "children": []}),
    ];
    for (k, c) in clumps.iter().enumerate() {
        let node = 3 + k;
        if let Some(children) = nodes[1 + c.group]["children"].as_array_mut() {
            children.push(json!(node));
        }
        let mut n = json!({"name": format!("clump{k}"), "mesh": 0});
        if c.as_matrix {
            n["matrix"] = json!(local(c).to_cols_array());
        } else {
            n["translation"] = json!(c.translation);
            n["rotation"] = json!(c.rotation);
            n["scale"] = json!(c.scale);
        }
        nodes.push(n);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "shadowgraph tests/procedural/canopy.rs"},
        "scene": 0,
        "scenes": [{"name": "canopy", "nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"name": "leaf_cards", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "mode": 4}
        ]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": pos.len(), "type": "VEC3",
             "min": min, "max": max},
            {"bufferView": 1, "componentType": 5126, "count": nrm.len(), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": idx.len(), "type": "SCALAR"},
        ],
        // One view per attribute: two vertex accessors sharing a view would need a byteStride.
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": vbytes, "target": 34962},
            {"buffer": 0, "byteOffset": vbytes, "byteLength": vbytes, "target": 34962},
            {"buffer": 0, "byteOffset": 2 * vbytes, "byteLength": ibytes, "target": 34963},
        ],
        "buffers": [{"uri": "canopy.bin", "byteLength": bin.len()}],
    });
    let text = serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n";
    (text, bin)
}

/// The canopy as the generator means it, flattened in f64: world positions and normals (one
/// per vertex, clump by clump in the hierarchy's depth-first order: the lower group's, then
/// the upper's) and triangles (a mirrored clump's winding reversed).
pub fn flattened() -> (Vec<DVec3>, Vec<DVec3>, Vec<[usize; 3]>) {
    let (pos, nrm, idx) = clump();
    let (mut p, mut n, mut t) = (Vec::new(), Vec::new(), Vec::new());
    let mut ordered = clumps();
    ordered.sort_by_key(|c| c.group);
    for c in ordered {
        let m = world(&c);
        let normal_m = glam::DMat3::from_mat4(m).inverse().transpose();
        let base = p.len();
        p.extend(
            pos.iter()
                .map(|&v| m.transform_point3(glam::Vec3::from(v).as_dvec3())),
        );
        n.extend(
            nrm.iter()
                .map(|&v| (normal_m * glam::Vec3::from(v).as_dvec3()).normalize()),
        );
        let mirrored = m.determinant() < 0.0;
        for tri in idx.chunks_exact(3) {
            let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| base + usize::from(i));
            t.push(if mirrored { [a, c, b] } else { [a, b, c] });
        }
    }
    (p, n, t)
}
