//! The sweep: which configurations `shadowgraph evaluate` renders, built as a scene file would
//! build them.

use super::EvaluateOptions;
use crate::error::{Error, Result};
use crate::model::ParamValue;
use crate::prefilter::PrefilterConfig;
use crate::scene::{BlurKernel, Filter, Scene, Storage, Technique};
use crate::technique;

/// A filter of a box `width` texels wide.
pub type FilterOfWidth = fn(f32) -> Filter;

/// The filters prefiltered techniques are swept with: a name and the filter of a box `width`
/// texels wide. Adding a filter (e.g. `filter = "sat"`) is one line here.
pub const FILTERS: &[(&str, FilterOfWidth)] = &[
    ("blur", |width| Filter::Blur {
        radius: 0.5 * (width - 1.0),
        sigma: (0.25 * (width - 1.0)).max(0.5),
        kernel: BlurKernel::Box,
    }),
    ("mips", |width| Filter::Mips {
        width,
        max_anisotropy: 0,
    }),
    ("sat", |width| Filter::Sat {
        width,
        variant: crate::sat::SatVariant::Fixed,
    }),
];

/// One configuration of the sweep: a technique with its knobs on a map size.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Short unique label, e.g. `vsm f16 blur5 1024`.
    pub label: String,
    /// Technique and knobs (every light of the scene gets it).
    pub technique: Technique,
    /// Shadow-map side.
    pub shadow_map: u32,
    /// Width in texels of the box the technique filters with, when it has one (the PCF truth
    /// then applies).
    pub box_width: Option<f64>,
}

/// PCSS tap counts (blocker search, filter) swept beside the scene's own: cheaper, and the
/// wider counts engines ship (Bevy's PCSS, Filament's).
pub const PCSS_TAPS: [(u32, u32); 4] = [(8, 16), (16, 32), (32, 64), (64, 64)];

