//! A scene's `[animation]`: over `frames` frames, tracks move a light's position or target,
//! the camera's position or target, or an object's translation, by linear interpolation
//! between keyframes (docs/SCENES.md). [`Scene::at_frame`] gives the scene of one frame.

use glam::Vec3;

use super::ctx::{Ctx, fmt_num};
use super::format::{AnimationFile, ObjectFile, TrackFile};
use super::object::WORLD_LIMIT;
use super::{Object, Scene};
use crate::error::{Error, Result};
use crate::model::{Camera, Light};

/// Most frames an animation may have.
pub const MAX_ANIMATION_FRAMES: i64 = 10_000;

/// A scene's animation: `frames` frames, numbered from 0, and what moves.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Frames F (at least 1).
    pub frames: u32,
    /// The tracks, each moving one value.
    pub tracks: Vec<Track>,
}

/// What a track moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Animated {
    /// `light[i].position`.
    LightPosition(usize),
    /// `light[i].target` (its direction).
    LightTarget(usize),
    /// `camera.position`.
    CameraPosition,
    /// `camera.target`.
    CameraTarget,
    /// `object[i].translate`: the object moves by the track's value less `base`, its
    /// translation in the file.
    ObjectTranslate {
        /// The object.
        object: usize,
        /// Its `translate` in the file (zero when absent).
        base: Vec3,
    },
}

/// One animated value: keyframes `(frame, value)` in increasing frame order, interpolated
/// linearly between them and held before the first and after the last.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// What it moves.
    pub animated: Animated,
    /// The keyframes.
    pub keys: Vec<(u32, Vec3)>,
}

impl Track {
    /// The value at `frame` (interpolated in f64).
    pub fn value(&self, frame: u32) -> Vec3 {
        let Some(&(first, v0)) = self.keys.first() else {
            return Vec3::ZERO;
        };
        if frame <= first {
            return v0;
        }
        for w in self.keys.windows(2) {
            let ((f0, a), (f1, b)) = (w[0], w[1]);
            if frame <= f1 {
                let t = f64::from(frame - f0) / f64::from(f1 - f0);
                return (a.as_dvec3() + (b.as_dvec3() - a.as_dvec3()) * t).as_vec3();
            }
        }
        self.keys.last().map_or(v0, |k| k.1)
    }
}

impl Animation {
    /// `scene` (whose animation this is) at `frame`: every track's value set.
    fn apply(&self, scene: &Scene, frame: u32) -> Scene {
        let mut s = scene.clone();
        for t in &self.tracks {
            let v = t.value(frame);
            match t.animated {
                Animated::LightPosition(i) => s.lights[i].position = v,
                Animated::LightTarget(i) => s.lights[i].target = v,
                Animated::CameraPosition => s.camera.position = v,
                Animated::CameraTarget => s.camera.target = v,
                Animated::ObjectTranslate { object, base } => {
                    let by = v - base;
                    for p in &mut s.objects[object].mesh.positions {
                        *p += by;
                    }
                }
            }
        }
        s
    }
}

impl Scene {
    /// Frames of the scene's animation (1 without one).
    pub fn frames(&self) -> u32 {
        self.animation.as_ref().map_or(1, |a| a.frames)
    }

    /// The scene at frame `frame` of its animation (below [`Scene::frames`]; frame 0 of a
    /// scene without one is the scene itself).
    pub fn at_frame(&self, frame: u32) -> Result<Scene> {
        if frame >= self.frames() {
            return Err(Error::Scene {
                path: self.path.clone(),
                location: self.locations.get("animation.frames"),
                message: format!(
                    "frame {frame} is past the last of the scene's {} frame(s) (`animation.frames`)",
                    self.frames()
                ),
            });
        }
        Ok(match &self.animation {
            Some(a) => a.apply(self, frame),
            None => self.clone(),
        })
    }
}

/// The validated `[animation]` of a scene with `lights`, `camera` and the objects of `files`.
pub(super) fn animation(
    ctx: &Ctx,
    file: &AnimationFile,
    lights: &[Light],
    camera: &Camera,
    files: &[ObjectFile],
    objects: &[Object],
) -> Result<Animation> {
    let frames = ctx.int("animation.frames", &file.frames, 1, MAX_ANIMATION_FRAMES)?;
    let tracks = file
        .tracks
        .iter()
        .enumerate()
        .map(|(k, t)| track(ctx, k, t, frames, lights.len(), files))
        .collect::<Result<Vec<_>>>()?;
    let a = Animation { frames, tracks };
    check_frames(ctx, file, &a, lights, camera)?;
    check_reach(ctx, file, &a, objects)?;
    Ok(a)
}

/// Track `k`: what it moves (`animate`) and its keyframes, in order, inside the frames.
fn track(
    ctx: &Ctx,
    k: usize,
    t: &TrackFile,
    frames: u32,
    lights: usize,
    files: &[ObjectFile],
) -> Result<Track> {
    let at = format!("animation.track[{k}]");
    let animated = animated(ctx, &at, t, lights, files)?;
    if t.keys.get_ref().is_empty() {
        return Err(ctx.err(
            Some(t.keys.span()),
            format!("`{at}.keys` is empty: give at least one keyframe"),
        ));
    }
    let mut keys: Vec<(u32, Vec3)> = Vec::new();
    for (j, key) in t.keys.get_ref().iter().enumerate() {
        let name = format!("{at}.keys[{j}]");
        let last = i64::from(frames) - 1;
        let f = ctx.int(&format!("{name}.frame"), &key.frame, 0, last)?;
        if let Some(&(prev, _)) = keys.last()
            && f <= prev
        {
            return Err(ctx.err(
                Some(key.frame.span()),
                format!("`{name}.frame` = {f} does not follow the previous keyframe's {prev}"),
            ));
        }
        keys.push((f, ctx.coord(&format!("{name}.value"), &key.value)?));
    }
    Ok(Track { animated, keys })
}

