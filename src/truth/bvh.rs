//! A bounding-volume hierarchy over the scene's triangles in f64: median splits on the longest
//! axis of the centroids' bounds, leaves of at most four triangles, Möller–Trumbore
//! intersection (two-sided, as the rasterizer draws without culling).

use glam::DVec3;

use crate::scene::Scene;

const LEAF: usize = 4;

/// One triangle: corners, vertex normals and the object (material) index.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// Corners.
    pub p: [DVec3; 3],
    /// Vertex normals.
    pub n: [DVec3; 3],
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first triangle; inner: index of the second child (the first follows the node).
    index: u32,
    /// Leaf: triangle count; inner: 0.
    count: u32,
}

/// A ray's nearest hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Ray parameter.
    pub t: f64,
    /// Triangle index (in [`Bvh::triangles`]).
    pub triangle: usize,
    /// Barycentrics of corners 1 and 2.
    pub uv: [f64; 2],
}

/// The hierarchy and its triangles (reordered).
pub struct Bvh {
    /// Triangles, in leaf order.
    pub triangles: Vec<Triangle>,
    nodes: Vec<Node>,
}

impl Bvh {
    /// Builds the hierarchy over every object's triangles.
    pub fn new(scene: &Scene) -> Self {
        let mut triangles: Vec<Triangle> = Vec::new();
        for o in &scene.objects {
            let m = &o.mesh;
            for t in m.indices.chunks_exact(3) {
                let c = |k: usize| t[k] as usize;
                triangles.push(Triangle {
                    p: [0, 1, 2].map(|k| m.positions[c(k)].as_dvec3()),
                    n: [0, 1, 2].map(|k| m.normals[c(k)].as_dvec3()),
                });
            }
        }
        let mut bvh = Self {
            triangles,
            nodes: Vec::new(),
        };
        let n = bvh.triangles.len();
        if n > 0 {
            bvh.build(0, n);
        }
        bvh
    }

    fn build(&mut self, start: usize, end: usize) -> usize {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for t in &self.triangles[start..end] {
            for p in t.p {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            let c = centroid(t);
            clo = clo.min(c);
            chi = chi.max(c);
        }
        let at = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            index: start as u32,
            count: (end - start) as u32,
        });
        if end - start <= LEAF {
            return at;
        }
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = start + (end - start) / 2;
        self.triangles[start..end].select_nth_unstable_by(mid - start, |a, b| {
            centroid(a)[axis].total_cmp(&centroid(b)[axis])
        });
        self.build(start, mid);
        let second = self.build(mid, end);
        self.nodes[at].index = second as u32;
        self.nodes[at].count = 0;
        at
    }

    /// The nearest hit with `t` in `(t_min, t_max)`, skipping triangle `skip`.
    pub fn nearest(
        &self,
        o: DVec3,
        d: DVec3,
        t_min: f64,
        t_max: f64,
        skip: Option<usize>,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut limit = t_max;
        self.walk(o, d, t_min, &mut limit, skip, &mut |h| {
            best = Some(h);
            false
        });
        best
    }

    /// Whether anything is hit with `t` in `(t_min, t_max)`, skipping triangle `skip`.
    pub fn occluded(
        &self,
        o: DVec3,
        d: DVec3,
        t_min: f64,
        t_max: f64,
        skip: Option<usize>,
    ) -> bool {
        let mut hit = false;
        let mut limit = t_max;
        self.walk(o, d, t_min, &mut limit, skip, &mut |_| {
            hit = true;
            true
        });
        hit
    }

    /// Visits hits nearer than `limit` (shrinking it to each hit); `found` returns true to stop.
    fn walk(
        &self,
        o: DVec3,
        d: DVec3,
        t_min: f64,
        limit: &mut f64,
        skip: Option<usize>,
        found: &mut dyn FnMut(Hit) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = d.recip();
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = self.nodes[i];
            if !slab(node.lo, node.hi, o, inv, t_min, *limit) {
                continue;
            }
            if node.count == 0 {
                stack.push(node.index as usize);
                stack.push(i + 1);
                continue;
            }
            let first = node.index as usize;
            for k in first..first + node.count as usize {
                if Some(k) == skip {
                    continue;
                }
                if let Some((t, uv)) = intersect(&self.triangles[k], o, d) {
                    if t > t_min && t < *limit {
                        *limit = t;
                        if found(Hit { t, triangle: k, uv }) {
                            return;
                        }
                    }
                }
            }
        }
    }
}

fn centroid(t: &Triangle) -> DVec3 {
    (t.p[0] + t.p[1] + t.p[2]) / 3.0
}

/// Whether the ray meets the box for some `t` in `[t_min, t_max]`.
fn slab(lo: DVec3, hi: DVec3, o: DVec3, inv: DVec3, t_min: f64, t_max: f64) -> bool {
    let (mut t0, mut t1) = (t_min, t_max);
    for k in 0..3 {
        if inv[k].is_infinite() {
            // Parallel to this slab: inside it or never.
            if o[k] < lo[k] || o[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo[k] - o[k]) * inv[k], (hi[k] - o[k]) * inv[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1
}

/// Möller–Trumbore, two-sided: `(t, [u, v])` where the ray meets the triangle's plane inside it.
fn intersect(tri: &Triangle, o: DVec3, d: DVec3) -> Option<(f64, [f64; 2])> {
    let e1 = tri.p[1] - tri.p[0];
    let e2 = tri.p[2] - tri.p[0];
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - tri.p[0];
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some((e2.dot(qv) * inv, [u, v]))
}
