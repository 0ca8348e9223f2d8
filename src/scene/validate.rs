//! A light's `[light.shadow]` table: the technique, the keys each technique accepts, their
//! ranges and defaults.

use std::ops::Range;

use toml::Spanned;

use super::ctx::Ctx;
use super::format::ShadowFile;
use super::{BlurKernel, Filter, PcfKernel, Prefilter, Shadow, Soft, Storage, Technique};
use crate::error::Result;
use crate::model::{
    DEFAULT_MAX_SEARCH, DEFAULT_SHARPEN, DEFAULT_SHARPEN_FALLOFF, default_moment_bias,
    default_soft_moment_bias, exponent_limit,
};
use crate::technique::sat_exponent_limit;

/// The technique-specific keys each technique accepts (the common ones — technique, bias,
/// slope_bias, normal_bias — are always allowed).
const TECHNIQUE_KEYS: &[(&str, &[&str])] = &[
    ("hard", &[]),
    ("pcf", &["radius", "kernel"]),
    ("pcss", &["blocker_samples", "filter_samples", "max_search"]),
    (
        "vsm",
        &[
            "format",
            FILTER,
            RADIUS,
            SIGMA,
            KERNEL,
            WIDTH,
            SAT_SUMS,
            ANISOTROPY,
            "bleed_reduction",
            "min_variance",
        ],
    ),
    (
        "evsm2",
        &[
            "format",
            FILTER,
            RADIUS,
            SIGMA,
            KERNEL,
            WIDTH,
            SAT_SUMS,
            ANISOTROPY,
            "bleed_reduction",
            "min_variance",
            "exponent_pos",
        ],
    ),
    (
        "evsm4",
        &[
            "format",
            FILTER,
            RADIUS,
            SIGMA,
            KERNEL,
            WIDTH,
            SAT_SUMS,
            ANISOTROPY,
            "bleed_reduction",
            "min_variance",
            "exponent_pos",
            "exponent_neg",
        ],
    ),
    (
        "esm",
        &[
            FILTER, RADIUS, SIGMA, KERNEL, WIDTH, SAT_SUMS, ANISOTROPY, "exponent",
        ],
    ),
    (
        "msm",
        &[
            "format",
            FILTER,
            RADIUS,
            SIGMA,
            KERNEL,
            WIDTH,
            SAT_SUMS,
            ANISOTROPY,
            "reconstruction",
            "moment_bias",
            "bleed_reduction",
        ],
    ),
    (
        "csm",
        &[
            "format",
            FILTER,
            RADIUS,
            SIGMA,
            KERNEL,
            WIDTH,
            SAT_SUMS,
            ANISOTROPY,
            "terms",
            "attenuation",
            "offset",
            "scale",
        ],
    ),
    (
        "cssm",
        &[
            "format",
            SAT_SUMS,
            "max_search",
            "terms",
            "attenuation",
            "offset",
            "scale",
            "sharpen",
            "sharpen_falloff",
        ],
    ),
    (
        "vssm",
        &[
            "format",
            SAT_SUMS,
            "max_search",
            "bleed_reduction",
            "min_variance",
        ],
    ),
    (
        "msm_soft",
        &[
            "format",
            SAT_SUMS,
            "max_search",
            "reconstruction",
            "moment_bias",
            "bleed_reduction",
        ],
    ),
];
const FILTER: &str = "filter";
const RADIUS: &str = "filter_radius";
const SIGMA: &str = "filter_sigma";
const KERNEL: &str = "filter_kernel";
const WIDTH: &str = "filter_width";
const SAT_SUMS: &str = "sat_sums";
const ANISOTROPY: &str = "max_anisotropy";

/// Storage formats of the two- and four-moment float techniques.
const FLOAT_STORAGE: &[(&str, Storage)] = &[("f32", Storage::F32), ("f16", Storage::F16)];

