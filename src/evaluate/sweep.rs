//! The sweep: which configurations `shadowgraph evaluate` renders, built as a scene file would
//! build them.

use super::EvaluateOptions;
use crate::error::{Error, Result};
use crate::model::ParamValue;
use crate::prefilter::PrefilterConfig;
use crate::technique::{self, SweepPlan, SweptStorages, SweptTerms, TechniqueDef};
use crate::{
    model::{BlurKernel, Filter, Storage, Technique},
    scene::Scene,
};

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
        variant: crate::model::SatVariant::Fixed,
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
    let area_lights = scene.lights.iter().all(|l| l.size > 0.0);
    let knobs = Knobs {
        quick,
        base,
        sizes: &sizes,
        widths,
        storages,
        light_size: scene.lights[0].size,
    };
    let mut out = Vec::new();
    for def in technique::REGISTRY {
        if !wanted.iter().any(|w| w == def.name) || (def.area_light && !area_lights) {
            continue;
        }
        let own = scene
            .lights
            .iter()
            .map(|l| l.shadow.technique)
            .find(|t| t.name() == def.name);
        swept(def, own, &knobs, &mut out)?;
    }
    // A point light's faces bound only some techniques' reach (`technique::reach`).
    out.retain(|c| {
        scene
            .lights
            .iter()
            .filter(|l| l.kind == crate::model::LightKind::Point)
            .all(|_| {
                crate::technique::reach(&c.technique, c.shadow_map)
                    .and_then(|r| crate::model::point::PointLayout::new(c.shadow_map, r))
                    .is_ok()
            })
    });
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
    let biased = |def: &technique::TechniqueDef| {
        def.params
            .iter()
            .any(|t| t.iter().any(|s| s.key == "moment_bias"))
    };
    if !configs.iter().any(|c| biased(technique::of(&c.technique))) {
        let takers: Vec<&str> = technique::REGISTRY
            .iter()
            .filter(|d| biased(d))
            .map(|d| d.name)
            .collect();
        return Err(Error::Invalid(format!(
            "--moment-bias: no technique of the sweep has a moment bias (those that do: {})",
            takers.join(", ")
        )));
    }
    let mut out = Vec::new();
    for c in configs {
        if !biased(technique::of(&c.technique)) {
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

/// The evaluation's side of a sweep: what every technique's plan is run over.
struct Knobs<'a> {
    quick: bool,
    /// The map size the knobs are swept at.
    base: u32,
    sizes: &'a [u32],
    /// Box widths of the filtered techniques (texels).
    widths: &'a [f32],
    /// Storages of the prefiltered techniques, f32 first.
    storages: &'a [Storage],
    /// The scene's first light's width (the soft techniques' validation).
    light_size: f32,
}

impl Knobs<'_> {
    /// `label` with `technique` at every map size (`every_size`) or at the base size.
    fn push(&self, out: &mut Vec<Config>, label: &str, t: Technique, every: bool, w: Option<f64>) {
        let base = [self.base];
        for &size in if every { self.sizes } else { &base[..] } {
            out.push(Config {
                label: format!("{label} {size}"),
                technique: t,
                shadow_map: size,
                box_width: w,
            });
        }
    }
}

