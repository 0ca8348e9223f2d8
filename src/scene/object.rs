//! `[[object]]` tables: the shape and the keys it takes, the transform, the colour; the
//! world-space mesh checked for finite, bounded vertices and unit normals.

use std::ops::Range;
use std::path::Path;

use glam::{EulerRot, Mat4, Quat, Vec3};
use toml::Spanned;

use super::ctx::{Ctx, LENGTH_RANGE, ROTATION_LIMIT, fmt_list, fmt_num};
use super::format::{Num, ObjectFile};
use super::{Mesh, Object, mesh, mesh_file};
use crate::error::Result;

/// Largest coordinate of a vertex after its object's transform, in world units (ten times
/// [`super::ctx::COORD_LIMIT`], room for a large object placed far out).
pub const WORLD_LIMIT: f64 = 1e7;

/// Most triangles in one scene: the vertex buffer (84 bytes a triangle) stays near 350 MB, and
/// a scene file of 1 MiB of sphere tables cannot ask for gigabytes.
pub const MAX_TRIANGLES: usize = 1 << 22;

/// The shape-specific keys each shape takes (`translate`, `rotate_degrees`, `scale` and
/// `color` apply to every shape).
pub(super) const SHAPE_KEYS: &[(&str, &[&str])] = &[
    ("plane", &["size"]),
    ("box", &["size"]),
    ("sphere", &["radius"]),
    ("cylinder", &["radius", "height"]),
    ("mesh", &["path"]),
];

pub(super) fn object(ctx: &Ctx, i: usize, o: &ObjectFile) -> Result<Object> {
    let key = |k: &str| format!("object[{i}].{k}");
    let local = shape(ctx, i, o)?;
    let translate = ctx.coord_or(&key("translate"), &o.translate, Vec3::ZERO)?;
    let rot = match &o.rotate_degrees {
        None => Vec3::ZERO,
        Some(r) => ctx.vec3_in(
            &key("rotate_degrees"),
            r,
            (-ROTATION_LIMIT, ROTATION_LIMIT),
            " degrees",
        )?,
    };
    let scale = match &o.scale {
        None => Vec3::ONE,
        Some(s) => {
            let v = num3(ctx, &key("scale"), s, false)?;
            if v.len() == 1 {
                Vec3::splat(v[0])
            } else {
                Vec3::new(v[0], v[1], v[2])
            }
        }
    };
    let rotation = Quat::from_euler(
        EulerRot::ZYX,
        rot.z.to_radians(),
        rot.y.to_radians(),
        rot.x.to_radians(),
    );
    let transform = Mat4::from_scale_rotation_translation(scale, rotation, translate);
    let color = ctx.color_or(&key("color"), &o.color, Vec3::splat(0.8))?;
    let mut mesh = local.transformed(transform);
    let far = mesh
        .positions
        .iter()
        .map(|p| {
            if p.is_finite() {
                f64::from(p.abs().max_element())
            } else {
                f64::INFINITY
            }
        })
        .fold(0.0, f64::max);
    if far > WORLD_LIMIT {
        let at = o.scale.as_ref().map_or(o.shape.span(), |s| s.span());
        return Err(ctx.err(
            Some(at),
            format!(
                "`object[{i}]` reaches {} world units once scaled and moved, beyond ±{}: \
                 lower its `scale`, size or `translate`",
                fmt_num(far),
                fmt_num(WORLD_LIMIT)
            ),
        ));
    }
    let repaired = mesh.repair_normals();
    if repaired > 0 {
        ctx.warn(
            o.scale.as_ref().map(|s| s.span()),
            format!(
                "`object[{i}]`: {repaired} normal(s) degenerate after the transform; replaced by \
                 the faces' normals"
            ),
        );
    }
    Ok(Object { mesh, color })
}