/// Storage formats of MSM (16-bit ones through the optimized quantization).
const MSM_STORAGE: &[(&str, Storage)] = &[
    ("f32", Storage::F32),
    ("f16", Storage::F16),
    ("unorm16", Storage::Unorm16),
];

/// MSM reconstructions: `hausdorff` is `true`.
const RECONSTRUCTIONS: [(&str, bool); 2] = [("hamburger", false), ("hausdorff", true)];

/// `c` clamped to the SAT limit, with a warning when the scene set it explicitly.
fn clamp_for_sat(ctx: &Ctx, key: &str, v: &Option<Spanned<f64>>, c: f32, sat: Option<f32>) -> f32 {
    let Some(limit) = sat else {
        return c;
    };
    if c > limit && v.is_some() {
        ctx.warnings.borrow_mut().push(format!(
            "{}{}: `{key}` = {c} exceeds {limit:.2}, the largest a summed-area table of this \
             `filter_width` keeps accurate; clamped",
            ctx.path.display(),
            ctx.location(v.as_ref().map(|v| v.span())),
        ));
    }
    c.min(limit)
}

fn present(s: &ShadowFile) -> Vec<(&'static str, Range<usize>)> {
    fn sp<T>(v: &Option<Spanned<T>>) -> Option<Range<usize>> {
        v.as_ref().map(|v| v.span())
    }
    [
        ("radius", sp(&s.radius)),
        ("kernel", sp(&s.kernel)),
        ("blocker_samples", sp(&s.blocker_samples)),
        ("filter_samples", sp(&s.filter_samples)),
        ("max_search", sp(&s.max_search)),
        ("format", sp(&s.format)),
        ("filter", sp(&s.filter)),
        ("filter_radius", sp(&s.filter_radius)),
        ("filter_sigma", sp(&s.filter_sigma)),
        ("filter_kernel", sp(&s.filter_kernel)),
        ("bleed_reduction", sp(&s.bleed_reduction)),
        ("min_variance", sp(&s.min_variance)),
        ("exponent", sp(&s.exponent)),
        ("exponent_pos", sp(&s.exponent_pos)),
        ("exponent_neg", sp(&s.exponent_neg)),
        ("filter_width", sp(&s.filter_width)),
        ("sat_sums", sp(&s.sat_sums)),
        ("max_anisotropy", sp(&s.max_anisotropy)),
        ("reconstruction", sp(&s.reconstruction)),
        ("moment_bias", sp(&s.moment_bias)),
        ("terms", sp(&s.terms)),
        ("attenuation", sp(&s.attenuation)),
        ("offset", sp(&s.offset)),
        ("scale", sp(&s.scale)),
        ("sharpen", sp(&s.sharpen)),
        ("sharpen_falloff", sp(&s.sharpen_falloff)),
    ]
    .into_iter()
    .filter_map(|(k, span)| span.map(|s| (k, s)))
    .collect()
}

