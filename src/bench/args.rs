//! The command line's arguments checked before any work: sizes and repeats, `--only` filters,
//! and `bench --lookup`'s `--map` and `--image` applied to its scene as set by their flags.

use super::cases::{BenchCase, CASES};
use crate::error::{Error, Result};

/// Refuses an empty entry of an `--only` list (`--only sat,` or `--only ,`): every name
/// contains the empty string, so it would keep everything while the user meant a filter.
pub(crate) fn check_only(flag: &str, only: &[String]) -> Result<()> {
    match only.iter().position(|o| o.trim().is_empty()) {
        Some(i) => Err(Error::Invalid(format!(
            "{flag} {}: entry {} is empty (every name contains it); name part of a kernel or \
             configuration",
            only.join(","),
            i + 1
        ))),
        None => Ok(()),
    }
}

/// The cases of [`CASES`] whose name contains one of `only` (all of them when `only` is
/// empty); a filter that names no case is an error listing the names.
pub fn select_cases(only: &[String]) -> Result<Vec<&'static BenchCase>> {
    check_only("bench --only", only)?;
    let picked: Vec<&BenchCase> = CASES
        .iter()
        .filter(|c| only.is_empty() || only.iter().any(|o| c.name.contains(o.as_str())))
        .collect();
    if picked.is_empty() {
        let names: Vec<&str> = CASES.iter().map(|c| c.name).collect();
        return Err(Error::Invalid(format!(
            "bench --only {}: matches no kernel; the kernels are: {}",
            only.join(","),
            names.join("; ")
        )));
    }
    Ok(picked)
}

/// `bench --lookup`'s `--map` and `--image` against the device's largest texture side: past
/// it an error naming the flag (the bench's own scene file would name a key and a line the
/// user did not write).
pub(super) fn check_map(
    device: &wgpu::Device,
    map: Option<u32>,
    image: Option<(u32, u32)>,
) -> Result<()> {
    crate::limits::flag_sides(
        device.limits().max_texture_dimension_2d,
        [
            ("bench --map (shadow-map side)", map),
            ("bench --image (width)", image.map(|(w, _)| w)),
            ("bench --image (height)", image.map(|(_, h)| h)),
        ],
    )
}

/// `bench --lookup`'s scene with `--image` and `--map` applied, each recorded as set by its flag
/// (`Locations::set_by`), so that a limit or memory error names the flag rather than a line of
/// the bundled scene, which the user did not write.
pub(super) fn with_flags(
    mut scene: crate::scene::Scene,
    map: Option<u32>,
    image: Option<(u32, u32)>,
) -> crate::scene::Scene {
    if let Some((w, h)) = image {
        (scene.width, scene.height) = (w, h);
        let by = format!("bench --lookup --image {w}x{h}");
        scene.locations.set_by("output.width", by.clone());
        scene.locations.set_by("output.height", by);
    }
    if let Some(n) = map {
        for (i, l) in scene.lights.iter_mut().enumerate() {
            l.shadow_map = n;
            let by = format!("bench --lookup --map {n}");
            scene.locations.set_by(format!("light[{i}].shadow_map"), by);
        }
    }
    scene
}

/// The kernel benchmark's sizes (at least one, each 1 to the device's largest texture side) and
/// `repeat` (at least 1), checked before any work; [`run`](super::run) and the `kernel_wall` example share
/// it.
pub fn check_args(device: &wgpu::Device, sizes: &[u32], repeat: u32) -> Result<()> {
    if sizes.is_empty() {
        return Err(Error::Invalid("no benchmark sizes given".into()));
    }
    if repeat == 0 {
        return Err(Error::Invalid("repeat must be at least 1".into()));
    }
    let max = device.limits().max_texture_dimension_2d;
    for &n in sizes {
        if n == 0 {
            return Err(Error::Invalid("benchmark size 0".into()));
        }
        if n > max {
            return Err(Error::Limit {
                what: "benchmark size".into(),
                requested: u64::from(n),
                limit: u64::from(max),
            });
        }
    }
    Ok(())
}
