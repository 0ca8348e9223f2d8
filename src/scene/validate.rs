//! A light's `[light.shadow]` table: the technique named, then its keys checked against the
//! technique's parameter table in the registry (`crate::technique`) by the one checker,
//! worded with the file, the key and the line.

use toml::Spanned;

use super::ctx::Ctx;
use super::format::ShadowFile;
use crate::error::{Error, Result};
use crate::model::{ParamSource, ParamValue, Shadow};
use crate::technique::{
    self, ClampReason, REGISTRY,
    params::{CASCADES, COMMON},
};

/// A key's value as written.
enum Raw<'a> {
    Int(&'a Spanned<i64>),
    Num(&'a Spanned<f64>),
    Str(&'a Spanned<String>),
}

impl Raw<'_> {
    fn span(&self) -> std::ops::Range<usize> {
        match self {
            Raw::Int(v) => v.span(),
            Raw::Num(v) => v.span(),
            Raw::Str(v) => v.span(),
        }
    }
}

/// The value of `key` as written, if it is.
fn raw<'a>(s: &'a ShadowFile, key: &str) -> Option<Raw<'a>> {
    let n = |v: &'a Option<Spanned<f64>>| v.as_ref().map(Raw::Num);
    let i = |v: &'a Option<Spanned<i64>>| v.as_ref().map(Raw::Int);
    let t = |v: &'a Option<Spanned<String>>| v.as_ref().map(Raw::Str);
    match key {
        "bias" => n(&s.bias),
        "slope_bias" => n(&s.slope_bias),
        "normal_bias" => n(&s.normal_bias),
        "radius" => i(&s.radius),
        "kernel" => t(&s.kernel),
        "blocker_samples" => i(&s.blocker_samples),
        "filter_samples" => i(&s.filter_samples),
        "max_search" => n(&s.max_search),
        "format" => t(&s.format),
        "filter" => t(&s.filter),
        "filter_radius" => n(&s.filter_radius),
        "filter_sigma" => n(&s.filter_sigma),
        "filter_kernel" => t(&s.filter_kernel),
        "bleed_reduction" => n(&s.bleed_reduction),
        "min_variance" => n(&s.min_variance),
        "exponent" => n(&s.exponent),
        "exponent_pos" => n(&s.exponent_pos),
        "exponent_neg" => n(&s.exponent_neg),
        "filter_width" => n(&s.filter_width),
        "sat_sums" => t(&s.sat_sums),
        "max_anisotropy" => i(&s.max_anisotropy),
        "reconstruction" => t(&s.reconstruction),
        "moment_bias" => n(&s.moment_bias),
        "terms" => i(&s.terms),
        "attenuation" => n(&s.attenuation),
        "offset" => n(&s.offset),
        "scale" => n(&s.scale),
        "sharpen" => n(&s.sharpen),
        "sharpen_falloff" => n(&s.sharpen_falloff),
        "blocker_search" => t(&s.blocker_search),
        "resolve" => t(&s.resolve),
        "bias_mode" => t(&s.bias_mode),
        "receiver_plane_cap" => n(&s.receiver_plane_cap),
        "rays" => i(&s.rays),
        "steps" => i(&s.steps),
        "max_slope" => n(&s.max_slope),
        "cascades" => i(&s.cascades),
        "cascade_lambda" => n(&s.cascade_lambda),
        "cascade_blend" => n(&s.cascade_blend),
        _ => None,
    }
}

/// Where `key` of the table is written, if it is.
pub(super) fn written(s: &ShadowFile, key: &str) -> Option<std::ops::Range<usize>> {
    raw(s, key).map(|r| r.span())
}

/// Light `i`'s table as the checker's source: values in f64 checked then rounded to f32
/// (`Ctx`), errors naming `light[i].shadow.<key>` and its line.
struct Table<'a> {
    ctx: &'a Ctx<'a>,
    i: usize,
    s: &'a ShadowFile,
}

impl Table<'_> {
    fn key(&self, k: &str) -> String {
        format!("light[{}].shadow.{k}", self.i)
    }

    /// A value of the wrong kind for its spec (the TOML reader types every key, so only a
    /// table that disagrees with `format.rs` gets here).
    fn mismatch(&self, key: &str, raw: &Raw) -> Error {
        self.ctx.err(
            Some(raw.span()),
            format!("`{}` has the wrong type", self.key(key)),
        )
    }
}