pub(super) fn shadow(ctx: &Ctx, i: usize, s: &ShadowFile) -> Result<Shadow> {
    let key = |k: &str| format!("light[{i}].shadow.{k}");
    let name = s.technique.get_ref().as_str();
    let Some((_, allowed)) = TECHNIQUE_KEYS.iter().find(|(t, _)| *t == name) else {
        let known: Vec<String> = TECHNIQUE_KEYS
            .iter()
            .map(|(t, _)| format!("\"{t}\""))
            .collect();
        return Err(ctx.err(
            Some(s.technique.span()),
            format!(
                "`{}` = {name:?}: unknown technique (this build knows {})",
                key("technique"),
                known.join(", ")
            ),
        ));
    };
    if let Some((k, span)) = present(s).into_iter().find(|(k, _)| !allowed.contains(k)) {
        return Err(ctx.err(
            Some(span),
            format!("`{}` does not apply to technique \"{name}\"", key(k)),
        ));
    }
    let technique = match name {
        "hard" => Technique::Hard,
        "pcf" => {
            let kernels = [
                ("box", PcfKernel::Box),
                ("tent", PcfKernel::Tent),
                ("hardware", PcfKernel::Hardware),
            ];
            let kernel = ctx.choice(&key("kernel"), &s.kernel, &kernels, PcfKernel::Box)?;
            if kernel == PcfKernel::Hardware {
                ctx.reject(
                    &key("radius"),
                    &s.radius,
                    "does not apply to the hardware 2×2 kernel",
                )?;
            }
            Technique::Pcf {
                radius: ctx.int_or(&key("radius"), &s.radius, 0, 32, 1)?,
                kernel,
            }
        }
        "pcss" => Technique::Pcss {
            blocker_samples: ctx.int_or(&key("blocker_samples"), &s.blocker_samples, 1, 256, 16)?,
            filter_samples: ctx.int_or(&key("filter_samples"), &s.filter_samples, 1, 1024, 32)?,
            max_search: ctx.num_or(
                &key("max_search"),
                &s.max_search,
                1e-4,
                1.0,
                DEFAULT_MAX_SEARCH,
            )?,
        },
        "vsm" => Technique::Vsm {
            prefilter: prefilter(ctx, i, s, FLOAT_STORAGE)?,
            bleed: ctx.num_or(&key("bleed_reduction"), &s.bleed_reduction, 0.0, 0.99, 0.2)?,
            min_variance: ctx.num_or(&key("min_variance"), &s.min_variance, 0.0, 1.0, 1e-5)?,
        },
        "evsm2" | "evsm4" => {
            let prefilter = prefilter(ctx, i, s, FLOAT_STORAGE)?;
            let limit = exponent_limit(prefilter.storage);
            let sat = sat_exponent_limit(&prefilter.filter, false);
            let exponent = |k: &str, v: &Option<Spanned<f64>>, default: f32| -> Result<f32> {
                let c = ctx.num_or(&key(k), v, 0.01, 1e4, default)?;
                if c > limit {
                    ctx.warnings.borrow_mut().push(format!(
                        "{}{}: `{}` = {c} exceeds the safe limit {limit} for {:?} storage; clamped to {limit}",
                        ctx.path.display(),
                        ctx.location(v.as_ref().map(|v| v.span())),
                        key(k),
                        prefilter.storage
                    ));
                }
                let c = c.min(limit);
                Ok(clamp_for_sat(ctx, &key(k), v, c, sat))
            };
            Technique::Evsm {
                prefilter,
                four: name == "evsm4",
                exp_pos: exponent("exponent_pos", &s.exponent_pos, 40.0)?,
                exp_neg: exponent("exponent_neg", &s.exponent_neg, 5.0)?,
                bleed: ctx.num_or(&key("bleed_reduction"), &s.bleed_reduction, 0.0, 0.99, 0.0)?,
                min_variance: ctx.num_or(&key("min_variance"), &s.min_variance, 0.0, 1.0, 1e-4)?,
            }
        }
        "msm" => {
            let prefilter = prefilter(ctx, i, s, MSM_STORAGE)?;
            let (hausdorff, moment_bias, bleed) =
                msm_keys(ctx, i, s, default_moment_bias(prefilter.storage))?;
            Technique::Msm {
                prefilter,
                hausdorff,
                moment_bias,
                bleed,
            }
        }
        "cssm" => {
            let (terms, attenuation, offset, scale) = csm_keys(ctx, i, s)?;
            Technique::Cssm {
                soft: soft(ctx, i, s, FLOAT_STORAGE)?,
                terms,
                attenuation,
                offset,
                scale,
                sharpen: ctx.num_or(&key("sharpen"), &s.sharpen, 0.0, 100.0, DEFAULT_SHARPEN)?,
                sharpen_falloff: ctx.num_or(
                    &key("sharpen_falloff"),
                    &s.sharpen_falloff,
                    0.0,
                    1e4,
                    DEFAULT_SHARPEN_FALLOFF,
                )?,
            }
        }
        "vssm" => Technique::Vssm {
            soft: soft(ctx, i, s, FLOAT_STORAGE)?,
            bleed: ctx.num_or(&key("bleed_reduction"), &s.bleed_reduction, 0.0, 0.99, 0.2)?,
            min_variance: ctx.num_or(&key("min_variance"), &s.min_variance, 0.0, 1.0, 1e-5)?,
        },
        "msm_soft" => {
            let soft = soft(ctx, i, s, MSM_STORAGE)?;
            let (hausdorff, moment_bias, bleed) =
                msm_keys(ctx, i, s, default_soft_moment_bias(soft.storage))?;
            Technique::MsmSoft {
                soft,
                hausdorff,
                moment_bias,
                bleed,
            }
        }
        "csm" => {
            let (terms, attenuation, offset, scale) = csm_keys(ctx, i, s)?;
            Technique::Csm {
                prefilter: prefilter(ctx, i, s, FLOAT_STORAGE)?,
                terms,
                attenuation,
                offset,
                scale,
            }
        }
        _ => {
            let filter = prefilter(ctx, i, s, &[("f32", Storage::F32)])?.filter;
            let c = ctx.num_or(&key("exponent"), &s.exponent, 0.01, 1e4, 80.0)?;
            let sat = sat_exponent_limit(&filter, true);
            Technique::Esm {
                filter,
                exponent: clamp_for_sat(ctx, &key("exponent"), &s.exponent, c, sat),
            }
        }
    };
    Ok(Shadow {
        technique,
        bias: ctx.num_or(&key("bias"), &s.bias, -1.0, 1.0, 0.002)?,
        slope_bias: ctx.num_or(&key("slope_bias"), &s.slope_bias, 0.0, 100.0, 1.0)?,
        normal_bias: ctx.num_or(&key("normal_bias"), &s.normal_bias, 0.0, 100.0, 1.0)?,
    })
}

