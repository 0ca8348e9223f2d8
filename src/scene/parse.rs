//! Turns the spanned TOML (`format`) into the validated model, naming key and line on errors:
//! the file, `[output]`, `[camera]` and each `[[light]]` (its `[light.shadow]` in `validate`,
//! objects in `object`).

use std::path::Path;

use glam::Vec3;

use super::ctx::{Ctx, LENGTH_RANGE, fmt_num};
use super::format::{LightFile, SceneFile, ShadowFile};
use super::locate::{self, Locations};
use super::search_cap;
use super::{Scene, animation, object, update, validate};
use crate::error::Result;
use crate::model::{Camera, Light, LightKind, Shadow, Technique};

/// Largest output or shadow-map side accepted before the device is even asked.
pub(super) const MAX_SIDE: i64 = 1 << 16;

pub(super) fn parse(path: &Path, text: &str) -> Result<Scene> {
    let ctx = Ctx {
        path,
        text,
        warnings: Default::default(),
    };
    let locations = Locations::of(text);
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        // A key missing from the top level comes with an empty span at 0: the whole file.
        let whole =
            e.message().starts_with("missing field") && e.span().is_none_or(|s| s.is_empty());
        let span = e.span().filter(|_| !whole);
        let key = span.as_ref().and_then(|s| locations.key_at(s));
        if e.message().trim() == "duplicate key" {
            // Refused before any tree is built: the key is read from the text at its span.
            let written = span.as_ref().and_then(|s| locate::written_key(text, s));
            if let Some(k) = written {
                return ctx.err(span, format!("duplicate key `{k}`: written twice"));
            }
        }
        ctx.err(span, locate::rewrite(e.message(), key))
    })?;
    let width = ctx.int("output.width", &file.output.width, 1, MAX_SIDE)?;
    let height = ctx.int("output.height", &file.output.height, 1, MAX_SIDE)?;
    let background = ctx.color_or(
        "output.background",
        &file.output.background,
        Vec3::new(0.55, 0.62, 0.72),
    )?;
    let ambient = ctx.color_or("ambient", &file.ambient, Vec3::splat(0.12))?;
    let camera = camera(&ctx, &file)?;
    if file.lights.is_empty() {
        return Err(ctx.err(None, "the scene has no `[[light]]`"));
    }
    let lights = file
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| light(&ctx, i, l))
        .collect::<Result<Vec<_>>>()?;
    let mut objects = Vec::with_capacity(file.objects.len());
    let mut triangles = 0;
    for (i, o) in file.objects.iter().enumerate() {
        let object = object::object(&ctx, i, o)?;
        triangles += object.mesh.indices.len() / 3;
        object::check_triangles(&ctx, i, o, triangles)?;
        objects.push(object);
    }
    if objects.is_empty() {
        return Err(ctx.err(None, "the scene has no `[[object]]`"));
    }
    for (i, (file, light)) in file.lights.iter().zip(&lights).enumerate() {
        search_cap::check(&ctx, i, file, light, &objects);
    }
    let updates = file
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| update::update_rate(&ctx, i, &l.update))
        .collect::<Result<Vec<_>>>()?;
    let animation = file
        .animation
        .as_ref()
        .map(|a| animation::animation(&ctx, a, &lights, &camera, &file.objects, &objects))
        .transpose()?;
    Ok(Scene {
        path: path.to_path_buf(),
        width,
        height,
        background,
        ambient,
        camera,
        lights,
        objects,
        warnings: ctx.warnings.into_inner(),
        locations,
        updates,
        animation,
    })
}

fn camera(ctx: &Ctx, file: &SceneFile) -> Result<Camera> {
    let c = &file.camera;
    let position = ctx.coord("camera.position", &c.position)?;
    let target = ctx.coord("camera.target", &c.target)?;
    let up = ctx.coord_or("camera.up", &c.up, Vec3::Y)?;
    let fov_y_degrees = ctx.num("camera.fov_y_degrees", &c.fov_y_degrees, 1.0, 170.0)?;
    let forward = target - position;
    if forward.length() < 1e-6 {
        return Err(ctx.err(
            Some(c.target.span()),
            "`camera.target` equals `camera.position`",
        ));
    }
    if forward.normalize().cross(up).length() < 1e-4 {
        // Without an `up` key (default +Y), the target sets the view direction: point there.
        let span = c.up.as_ref().map_or(c.target.span(), |u| u.span());
        return Err(ctx.err(Some(span), "`camera.up` is parallel to the view direction"));
    }
    Ok(Camera {
        position,
        target,
        up,
        fov_y_degrees,
    })
}