/// What track `at` animates: `light[i].position`, `light[i].target`, `camera.position`,
/// `camera.target` or `object[i].translate`.
fn animated(
    ctx: &Ctx,
    at: &str,
    t: &TrackFile,
    lights: usize,
    files: &[ObjectFile],
) -> Result<Animated> {
    let what = t.animate.get_ref().as_str();
    let err = |why: String| {
        ctx.err(
            Some(t.animate.span()),
            format!("`{at}.animate` = {what:?}: {why}"),
        )
    };
    let indexed = |prefix: &str, count: usize| -> Result<Option<(usize, &str)>> {
        let Some(rest) = what.strip_prefix(prefix) else {
            return Ok(None);
        };
        let (index, field) = rest
            .split_once("].")
            .ok_or_else(|| err("expected `[i].` after it".into()))?;
        let i: usize = index
            .parse()
            .map_err(|_| err(format!("`{index}` is not an index")))?;
        if i >= count {
            return Err(err(format!(
                "the scene has {count} {}",
                prefix.trim_end_matches('[')
            )));
        }
        Ok(Some((i, field)))
    };
    let unknown = || {
        err("expected `light[i].position`, `light[i].target`, `camera.position`, `camera.target` or `object[i].translate`".into())
    };
    if let Some((i, field)) = indexed("light[", lights)? {
        return match field {
            "position" => Ok(Animated::LightPosition(i)),
            "target" => Ok(Animated::LightTarget(i)),
            _ => Err(unknown()),
        };
    }
    if let Some((object, field)) = indexed("object[", files.len())? {
        if field != "translate" {
            return Err(unknown());
        }
        let key = format!("object[{object}].translate");
        let base = ctx.coord_or(&key, &files[object].translate, Vec3::ZERO)?;
        return Ok(Animated::ObjectTranslate { object, base });
    }
    match what {
        "camera.position" => Ok(Animated::CameraPosition),
        "camera.target" => Ok(Animated::CameraTarget),
        _ => Err(unknown()),
    }
}

/// Every frame's lights and camera must stay valid (a target off its position, a view not
/// along `camera.up`): interpolation between valid keyframes may pass through either. Named
/// with the first track that moves the value.
fn check_frames(
    ctx: &Ctx,
    file: &AnimationFile,
    a: &Animation,
    lights: &[Light],
    camera: &Camera,
) -> Result<()> {
    let span_of = |pred: &dyn Fn(Animated) -> bool| {
        a.tracks
            .iter()
            .position(|t| pred(t.animated))
            .map(|k| file.tracks[k].animate.span())
    };
    for f in 0..a.frames {
        for (i, l) in lights.iter().enumerate() {
            let (mut p, mut t) = (l.position, l.target);
            for tr in &a.tracks {
                match tr.animated {
                    Animated::LightPosition(j) if j == i => p = tr.value(f),
                    Animated::LightTarget(j) if j == i => t = tr.value(f),
                    _ => {}
                }
            }
            if (t - p).length() < 1e-6 {
                let span = span_of(
                    &|x| matches!(x, Animated::LightPosition(j) | Animated::LightTarget(j) if j == i),
                );
                return Err(ctx.err(
                    span,
                    format!("frame {f} puts `light[{i}].target` on its position"),
                ));
            }
        }
        let (mut p, mut t) = (camera.position, camera.target);
        for tr in &a.tracks {
            match tr.animated {
                Animated::CameraPosition => p = tr.value(f),
                Animated::CameraTarget => t = tr.value(f),
                _ => {}
            }
        }
        let forward = (t - p).as_dvec3();
        let bad = forward.length() < 1e-6
            || forward.normalize().cross(camera.up.as_dvec3()).length() < 1e-4;
        if bad {
            let span = span_of(&|x| matches!(x, Animated::CameraPosition | Animated::CameraTarget));
            return Err(ctx.err(
                span,
                format!(
                    "frame {f} points the camera along `camera.up` or puts its target on its position ({} from it)",
                    fmt_num(forward.length())
                ),
            ));
        }
    }
    Ok(())
}

/// A moved object must stay within [`WORLD_LIMIT`] at every keyframe (between them it lies
/// between its keyframes' places).
fn check_reach(ctx: &Ctx, file: &AnimationFile, a: &Animation, objects: &[Object]) -> Result<()> {
    for (k, t) in a.tracks.iter().enumerate() {
        let Animated::ObjectTranslate { object, base } = t.animated else {
            continue;
        };
        let positions = &objects[object].mesh.positions;
        for (j, &(_, v)) in t.keys.iter().enumerate() {
            let by = (v - base).as_dvec3();
            let far = positions
                .iter()
                .map(|p| (p.as_dvec3() + by).abs().max_element())
                .fold(0.0, f64::max);
            if far > WORLD_LIMIT {
                return Err(ctx.err(
                    Some(file.tracks[k].keys.get_ref()[j].value.span()),
                    format!(
                        "`animation.track[{k}].keys[{j}].value` moves `object[{object}]` to {} \
                         world units, beyond ±{}",
                        fmt_num(far),
                        fmt_num(WORLD_LIMIT)
                    ),
                ));
            }
        }
    }
    Ok(())
}
