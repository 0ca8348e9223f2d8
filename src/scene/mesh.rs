//! Triangle meshes: the built-in shapes and OBJ loading.

use std::path::Path;

use glam::{Mat3, Mat4, Vec3};

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

/// Vertex as uploaded: keep in sync with `VsIn` in `kernels/shared/vertex.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// World position.
    pub position: [f32; 3],
    /// World normal.
    pub normal: [f32; 3],
    /// Index into the scene's material (object colour) table.
    pub material: u32,
}

impl Mesh {
    /// The mesh under `m` (normals by the inverse transpose).
    pub fn transformed(&self, m: Mat4) -> Mesh {
        let nm = Mat3::from_mat4(m).inverse().transpose();
        Mesh {
            positions: self
                .positions
                .iter()
                .map(|&p| m.transform_point3(p))
                .collect(),
            normals: self
                .normals
                .iter()
                .map(|&n| (nm * n).normalize_or_zero())
                .collect(),
            indices: self.indices.clone(),
        }
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

/// Loads a Wavefront OBJ (triangulated); computes smooth normals when the file has none.
pub fn load_obj(path: &Path) -> Result<Mesh, String> {
    if !path.is_file() {
        return Err(format!("mesh file `{}` not found", path.display()));
    }
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    let mut mesh = Mesh::default();
    for model in models {
        let mm = &model.mesh;
        let base = mesh.positions.len() as u32;
        let pos: Vec<Vec3> = mm
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        if pos.iter().any(|p| !p.is_finite()) {
            return Err(format!("`{}` has a non-finite vertex", path.display()));
        }
        let normals = if mm.normals.len() == mm.positions.len() {
            mm.normals
                .chunks_exact(3)
                .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero())
                .collect()
        } else {
            smooth_normals(&pos, &mm.indices)
        };
        mesh.positions.extend(pos);
        mesh.normals.extend(normals);
        mesh.indices.extend(mm.indices.iter().map(|i| i + base));
    }
    if mesh.indices.is_empty() {
        return Err(format!("`{}` has no triangles", path.display()));
    }
    Ok(mesh)
}

/// Area-weighted vertex normals.
fn smooth_normals(pos: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; pos.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let face = (pos[b] - pos[a]).cross(pos[c] - pos[a]);
        for i in [a, b, c] {
            n[i] += face;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Y)).collect()
}