/// The object's own mesh, from the keys its shape takes (any other shape key is an error).
fn shape(ctx: &Ctx, i: usize, o: &ObjectFile) -> Result<Mesh> {
    let key = |k: &str| format!("object[{i}].{k}");
    let at = o.shape.span();
    let name = o.shape.get_ref().as_str();
    let Some((_, allowed)) = SHAPE_KEYS.iter().find(|(s, _)| *s == name) else {
        return Err(ctx.err(
            Some(at),
            format!(
                "`{}` = {name:?}: unknown shape (expected \"plane\", \"box\", \"sphere\", \
                 \"cylinder\" or \"mesh\")",
                key("shape")
            ),
        ));
    };
    if let Some((k, span)) = present(o).into_iter().find(|(k, _)| !allowed.contains(k)) {
        return Err(ctx.err(
            Some(span),
            format!("`{}` does not apply to shape \"{name}\"", key(k)),
        ));
    }
    let (lo, hi) = LENGTH_RANGE;
    let length = |k: &str, v: &Option<Spanned<f64>>| -> Result<f32> {
        ctx.num(&key(k), ctx.required(&key(k), v, at.clone())?, lo, hi)
    };
    let size = |len2_ok| -> Result<Vec<f32>> {
        num3(
            ctx,
            &key("size"),
            ctx.required(&key("size"), &o.size, at.clone())?,
            len2_ok,
        )
    };
    Ok(match name {
        "plane" => match size(true)?.as_slice() {
            [a] => mesh::plane(*a, *a),
            [a, b] => mesh::plane(*a, *b),
            _ => {
                return Err(ctx.err(
                    o.size.as_ref().map(|s| s.span()),
                    format!("`{}` of a plane is `[x, z]` or one number", key("size")),
                ));
            }
        },
        "box" => match size(false)?.as_slice() {
            [a] => mesh::cuboid(Vec3::splat(*a)),
            s => mesh::cuboid(Vec3::new(s[0], s[1], s[2])),
        },
        "sphere" => mesh::sphere(length("radius", &o.radius)?, 48, 24),
        "cylinder" => mesh::cylinder(
            length("radius", &o.radius)?,
            length("height", &o.height)?,
            48,
        ),
        _ => {
            let p = ctx.required(&key("path"), &o.path, at.clone())?;
            let dir = ctx.path.parent().unwrap_or(Path::new("."));
            let loaded = mesh_file::load(&dir.join(p.get_ref()))
                .map_err(|e| ctx.err(Some(p.span()), format!("`{}`: {e}", key("path"))))?;
            if loaded.repaired_normals > 0 {
                ctx.warn(
                    Some(p.span()),
                    format!(
                        "`{}`: {} normal(s) in the file are zero or not finite; replaced by the \
                         faces' normals",
                        key("path"),
                        loaded.repaired_normals
                    ),
                );
            }
            loaded.mesh
        }
    })
}

/// The shape-specific keys written in `o`, with their spans.
fn present(o: &ObjectFile) -> Vec<(&'static str, Range<usize>)> {
    [
        ("size", o.size.as_ref().map(|v| v.span())),
        ("radius", o.radius.as_ref().map(|v| v.span())),
        ("height", o.height.as_ref().map(|v| v.span())),
        ("path", o.path.as_ref().map(|v| v.span())),
    ]
    .into_iter()
    .filter_map(|(k, s)| s.map(|s| (k, s)))
    .collect()
}

/// One length or a list of 1 or 3 (2 for a plane's size), each in [`LENGTH_RANGE`].
fn num3(ctx: &Ctx, key: &str, v: &Spanned<Num>, len2_ok: bool) -> Result<Vec<f32>> {
    let vals = match v.get_ref() {
        Num::One(x) => vec![*x],
        Num::Many(xs) => xs.clone(),
    };
    let (lo, hi) = LENGTH_RANGE;
    let ok_len = matches!(vals.len(), 1 | 3) || (len2_ok && vals.len() == 2);
    if !ok_len
        || vals
            .iter()
            .any(|x| !(x.is_finite() && (lo..=hi).contains(x)))
    {
        let lengths = if len2_ok { "1, 2 or 3" } else { "1 or 3" };
        return Err(ctx.err(
            Some(v.span()),
            format!(
                "`{key}` must be one number or a list of {lengths}, each in [{}, {}], got {}",
                fmt_num(lo),
                fmt_num(hi),
                fmt_list(&vals)
            ),
        ));
    }
    ctx.f32s(key, v.span(), &vals)
}

/// Errors once the objects so far (`object[i]` the last) hold more than [`MAX_TRIANGLES`].
pub(super) fn check_triangles(ctx: &Ctx, i: usize, o: &ObjectFile, total: usize) -> Result<()> {
    if total > MAX_TRIANGLES {
        return Err(ctx.err(
            Some(o.shape.span()),
            format!(
                "the scene holds {total} triangles up to `object[{i}]`, more than {MAX_TRIANGLES}"
            ),
        ));
    }
    Ok(())
}