fn prefilter(
    ctx: &Ctx,
    i: usize,
    s: &ShadowFile,
    storages: &[(&str, Storage)],
) -> Result<Prefilter> {
    let key = |k: &str| format!("light[{i}].shadow.{k}");
    let storage = ctx.choice(&key("format"), &s.format, storages, Storage::F32)?;
    #[derive(Clone, Copy, PartialEq)]
    enum Kind {
        None,
        Blur,
        Mips,
        Sat,
    }
    let kind = ctx.choice(
        &key("filter"),
        &s.filter,
        &[
            ("none", Kind::None),
            ("blur", Kind::Blur),
            ("mips", Kind::Mips),
            ("sat", Kind::Sat),
        ],
        Kind::Blur,
    )?;
    if kind != Kind::Blur {
        let why = "needs `filter = \"blur\"`";
        ctx.reject(&key("filter_radius"), &s.filter_radius, why)?;
        ctx.reject(&key("filter_sigma"), &s.filter_sigma, why)?;
        ctx.reject(&key("filter_kernel"), &s.filter_kernel, why)?;
    }
    if !matches!(kind, Kind::Mips | Kind::Sat) {
        ctx.reject(
            &key("filter_width"),
            &s.filter_width,
            "needs `filter = \"mips\"` or `\"sat\"`",
        )?;
    }
    if kind != Kind::Sat {
        ctx.reject(&key(SAT_SUMS), &s.sat_sums, "needs `filter = \"sat\"`")?;
    }
    if kind != Kind::Mips {
        ctx.reject(
            &key(ANISOTROPY),
            &s.max_anisotropy,
            "needs `filter = \"mips\"`",
        )?;
    }
    let filter = match kind {
        Kind::None => Filter::None,
        Kind::Mips => Filter::Mips {
            width: ctx.num_or(&key("filter_width"), &s.filter_width, 1.0, 65536.0, 1.0)?,
            max_anisotropy: ctx.int_or(&key(ANISOTROPY), &s.max_anisotropy, 0, 16, 0)?,
        },
        Kind::Sat => Filter::Sat {
            width: ctx.num_or(&key("filter_width"), &s.filter_width, 1.0, 1024.0, 3.0)?,
            variant: ctx.choice(
                &key(SAT_SUMS),
                &s.sat_sums,
                &[
                    ("fixed", crate::sat::SatVariant::Fixed),
                    ("float", crate::sat::SatVariant::Float),
                ],
                crate::sat::SatVariant::Fixed,
            )?,
        },
        Kind::Blur => {
            let radius = ctx.num_or(
                &key("filter_radius"),
                &s.filter_radius,
                0.0,
                f64::from(crate::filter::MAX_BLUR_RADIUS),
                2.0,
            )?;
            let kernel = ctx.choice(
                &key("filter_kernel"),
                &s.filter_kernel,
                &[("gaussian", BlurKernel::Gaussian), ("box", BlurKernel::Box)],
                BlurKernel::Gaussian,
            )?;
            if kernel == BlurKernel::Box {
                ctx.reject(
                    &key("filter_sigma"),
                    &s.filter_sigma,
                    "does not apply to the box kernel",
                )?;
            }
            let sigma = ctx.num_or(
                &key("filter_sigma"),
                &s.filter_sigma,
                0.1,
                100.0,
                (0.5 * radius).max(0.5),
            )?;
            Filter::Blur {
                radius,
                sigma,
                kernel,
            }
        }
    };
    Ok(Prefilter { storage, filter })
}