impl ParamSource for Table<'_> {
    type Error = Error;

    fn present(&self, key: &str) -> bool {
        raw(self.s, key).is_some()
    }

    fn int(&self, key: &'static str, lo: i64, hi: i64) -> Result<Option<u32>> {
        match raw(self.s, key) {
            None => Ok(None),
            Some(Raw::Int(v)) => self.ctx.int(&self.key(key), v, lo, hi).map(Some),
            Some(r) => Err(self.mismatch(key, &r)),
        }
    }

    fn float(&self, key: &'static str, lo: f64, hi: f64) -> Result<Option<f32>> {
        match raw(self.s, key) {
            None => Ok(None),
            Some(Raw::Num(v)) => self.ctx.num(&self.key(key), v, lo, hi).map(Some),
            Some(r) => Err(self.mismatch(key, &r)),
        }
    }

    fn choice(
        &self,
        key: &'static str,
        options: &'static [&'static str],
    ) -> Result<Option<&'static str>> {
        match raw(self.s, key) {
            None => Ok(None),
            Some(Raw::Str(v)) => {
                let named: Vec<(&str, &'static str)> = options.iter().map(|o| (*o, *o)).collect();
                let v = Some(v.clone());
                self.ctx.choice(&self.key(key), &v, &named, "").map(Some)
            }
            Some(r) => Err(self.mismatch(key, &r)),
        }
    }

    fn not_applicable(&self, key: &'static str, why: &str) -> Error {
        let span = raw(self.s, key).map(|r| r.span());
        self.ctx.err(span, format!("`{}` {why}", self.key(key)))
    }
}

pub(super) fn shadow(ctx: &Ctx, i: usize, s: &ShadowFile) -> Result<Shadow> {
    let table = Table { ctx, i, s };
    let name = s.technique.get_ref().as_str();
    let Some(def) = technique::by_name(name) else {
        let known: Vec<String> = REGISTRY.iter().map(|d| format!("\"{}\"", d.name)).collect();
        return Err(ctx.err(
            Some(s.technique.span()),
            format!(
                "`{}` = {name:?}: unknown technique (this build knows {})",
                table.key("technique"),
                known.join(", ")
            ),
        ));
    };
    let allowed = crate::model::keys(def.params);
    // Every technique's keys (the registry's tables, in its order): the first written that
    // this technique does not take is reported.
    let keys = REGISTRY.iter().flat_map(|d| crate::model::keys(d.params));
    if let Some(k) = keys
        .filter(|k| !allowed.contains(k))
        .find(|k| raw(s, k).is_some())
    {
        return Err(table.not_applicable(k, &format!("does not apply to technique \"{name}\"")));
    }
    let (technique, clamps) = technique::check_and_build(def, &table)?;
    for c in clamps {
        // A table's limit is the scene's choice of width: its clamp is reported only when the
        // exponent was written; a storage's limit always.
        let written = raw(s, c.key);
        if c.reason == ClampReason::Sat && written.is_none() {
            continue;
        }
        ctx.warn(written.map(|r| r.span()), c.message(&table.key(c.key)));
    }
    // The technique's own values again, for the keys its `Technique` does not hold (the
    // receiver-plane bias, which is the light's `Shadow`).
    let receiver_plane =
        technique::params::receiver_plane(&crate::model::check_params(def.params, &table)?);
    let common = crate::model::check_params(&[COMMON], &table)?;
    let cascades = technique::params::cascades(&crate::model::check_params(&[CASCADES], &table)?);
    if cascades.count > 1 {
        if let Err(why) = technique::params::cascade_support(&technique) {
            return Err(table.not_applicable(
                "cascades",
                &format!(
                    "= {} does not apply to technique \"{name}\": {why}",
                    cascades.count
                ),
            ));
        }
    }
    let float = |k| match common.get(k) {
        Some(ParamValue::Float(v)) => v,
        _ => 0.0,
    };
    Ok(Shadow {
        technique,
        bias: float("bias"),
        slope_bias: float("slope_bias"),
        normal_bias: float("normal_bias"),
        receiver_plane,
        cascades,
    })
}