fn light(ctx: &Ctx, i: usize, l: &LightFile) -> Result<Light> {
    let key = |k: &str| format!("light[{i}].{k}");
    let kind = match l.kind.get_ref().as_str() {
        "directional" => {
            ctx.reject(
                &key("fov_degrees"),
                &l.fov_degrees,
                "applies to spot lights only",
            )?;
            let e = ctx.required(&key("extent"), &l.extent, l.kind.span())?;
            LightKind::Directional {
                extent: ctx.num(&key("extent"), e, 1e-3, 1e6)?,
            }
        }
        "spot" => {
            ctx.reject(
                &key("extent"),
                &l.extent,
                "applies to directional lights only",
            )?;
            let f = ctx.required(&key("fov_degrees"), &l.fov_degrees, l.kind.span())?;
            LightKind::Spot {
                fov_degrees: ctx.num(&key("fov_degrees"), f, 1.0, 170.0)?,
            }
        }
        "point" => {
            ctx.reject(
                &key("extent"),
                &l.extent,
                "applies to directional lights only",
            )?;
            ctx.reject(
                &key("fov_degrees"),
                &l.fov_degrees,
                "applies to spot lights only",
            )?;
            LightKind::Point
        }
        other => {
            return Err(ctx.err(
                Some(l.kind.span()),
                format!(
                    "`{}` = {other:?}: unknown light kind (expected \"directional\", \"spot\" or \"point\")",
                    key("kind")
                ),
            ));
        }
    };
    let position = ctx.coord(&key("position"), &l.position)?;
    let target = match (&l.target, kind) {
        // A point light lights every direction: its target only orients its emitter's frame.
        (None, LightKind::Point) => position - Vec3::Y,
        (None, _) => {
            return Err(ctx.err(
                Some(l.kind.span()),
                format!(
                    "`{}` is required for a {} light",
                    key("target"),
                    l.kind.get_ref()
                ),
            ));
        }
        (Some(t), _) => {
            let target = ctx.coord(&key("target"), t)?;
            if (target - position).length() < 1e-6 {
                return Err(ctx.err(
                    Some(t.span()),
                    format!("`{}` equals its position", key("target")),
                ));
            }
            target
        }
    };
    let near = ctx.num_or(&key("near"), &l.near, 1e-6, 1e7, 0.1)?;
    let far = ctx.num_or(&key("far"), &l.far, 1e-6, 1e7, 50.0)?;
    if far <= near {
        let span = l.far.as_ref().or(l.near.as_ref()).map(|s| s.span());
        return Err(ctx.err(
            span,
            format!(
                "`{}` ({far}) must exceed `{}` ({near})",
                key("far"),
                key("near")
            ),
        ));
    }
    let size = ctx.num_or(&key("size"), &l.size, 0.0, LENGTH_RANGE.1, 0.0)?;
    let color = ctx.color_or(&key("color"), &l.color, Vec3::ONE)?;
    let intensity = ctx.num_or(&key("intensity"), &l.intensity, 0.0, 1e6, 1.0)?;
    let shadow_map = ctx.int_or(&key("shadow_map"), &l.shadow_map, 1, MAX_SIDE, 1024)?;
    if let Some(s) = &l.shadow {
        directional_keys(ctx, i, s, kind)?;
    }
    let shadow = match &l.shadow {
        Some(s) => validate::shadow(ctx, i, s)?,
        None => Shadow {
            technique: Technique::Hard,
            bias: 0.002,
            slope_bias: 1.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: crate::model::Cascades::SINGLE,
        },
    };
    if kind == LightKind::Point {
        point_support(ctx, i, l, &shadow, shadow_map)?;
    }
    if crate::technique::of(&shadow.technique).area_light && size <= 0.0 {
        let span = l.size.as_ref().map(|s| s.span()).or(Some(l.kind.span()));
        return Err(ctx.err(
            span,
            format!(
                "technique \"{}\" needs `{}` > 0 (the area light's width)",
                shadow.technique.name(),
                key("size")
            ),
        ));
    }
    if let Some(soft) = shadow.technique.soft() {
        let area = crate::technique::soft_lookup_area(soft.max_search, shadow_map);
        if soft.sums == crate::model::SatVariant::Fixed && area > crate::sat::MAX_FIXED_AREA {
            let span = l
                .shadow
                .as_ref()
                .and_then(|s| s.max_search.as_ref())
                .map(|v| v.span());
            return Err(ctx.err(
                span.or(l.shadow_map.as_ref().map(|v| v.span())),
                format!(
                    "`{}` = {} on a {shadow_map}² map reads squares of {area} texels, more than a \
                     fixed-point table can sum; lower it or set `sat_sums = \"float\"`",
                    key("shadow.max_search"),
                    fmt_num(f64::from(soft.max_search))
                ),
            ));
        }
    }
    let light = Light {
        kind,
        position,
        target,
        near,
        far,
        size,
        radiance: color * intensity,
        shadow_map,
        shadow,
    };
    if light.shadow.cascades.count > 1 {
        cascade_band(ctx, i, l, &light)?;
    }
    Ok(light)
}