/// Configurations of the sweep for `scene` (every light gets each), filtered by
/// `opts.techniques`. Unknown technique names are an error listing the known ones.
pub fn sweep(scene: &Scene, opts: &EvaluateOptions) -> Result<Vec<Config>> {
    let known = crate::technique::names();
    let wanted: Vec<String> = match &opts.techniques {
        None => known.iter().map(|s| s.to_string()).collect(),
        Some(list) => {
            for t in list {
                if !known.contains(&t.as_str()) {
                    return Err(Error::Invalid(format!(
                        "unknown technique `{t}` in --techniques (known: {})",
                        known.join(", ")
                    )));
                }
            }
            list.clone()
        }
    };
    let quick = opts.quick;
    let sizes = opts.sizes.clone().unwrap_or_else(|| {
        if quick {
            vec![512]
        } else {
            vec![512, 1024, 2048, 4096]
        }
    });
    if sizes.is_empty() || sizes.iter().any(|&s| !(1..=65536).contains(&s)) {
        return Err(Error::Invalid(format!(
            "--sizes must be map sides in [1, 65536], got {sizes:?}"
        )));
    }
    let base = if sizes.contains(&1024) {
        1024
    } else {
        sizes[0]
    };
    let widths: &[f32] = if quick { &[5.0] } else { &[3.0, 5.0, 9.0] };
    let storages: &[Storage] = if quick {
        &[Storage::F32]
    } else {
        &[Storage::F32, Storage::F16]
    };
    let mut out = Vec::new();
    let mut push = |label: String, technique: Technique, size: u32, box_width: Option<f64>| {
        out.push(Config {
            label: format!("{label} {size}"),
            technique,
            shadow_map: size,
            box_width,
        });
    };
    let size_sweep = |t: &str| -> Vec<u32> {
        if wanted.iter().any(|w| w == t) {
            sizes.clone()
        } else {
            Vec::new()
        }
    };
    let named = |name: &str, values: &[(&'static str, ParamValue)]| {
        technique::named(name, values)
            .ok_or_else(|| Error::Invalid(format!("sweep: cannot build technique `{name}`")))
    };
    for &size in &size_sweep("hard") {
        push("hard".into(), named("hard", &[])?, size, None);
    }
    if wanted.iter().any(|w| w == "pcf") {
        for r in if quick { vec![2] } else { vec![1, 2, 4] } {
            // The default kernel (box) at radius r.
            let t = named("pcf", &[("radius", ParamValue::Int(r))])?;
            let width = Some(f64::from(2 * r + 1));
            let on: Vec<u32> = if r == 2 { sizes.clone() } else { vec![base] };
            for size in on {
                push(format!("pcf box{}", 2 * r + 1), t, size, width);
            }
        }
    }
    if scene.lights.iter().all(|l| l.size > 0.0) {
        let pcss = match scene
            .lights
            .iter()
            .map(|l| l.shadow.technique)
            .find(|t| t.name() == "pcss")
        {
            Some(t) => t,
            None => named("pcss", &[])?,
        };
        // PCSS as engines ship it, at several tap counts (blocker search + filter): the
        // scene's (default 16 + 32) on every size, the others at the base size.
        let pcss_label = |t: &Technique| {
            let v = (technique::of(t).values)(t);
            let (blockers, taps) = (v.int("blocker_samples"), v.int("filter_samples"));
            format!("pcss {blockers}+{taps}")
        };
        for &size in &size_sweep("pcss") {
            push(pcss_label(&pcss), pcss, size, None);
        }
        if !quick && wanted.iter().any(|w| w == "pcss") {
            for (blocker_samples, filter_samples) in PCSS_TAPS {
                let taps = [
                    ("blocker_samples", ParamValue::Int(blocker_samples)),
                    ("filter_samples", ParamValue::Int(filter_samples)),
                ];
                let Some(t) = technique::with_values(&pcss, &taps) else {
                    continue;
                };
                if t != pcss {
                    push(pcss_label(&t), t, base, None);
                }
            }
        }
        // The soft techniques (every step a summed-area-table lookup), validated as a scene
        // would be; their first variant on every size, the others at the base size.
        let light_size = scene.lights[0].size;
        for name in ["cssm", "vssm", "msm_soft"] {
            if !wanted.iter().any(|w| w == name) {
                continue;
            }
            let variants: Vec<(String, PrefilterConfig)> = match name {
                "cssm" => (if quick { vec![8] } else { vec![8, 4, 16] })
                    .into_iter()
                    .map(|m| {
                        (
                            format!("cssm M{m}"),
                            PrefilterConfig::cssm(1, m, light_size),
                        )
                    })
                    .collect(),
                "vssm" => vec![("vssm".into(), PrefilterConfig::vssm(1, light_size))],
                _ => {
                    let mut v = vec![(
                        "msm_soft f32".to_string(),
                        PrefilterConfig::msm_soft(1, light_size),
                    )];
                    if !quick {
                        v.push((
                            "msm_soft f16".into(),
                            PrefilterConfig::msm_soft(1, light_size).with_storage(Storage::F16),
                        ));
                    }
                    v
                }
            };
            for (k, (label, config)) in variants.into_iter().enumerate() {
                let (valid, _) = config.validated()?;
                let on = if k == 0 { sizes.clone() } else { vec![base] };
                for size in on {
                    push(label.clone(), valid.technique, size, None);
                }
            }
        }
    }
    for name in ["vsm", "evsm2", "evsm4", "esm", "msm", "csm"] {
        if wanted.iter().any(|w| w == name) {
            prefiltered_configs(name, quick, base, &sizes, widths, storages, &mut out)?;
        }
    }
    match &opts.moment_biases {
        Some(biases) => with_moment_biases(out, biases),
        None => Ok(out),
    }
}

/// Every `msm` and `msm_soft` configuration once per moment bias in `biases` (label suffix
/// `bias<α>`), instead of at its storage's default; the others as they are. Each bias is
/// checked against the scene key's range.
fn with_moment_biases(configs: Vec<Config>, biases: &[f32]) -> Result<Vec<Config>> {
    if let Some(a) = biases.iter().find(|a| !(0.0..=0.5).contains(*a)) {
        return Err(Error::Invalid(format!(
            "--moment-bias: {a} is outside [0, 0.5]"
        )));
    }
    let mut out = Vec::new();
    for c in configs {
        if technique::of(&c.technique)
            .params
            .iter()
            .all(|t| t.iter().all(|s| s.key != "moment_bias"))
        {
            out.push(c);
            continue;
        }
        for &a in biases {
            let bias = [("moment_bias", ParamValue::Float(a))];
            let technique = technique::with_values(&c.technique, &bias).unwrap_or(c.technique);
            out.push(Config {
                label: format!("{} bias{a:e}", c.label),
                technique,
                ..c.clone()
            });
        }
    }
    Ok(out)
}

/// The prefiltered technique `name` with `storage`, `filter` and (CSM) `terms`, validated
/// like a scene file (EVSM exponents clamped to the storage's limit, MSM's default bias for
/// the storage: `PrefilterConfig::with_storage`).
fn prefiltered(name: &str, storage: Storage, filter: Filter, terms: u32) -> Result<Technique> {
    let terms = [("terms", ParamValue::Int(terms))];
    let values: &[(&str, ParamValue)] = if name == "csm" { &terms } else { &[] };
    let t = technique::named(name, values)
        .ok_or_else(|| Error::Invalid(format!("sweep: cannot build technique `{name}`")))?;
    let config = PrefilterConfig::new(t, 1);
    let config = if name == "esm" {
        config.with_filter(filter)
    } else {
        config.with_storage(storage).with_filter(filter)
    };
    let (valid, _) = config.validated()?;
    Ok(valid.technique)
}

pub(super) fn storage_name(s: Storage) -> &'static str {
    match s {
        Storage::F32 => "f32",
        Storage::F16 => "f16",
        Storage::Unorm16 => "unorm16",
    }
}