fn named(name: &str, values: &[(&'static str, ParamValue)]) -> Result<Technique> {
    technique::named(name, values)
        .ok_or_else(|| Error::Invalid(format!("sweep: cannot build technique `{name}`")))
}

/// The configurations of `def`'s sweep plan; `own` is the scene's configuration of it.
fn swept(
    def: &TechniqueDef,
    own: Option<Technique>,
    k: &Knobs,
    out: &mut Vec<Config>,
) -> Result<()> {
    let name = def.name;
    match def.sweep {
        SweepPlan::Defaults => k.push(out, name, named(name, &[])?, true, None),
        SweepPlan::Radii {
            full,
            quick,
            every_size,
        } => {
            for &r in if k.quick { quick } else { full } {
                // The default kernel (box) at radius r.
                let t = named(name, &[("radius", ParamValue::Int(r))])?;
                let label = format!("{name} box{}", 2 * r + 1);
                k.push(out, &label, t, r == every_size, Some(f64::from(2 * r + 1)));
            }
        }
        SweepPlan::Taps(taps) => {
            let own = match own {
                Some(t) => t,
                None => named(name, &[])?,
            };
            let label = |t: &Technique| {
                let v = (def.values)(t);
                let (blockers, filter) = (v.int("blocker_samples"), v.int("filter_samples"));
                format!("{name} {blockers}+{filter}")
            };
            k.push(out, &label(&own), own, true, None);
            for &(blocker_samples, filter_samples) in taps.iter().filter(|_| !k.quick) {
                let taps = [
                    ("blocker_samples", ParamValue::Int(blocker_samples)),
                    ("filter_samples", ParamValue::Int(filter_samples)),
                ];
                match technique::with_values(&own, &taps) {
                    Some(t) if t != own => k.push(out, &label(&t), t, false, None),
                    _ => {}
                }
            }
        }
        SweepPlan::Variants { full, quick } => {
            let n = if k.quick { quick } else { full.len() };
            for (i, v) in full.iter().take(n).enumerate() {
                let mut config =
                    PrefilterConfig::new(named(name, v.values)?, 1).with_light_size(k.light_size);
                if let Some(storage) = v.storage {
                    config = config.with_storage(storage);
                }
                let (valid, _) = config.validated()?;
                k.push(out, v.label, valid.technique, i == 0, None);
            }
        }
        SweepPlan::Prefiltered { storages, terms } => prefiltered(name, storages, terms, k, out)?,
    }
    Ok(())
}

/// The prefiltered technique `name` with `storage`, `filter` and (CSM) `terms`, validated
/// like a scene file (EVSM exponents clamped to the storage's limit, MSM's default bias for
/// the storage: `PrefilterConfig::with_storage`); a technique of one storage keeps it.
fn prefiltered_one(
    name: &str,
    storage: Option<Storage>,
    filter: Filter,
    terms: Option<u32>,
) -> Result<Technique> {
    let values = terms.map(|m| ("terms", ParamValue::Int(m)));
    let config = PrefilterConfig::new(named(name, values.as_slice())?, 1);
    let config = match storage {
        Some(s) => config.with_storage(s),
        None => config,
    };
    let (valid, _) = config.with_filter(filter).validated()?;
    Ok(valid.technique)
}

pub(super) fn storage_name(s: Storage) -> &'static str {
    match s {
        Storage::F32 => "f32",
        Storage::F16 => "f16",
        Storage::Unorm16 => "unorm16",
    }
}

/// A prefiltered encoding's configurations: every filter at every width (f32) or at the
/// middle width (other storages) at the base size, CSM's other term counts with the first
/// filter, and the default (f32, first filter, middle width) at every other map size.
fn prefiltered(
    name: &str,
    storages: SweptStorages,
    terms: Option<SweptTerms>,
    k: &Knobs,
    out: &mut Vec<Config>,
) -> Result<()> {
    let mid = k.widths[k.widths.len() / 2];
    let (default_m, other_m): (Option<u32>, &[u32]) = match terms {
        Some(t) if k.quick => (Some(t.quick), &[]),
        Some(t) => (Some(t.full), t.others),
        None => (None, &[]),
    };
    let prefix = |m: Option<u32>| match m {
        Some(m) => format!("{name} M{m}"),
        None => name.to_string(),
    };
    let swept: Vec<Option<Storage>> = match storages {
        SweptStorages::F32Only => vec![None],
        SweptStorages::Standard => k.storages.iter().map(|&s| Some(s)).collect(),
        SweptStorages::WithUnorm16 => {
            let mut v: Vec<Option<Storage>> = k.storages.iter().map(|&s| Some(s)).collect();
            if !k.quick {
                v.push(Some(Storage::Unorm16));
            }
            v
        }
    };
    let label = |m, storage: Option<Storage>, fname: &str, w: f32| {
        let s = storage_name(storage.unwrap_or(Storage::F32));
        format!("{} {s} {fname}{w}", prefix(m))
    };
    for &storage in &swept {
        for (fname, filter) in FILTERS {
            // Widths are swept for f32; other storages at the middle width.
            let f32_storage = storage.is_none_or(|s| s == Storage::F32);
            let ws: &[f32] = if f32_storage { k.widths } else { &[mid] };
            for &w in ws {
                let t = prefiltered_one(name, storage, filter(w), default_m)?;
                // The default configuration runs at every map size.
                let every = f32_storage && *fname == FILTERS[0].0 && w == mid;
                k.push(
                    out,
                    &label(default_m, storage, fname, w),
                    t,
                    every,
                    Some(f64::from(w)),
                );
            }
        }
    }
    let (fname, filter) = FILTERS[0];
    for &m in other_m {
        for &storage in &swept {
            let t = prefiltered_one(name, storage, filter(mid), Some(m))?;
            k.push(
                out,
                &label(Some(m), storage, fname, mid),
                t,
                false,
                Some(f64::from(mid)),
            );
        }
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
            .filter(|c| c.technique.name() == "pcss")
            .map(|c| (c.label, c.shadow_map))
            .collect()
    }

    /// PCSS is on the front at the tap counts users pick: the scene's own (16 + 32) on every
    /// size, each other count of its `SweepPlan::Taps` once at the base size, labelled by its taps.
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

    /// Every registered technique is swept (by its registry entry's plan) on a scene with an
    /// area light, so a new technique reaches the evaluation by naming its plan.
    #[test]
    fn every_registered_technique_is_swept() {
        let opts = EvaluateOptions {
            sizes: Some(vec![512]),
            ..Default::default()
        };
        let configs = sweep(&scene(), &opts).expect("sweep");
        for def in technique::REGISTRY {
            assert!(
                configs.iter().any(|c| c.technique.name() == def.name),
                "{} is not swept",
                def.name
            );
        }
    }
}
