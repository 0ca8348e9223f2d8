//! The warning of a blocker search cut by its cap. PCSS and the soft techniques search a
//! square around the receiver, at distance Z from the light, for blockers of the cone toward
//! the light's width, and cap its half-width at `max_search` (shadow-map UV; the soft
//! techniques' fixed-point tables are coded for squares of that size). A blocker at distance
//! Z_b falls in the cone within `½·size·(Z − Z_b)/Z` world units of the receiver's ray, which
//! the map at Z_b spans `width(Z_b)` of (the width of the whole map there). Where the scene's
//! geometry holds a blocker nearer the light, and a receiver farther from it, than the cap
//! covers, blockers past the cut are missed: shadows thin out and end early. Such a scene is
//! told so, with the cap that would cover it (the nearest and farthest vertices bound both).

use super::Object;
use super::ctx::Ctx;
use super::format::LightFile;
use crate::model::{Light, LightKind};

/// The largest `max_search` a scene may set.
const MAX_SEARCH: f32 = 1.0;

/// Warns, for light `i`, where its blocker search's cap cuts the search of receivers among
/// `objects` (their farthest vertex from the light, within its depth range).
pub(super) fn check(ctx: &Ctx, i: usize, file: &LightFile, light: &Light, objects: &[Object]) {
    let Some(cap) = light.shadow.technique.max_search() else {
        return;
    };
    if light.size <= 0.0 {
        return;
    }
    let Some((z_b, z)) = depth_range(light, objects) else {
        return;
    };
    let width = |z: f32| match light.kind {
        LightKind::Directional { .. } => light.width_at_unit(),
        _ => light.width_at_unit() * z,
    };
    let needed = 0.5 * light.size * (z - z_b) / z / width(z_b);
    if needed <= cap {
        return;
    }
    // Rounded up, so that the cap named covers it.
    let cover = if needed <= MAX_SEARCH {
        format!(
            "`max_search` = {} covers it",
            (needed * 1000.0).ceil() / 1000.0
        )
    } else {
        format!(
            "no `max_search` up to {MAX_SEARCH} covers it: a smaller `size` or a wider map does"
        )
    };
    ctx.warn(
        file.size.as_ref().map(|s| s.span()),
        format!(
            "light[{i}] `{}`: the blocker search's cap (`max_search` = {cap:.3}) cuts the \
             search of a receiver {z:.3} from the light for blockers {z_b:.3} from it (the \
             scene's farthest and nearest vertices): blockers past the cut are missed; {cover}",
            light.shadow.technique.name(),
        ),
    );
}

/// The distances from the light, along its axis (a point light's faces: the largest of the
/// three axes), of the object vertices nearest to and farthest from it within `[near, far]`;
/// `None` when none lies past `near` or they are all at one distance.
fn depth_range(light: &Light, objects: &[Object]) -> Option<(f32, f32)> {
    let dir = light.direction();
    let (lo, hi) = objects
        .iter()
        .flat_map(|o| o.mesh.positions.iter())
        .map(|&p| {
            let d = p - light.position;
            match light.kind {
                LightKind::Point => d.abs().max_element(),
                _ => d.dot(dir),
            }
        })
        .filter(|z| (light.near..=light.far).contains(z))
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), z| {
            (lo.min(z), hi.max(z))
        });
    (lo < hi).then_some((lo, hi))
}