/// The storage, table sums and search cap of a soft technique; its table is always a
/// summed-area table read at a per-receiver width.
/// MSM's reconstruction keys (`msm`, `msm_soft`): Hausdorff or not, the moment bias (default
/// `bias`) and the bleeding reduction.
fn msm_keys(ctx: &Ctx, i: usize, s: &ShadowFile, bias: f32) -> Result<(bool, f32, f32)> {
    let key = |k: &str| format!("light[{i}].shadow.{k}");
    Ok((
        ctx.choice(
            &key("reconstruction"),
            &s.reconstruction,
            &RECONSTRUCTIONS,
            false,
        )?,
        ctx.num_or(&key("moment_bias"), &s.moment_bias, 0.0, 0.5, bias)?,
        ctx.num_or(&key("bleed_reduction"), &s.bleed_reduction, 0.0, 0.99, 0.0)?,
    ))
}

/// CSM's series keys (`csm`, `cssm`): terms M, attenuation, offset (default ½/M) and scale.
fn csm_keys(ctx: &Ctx, i: usize, s: &ShadowFile) -> Result<(u32, f32, f32, f32)> {
    let key = |k: &str| format!("light[{i}].shadow.{k}");
    let terms = ctx.int_or(&key("terms"), &s.terms, 1, 16, 8)?;
    Ok((
        terms,
        ctx.num_or(&key("attenuation"), &s.attenuation, 0.0, 20.0, 1.0)?,
        ctx.num_or(&key("offset"), &s.offset, 0.0, 0.5, 0.5 / terms as f32)?,
        ctx.num_or(&key("scale"), &s.scale, 1.0, 16.0, 2.0)?,
    ))
}

fn soft(ctx: &Ctx, i: usize, s: &ShadowFile, storages: &[(&str, Storage)]) -> Result<Soft> {
    let key = |k: &str| format!("light[{i}].shadow.{k}");
    Ok(Soft {
        storage: ctx.choice(&key("format"), &s.format, storages, Storage::F32)?,
        sums: ctx.choice(
            &key(SAT_SUMS),
            &s.sat_sums,
            &[
                ("fixed", crate::sat::SatVariant::Fixed),
                ("float", crate::sat::SatVariant::Float),
            ],
            crate::sat::SatVariant::Fixed,
        )?,
        max_search: ctx.num_or(
            &key("max_search"),
            &s.max_search,
            1e-4,
            1.0,
            DEFAULT_MAX_SEARCH,
        )?,
    })
}
