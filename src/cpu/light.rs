//! Reference of `kernels/shared/light.wgsl`: where a receiver lands in a light's map.

use glam::{DMat4, DVec3, DVec4};

use crate::model::point;
use crate::wgsl_mirrors::LightGpu;

/// Reference of `LightSample`.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Map UV, y down.
    pub uv: [f64; 2],
    /// Linear depth.
    pub depth: f64,
    /// Distance along the light axis.
    pub view_z: f64,
    /// Inside the map and depth range.
    pub inside: bool,
    /// The pixel's footprint in the map, texels: axes `[0..2]` and `[2..4]` (0: unknown).
    pub footprint: [f64; 4],
    /// Receiver plane: d(depth)/d(texel) along u and v (0 unless [`plane_slope`]).
    pub depth_slope: [f64; 2],
}

fn mat(m: &[[f32; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)))
}

fn v3(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

/// `light_map_width`.
pub fn map_width(l: &LightGpu, z: f64) -> f64 {
    let w = f64::from(l.width_at_unit);
    if l.kind == 0 { w } else { w * z }
}

/// `light_to_light`.
pub fn to_light(l: &LightGpu, p: DVec3) -> DVec3 {
    if l.kind == 0 {
        -v3(l.direction)
    } else {
        (v3(l.position) - p).normalize()
    }
}

/// `light_faces`: N·L of a receiver at `p` with unit normal `n`, which the shading compares with
/// 0 (a receiver facing away reads 0 without a lookup). Returned rather than compared so that a
/// test can set aside receivers where f32 and f64 may disagree on the sign.
pub fn facing(l: &LightGpu, p: DVec3, n: DVec3) -> f64 {
    n.dot(to_light(l, p))
}

/// `light_texel`: the world size of one texel at view distance `z`.
pub fn texel(l: &LightGpu, z: f64) -> f64 {
    map_width(l, z) / (f64::from(l.map_size[0]) * f64::from(l.face_uv[0]))
}

/// `light_sample`: project `p` after the normal offset along `n`.
pub fn sample(l: &LightGpu, p: DVec3, n: DVec3) -> LightSample {
    if l.kind == 2 {
        return point_sample(l, p, n);
    }
    let view = mat(&l.view);
    let (near, far) = (f64::from(l.near), f64::from(l.far));
    let z0 = -(view * p.extend(1.0)).z;
    let texel = texel(l, z0.max(near));
    let ndl = n.dot(to_light(l, p)).clamp(0.0, 1.0);
    let q = p + n * (f64::from(l.normal_bias) * texel * (1.0 - ndl));
    let clip: DVec4 = mat(&l.view_proj) * q.extend(1.0);
    let ndc = [clip.x / clip.w, clip.y / clip.w];
    let uv = [0.5 + 0.5 * ndc[0], 0.5 - 0.5 * ndc[1]];
    let view_z = -(view * q.extend(1.0)).z;
    let depth = (view_z - near) / (far - near);
    let inside = clip.w > 0.0
        && uv.iter().all(|&c| (0.0..=1.0).contains(&c))
        && (0.0..=1.0).contains(&depth);
    let depth_slope = if plane_slope(l) {
        depth_slope(l, q, n, view_z)
    } else {
        [0.0; 2]
    };
    LightSample {
        uv,
        depth,
        view_z,
        inside,
        footprint: [0.0; 4],
        depth_slope,
    }
}

/// `point_sample`: a point light's receiver, moved by the normal offset at the texel size of
/// the face that sees it, projected through the view of the face that sees the moved point
/// (the matrices the raster pass draws with, `model::point::PointLayout::view`, in f64) into
/// that face's tile of the atlas.
pub fn point_sample(l: &LightGpu, p: DVec3, n: DVec3) -> LightSample {
    let position = v3(l.position);
    let (near, far) = (f64::from(l.near), f64::from(l.far));
    let q = point_moved(l, p, n);
    let f = point::face_of(q - position);
    let (forward, up) = point::face_axes(f);
    let view = DMat4::look_at_rh(position, position + forward.as_dvec3(), up.as_dvec3());
    let v = (view * q.extend(1.0)).truncate();
    let view_z = -v.z;
    let t = 0.5 * f64::from(l.width_at_unit) * view_z;
    let tile = [0.5 + 0.5 * v.x / t, 0.5 - 0.5 * v.y / t];
    let (col, row) = (f64::from(f % point::COLUMNS), f64::from(f / point::COLUMNS));
    let depth = (view_z - near) / (far - near);
    let depth_slope = if plane_slope(l) {
        let nv = (view * n.extend(0.0)).truncate();
        depth_slope_view(l, v, nv, view_z, true)
    } else {
        [0.0; 2]
    };
    LightSample {
        uv: [
            (col + tile[0]) * f64::from(l.face_uv[0]),
            (row + tile[1]) * f64::from(l.face_uv[1]),
        ],
        depth,
        view_z,
        inside: view_z > 0.0 && (0.0..=1.0).contains(&depth),
        footprint: [0.0; 4],
        depth_slope,
    }
}

/// A point light's receiver `p` moved along `n` by the normal offset at the texel size of the
/// face that sees `p`: the point `point_sample` projects (its face is the major axis of the
/// result's direction from the light).
pub fn point_moved(l: &LightGpu, p: DVec3, n: DVec3) -> DVec3 {
    let z0 = (p - v3(l.position)).abs().max_element();
    let ndl = n.dot(to_light(l, p)).clamp(0.0, 1.0);
    p + n * (f64::from(l.normal_bias) * texel(l, z0.max(f64::from(l.near))) * (1.0 - ndl))
}

/// `light_plane_slope`: whether a sample carries its receiver plane's slope.
pub fn plane_slope(l: &LightGpu) -> bool {
    l.receiver_plane > 0.0 || l.cssm_two_depth != 0
}

/// `light_depth_slope`: the depth of the plane through `q` with normal `n` per texel of offset
/// in the map along u and v; 0 where it is not finite (edge-on).
pub fn depth_slope(l: &LightGpu, q: DVec3, n: DVec3, z: f64) -> [f64; 2] {
    let view = mat(&l.view);
    let v = (view * q.extend(1.0)).truncate();
    let nv = (view * n.extend(0.0)).truncate();
    depth_slope_view(l, v, nv, z, l.kind != 0)
}

/// `light_depth_slope_view`: [`depth_slope`] of the receiver at `v` with normal `nv` in the
/// view its map was drawn from (a point light's face's).
pub fn depth_slope_view(l: &LightGpu, v: DVec3, nv: DVec3, z: f64, perspective: bool) -> [f64; 2] {
    let per_world = if !perspective {
        [nv.x / nv.z, -nv.y / nv.z]
    } else {
        let k = z * z / nv.dot(v);
        [-nv.x * k, nv.y * k]
    };
    let texel = f64::from(l.width_at_unit) / (f64::from(l.map_size[0]) * f64::from(l.face_uv[0]));
    let slope = per_world.map(|w| w * texel / f64::from(l.far - l.near));
    if slope.iter().all(|s| s.abs() < 1e30) {
        slope
    } else {
        [0.0; 2]
    }
}

/// `light_receiver_offset`: the receiver plane's depth change to a tap `offset` texels away,
/// capped at ±`receiver_plane`.
pub fn receiver_offset(l: &LightGpu, s: &LightSample, offset: [f64; 2]) -> f64 {
    let cap = f64::from(l.receiver_plane);
    (s.depth_slope[0] * offset[0] + s.depth_slope[1] * offset[1]).clamp(-cap, cap)
}

/// `light_tap_offset`: texels from the receiver to the centre of texel `(x, y)`.
pub fn tap_offset(l: &LightGpu, s: &LightSample, x: i64, y: i64) -> [f64; 2] {
    [
        x as f64 + 0.5 - s.uv[0] * f64::from(l.map_size[0]),
        y as f64 + 0.5 - s.uv[1] * f64::from(l.map_size[1]),
    ]
}

/// `light_footprint`: the differences, in texels, of the points `p + dpdx` and `p + dpdy`
/// projected (with the same normal offset) from `s`, the projection of `p`.
pub fn footprint(
    l: &LightGpu,
    s: &LightSample,
    p: DVec3,
    n: DVec3,
    dpdx: DVec3,
    dpdy: DVec3,
) -> [f64; 4] {
    let size = [f64::from(l.map_size[0]), f64::from(l.map_size[1])];
    let a = sample(l, p + dpdx, n).uv;
    let b = sample(l, p + dpdy, n).uv;
    [
        (a[0] - s.uv[0]) * size[0],
        (a[1] - s.uv[1]) * size[1],
        (b[0] - s.uv[0]) * size[0],
        (b[1] - s.uv[1]) * size[1],
    ]
}

/// `light_linear_to_ndc`.
pub fn linear_to_ndc(l: &LightGpu, d: f64) -> f64 {
    if l.kind == 0 {
        return d;
    }
    let (near, far) = (f64::from(l.near), f64::from(l.far));
    let z = near + d * (far - near);
    far * (z - near) / ((far - near) * z)
}

/// `light_linear_to_z`.
pub fn linear_to_z(l: &LightGpu, d: f64) -> f64 {
    f64::from(l.near) + d * f64::from(l.far - l.near)
}