/// A cascaded light's guard band (`technique::cascade_guard`: PCSS and the soft techniques) must
/// leave at least half of each cascade's map, as a point light's faces must; named with the
/// line of `normal_bias` (most of a wide band's texels) or of the technique.
fn cascade_band(ctx: &Ctx, i: usize, l: &LightFile, light: &Light) -> Result<()> {
    let guard = crate::technique::cascade_guard(light);
    let map = light.shadow_map as f32;
    if 4.0 * guard.texels <= map {
        return Ok(());
    }
    let file = l.shadow.as_ref();
    let span = file
        .and_then(|s| s.normal_bias.as_ref())
        .map(|v| v.span())
        .or(file.map(|s| s.technique.span()))
        .or(l.shadow_map.as_ref().map(|v| v.span()));
    Err(ctx.err(
        span,
        format!(
            "`light[{i}].shadow`: cascades of technique \"{}\" need a guard band of {} texels (the lookups' reach past a radius and `normal_bias`), which leaves less than half of a {}² cascade: raise `shadow_map` to at least {} or lower `normal_bias`",
            light.shadow.technique.name(),
            guard.texels,
            light.shadow_map,
            (4.0 * guard.texels).ceil()
        ),
    ))
}

/// The cascade keys (`params::CASCADES`) apply to directional lights only: on a spot or a
/// point light any of them, even `cascades = 1`, is refused as `extent` is, naming its line.
fn directional_keys(ctx: &Ctx, i: usize, s: &ShadowFile, kind: LightKind) -> Result<()> {
    let why = match kind {
        LightKind::Directional { .. } => return Ok(()),
        LightKind::Spot { .. } => "cascades split a sun's view range, a spot light has one frustum",
        LightKind::Point => {
            "cascades split a sun's view range, a point light's six faces cover every direction"
        }
    };
    let keys = crate::technique::params::CASCADES.iter().map(|p| p.key);
    match keys
        .filter_map(|k| validate::written(s, k).map(|span| (k, span)))
        .next()
    {
        Some((k, span)) => Err(ctx.err(
            Some(span),
            format!("`light[{i}].shadow.{k}` applies to directional lights only: {why}"),
        )),
        None => Ok(()),
    }
}

/// What a point light's six faces refuse: techniques whose reach no guard band bounds
/// (`technique::reach`), naming the technique's line.
fn point_support(ctx: &Ctx, i: usize, l: &LightFile, shadow: &Shadow, face: u32) -> Result<()> {
    let key = |k: &str| format!("light[{i}].{k}");
    let file = l.shadow.as_ref();
    let reach = crate::technique::reach(&shadow.technique, face);
    if let Err(why) = reach.and_then(|r| crate::model::point::PointLayout::new(face, r)) {
        let span = file
            .map(|s| s.technique.span())
            .or(l.shadow_map.as_ref().map(|v| v.span()));
        return Err(ctx.err(span, format!("`{}`: {why}", key("shadow"))));
    }
    Ok(())
}
