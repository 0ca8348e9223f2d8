//! Triangle meshes: the built-in shapes, transforms and normal repair (OBJ files: `obj`).

use glam::{DMat3, DMat4, DVec3, Mat4, Vec3};

use crate::wgsl_mirrors::Vertex;

/// Indexed triangles with per-vertex normals.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per position.
    pub normals: Vec<Vec3>,
    /// Triangle list.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// The mesh under `m`, computed in f64. Normals go through the cofactor matrix (the inverse
    /// transpose times the determinant, so no division: a scale of 10⁻⁶ on one axis still gives
    /// unit normals); a normal that comes out zero or not finite is left zero for
    /// [`Mesh::repair_normals`].
    pub fn transformed(&self, m: Mat4) -> Mesh {
        self.transformed_f64(m.as_dmat4())
    }

    /// [`Mesh::transformed`] under an f64 matrix (glTF node transforms are composed in f64).
    pub fn transformed_f64(&self, m: DMat4) -> Mesh {
        let [a, b, c] = [
            m.x_axis.truncate(),
            m.y_axis.truncate(),
            m.z_axis.truncate(),
        ];
        let cofactor = DMat3::from_cols(b.cross(c), c.cross(a), a.cross(b));
        let sign = if a.dot(b.cross(c)) < 0.0 { -1.0 } else { 1.0 };
        Mesh {
            positions: self
                .positions
                .iter()
                .map(|&p| m.transform_point3(p.as_dvec3()).as_vec3())
                .collect(),
            normals: self
                .normals
                .iter()
                .map(|&n| {
                    (sign * (cofactor * n.as_dvec3()))
                        .try_normalize()
                        .map_or(Vec3::ZERO, |n| n.as_vec3())
                })
                .collect(),
            indices: self.indices.clone(),
        }
    }

    /// Replaces every normal that is not a finite unit vector by the area-weighted normal of
    /// the faces around its vertex; returns how many were replaced.
    pub fn repair_normals(&mut self) -> usize {
        let bad: Vec<usize> = (0..self.normals.len())
            .filter(|&i| {
                let n = self.normals[i];
                !(n.is_finite() && (n.length() - 1.0).abs() < 1e-3)
            })
            .collect();
        if !bad.is_empty() {
            let faces = self.face_normals();
            for &i in &bad {
                self.normals[i] = faces[i];
            }
        }
        bad.len()
    }

    /// Per vertex, the area-weighted normal of the faces around it (summed in f64); +Y for a
    /// vertex of degenerate faces only.
    pub fn face_normals(&self) -> Vec<Vec3> {
        let mut n = vec![DVec3::ZERO; self.positions.len()];
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            let p = [a, b, c].map(|i| self.positions[i].as_dvec3());
            let face = (p[1] - p[0]).cross(p[2] - p[0]);
            if face.is_finite() {
                for i in [a, b, c] {
                    n[i] += face;
                }
            }
        }
        n.into_iter()
            .map(|v| v.try_normalize().map_or(Vec3::Y, |n| n.as_vec3()))
            .collect()
    }

    /// Unindexed vertices tagged with `material`.
    pub fn vertices(&self, material: u32) -> impl Iterator<Item = Vertex> + '_ {
        self.indices.iter().map(move |&i| Vertex {
            position: self.positions[i as usize].to_array(),
            normal: self.normals[i as usize].to_array(),
            material,
        })
    }

    fn quad(&mut self, corners: [Vec3; 4], normal: Vec3) {
        let base = self.positions.len() as u32;
        self.positions.extend(corners);
        self.normals.extend([normal; 4]);
        self.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
}

/// A plane in XZ at y = 0, centred, normal +Y.
pub fn plane(sx: f32, sz: f32) -> Mesh {
    let (x, z) = (0.5 * sx, 0.5 * sz);
    let mut m = Mesh::default();
    m.quad(
        [
            Vec3::new(-x, 0.0, -z),
            Vec3::new(-x, 0.0, z),
            Vec3::new(x, 0.0, z),
            Vec3::new(x, 0.0, -z),
        ],
        Vec3::Y,
    );
    m
}

/// An axis-aligned box of full size `s`, centred.
pub fn cuboid(s: Vec3) -> Mesh {
    let h = 0.5 * s;
    let mut m = Mesh::default();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            // Two tangent axes, ordered so the quad winds counter-clockwise seen from outside.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f32, b: f32| {
                let mut p = Vec3::ZERO;
                p[axis] = sign * h[axis];
                p[u] = a * h[u];
                p[v] = b * h[v];
                p
            };
            let c = if sign > 0.0 {
                [
                    corner(-1.0, -1.0),
                    corner(1.0, -1.0),
                    corner(1.0, 1.0),
                    corner(-1.0, 1.0),
                ]
            } else {
                [
                    corner(-1.0, -1.0),
                    corner(-1.0, 1.0),
                    corner(1.0, 1.0),
                    corner(1.0, -1.0),
                ]
            };
            m.quad(c, n);
        }
    }
    m
}

/// A UV sphere, centred.
pub fn sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let mut m = Mesh::default();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            m.positions.push(n * radius);
            m.normals.push(n);
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + row;
            m.indices.extend([a, a + 1, b, a + 1, b + 1, b]);
        }
    }
    m
}

/// A cylinder along Y, centred, with caps.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut m = Mesh::default();
    let h = 0.5 * height;
    for s in 0..segments {
        let a0 = std::f32::consts::TAU * s as f32 / segments as f32;
        let a1 = std::f32::consts::TAU * (s + 1) as f32 / segments as f32;
        let (d0, d1) = (
            Vec3::new(a0.cos(), 0.0, a0.sin()),
            Vec3::new(a1.cos(), 0.0, a1.sin()),
        );
        let base = m.positions.len() as u32;
        m.positions.extend([
            d0 * radius - Vec3::Y * h,
            d0 * radius + Vec3::Y * h,
            d1 * radius + Vec3::Y * h,
            d1 * radius - Vec3::Y * h,
        ]);
        m.normals.extend([d0, d0, d1, d1]);
        m.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        // Counter-clockwise seen from outside: d1 before d0 on the top cap, d0 before d1 below.
        for (y, n, (e0, e1)) in [(h, Vec3::Y, (d1, d0)), (-h, -Vec3::Y, (d0, d1))] {
            let base = m.positions.len() as u32;
            m.positions.extend([
                Vec3::Y * y,
                e0 * radius + Vec3::Y * y,
                e1 * radius + Vec3::Y * y,
            ]);
            m.normals.extend([n; 3]);
            m.indices.extend([base, base + 1, base + 2]);
        }
    }
    m
}