fn prefiltered_configs(
    name: &str,
    quick: bool,
    base: u32,
    sizes: &[u32],
    widths: &[f32],
    storages: &[Storage],
    out: &mut Vec<Config>,
) -> Result<()> {
    let mut push = |label: String, t: Technique, size: u32, width: f32| {
        out.push(Config {
            label: format!("{label} {size}"),
            technique: t,
            shadow_map: size,
            box_width: Some(f64::from(width)),
        });
    };
    let mid = widths[widths.len() / 2];
    // CSM: the knobs are swept at M = 8 (4 when quick); the other M with the first filter.
    let (default_m, other_m): (u32, &[u32]) = match (name, quick) {
        ("csm", true) => (4, &[]),
        ("csm", false) => (8, &[2, 4, 16]),
        _ => (0, &[]),
    };
    let prefix = |m: u32| {
        if m > 0 {
            format!("{name} M{m}")
        } else {
            name.to_string()
        }
    };
    let mut storages = storages.to_vec();
    if name == "esm" {
        storages = vec![Storage::F32];
    } else if name == "msm" && !quick {
        storages.push(Storage::Unorm16);
    }
    for &storage in &storages {
        for (fname, filter) in FILTERS {
            // Widths are swept for f32; other storages at the middle width.
            let ws: &[f32] = if storage == Storage::F32 {
                widths
            } else {
                &[mid]
            };
            for &w in ws {
                let t = prefiltered(name, storage, filter(w), default_m)?;
                let label = format!("{} {} {fname}{w}", prefix(default_m), storage_name(storage));
                push(label, t, base, w);
            }
        }
    }
    let (fname, filter) = FILTERS[0];
    for &m in other_m {
        for &storage in &storages {
            let t = prefiltered(name, storage, filter(mid), m)?;
            let label = format!("{} {} {fname}{mid}", prefix(m), storage_name(storage));
            push(label, t, base, mid);
        }
    }
    // Map sizes for the default configuration.
    let t = prefiltered(name, Storage::F32, filter(mid), default_m)?;
    for &size in sizes.iter().filter(|&&s| s != base) {
        push(
            format!("{} f32 {fname}{mid}", prefix(default_m)),
            t,
            size,
            mid,
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_on_plane.toml");
        Scene::load(path).expect("sphere_on_plane")
    }

    fn pcss_rows(opts: &EvaluateOptions) -> Vec<(String, u32)> {
        sweep(&scene(), opts)
            .expect("sweep")
            .into_iter()
            .filter(|c| matches!(c.technique, Technique::Pcss { .. }))
            .map(|c| (c.label, c.shadow_map))
            .collect()
    }

    /// PCSS is on the front at the tap counts users pick: the scene's own (16 + 32) on every
    /// size, each other count of `PCSS_TAPS` once at the base size, labelled by its taps.
    #[test]
    fn pcss_is_swept_at_several_tap_counts() {
        let opts = EvaluateOptions {
            techniques: Some(vec!["pcss".into()]),
            sizes: Some(vec![512, 1024]),
            ..Default::default()
        };
        let want: Vec<(String, u32)> = [
            ("pcss 16+32 512", 512),
            ("pcss 16+32 1024", 1024),
            ("pcss 8+16 1024", 1024),
            ("pcss 32+64 1024", 1024),
            ("pcss 64+64 1024", 1024),
        ]
        .into_iter()
        .map(|(l, s)| (l.to_string(), s))
        .collect();
        assert_eq!(pcss_rows(&opts), want);
        let quick = EvaluateOptions {
            quick: true,
            sizes: None,
            ..opts
        };
        assert_eq!(pcss_rows(&quick), [("pcss 16+32 512".to_string(), 512)]);
    }
}
