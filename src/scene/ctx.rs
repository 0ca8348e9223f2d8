//! The validation context: every number is checked against a range in f64 and then in the f32
//! it is used as, and every error names the file, the key and the line.

use std::cell::RefCell;
use std::ops::Range;
use std::path::Path;

use glam::Vec3;
use toml::Spanned;

use super::format::V3;
use crate::error::{Error, Result};

/// Largest coordinate of a position, target, translation or direction, in world units. The
/// shading squares distances and the shadow maps project through matrices built from these,
/// so every coordinate stays far from f32's 3.4·10³⁸ (10¹² squared is 10²⁴).
pub const COORD_LIMIT: f64 = 1e6;

/// Smallest and largest length (sizes, radii, heights) and per-axis scale: small enough to
/// stay an f32 normal number after any product of two (10⁻¹²), large enough for any scene.
pub const LENGTH_RANGE: (f64, f64) = (1e-6, 1e6);

/// Largest rotation angle in degrees, either way (ten turns).
pub const ROTATION_LIMIT: f64 = 3600.0;

/// Largest colour component (albedo, background, ambient, light colour); with `intensity`
/// ≤ 10⁶ a light's radiance stays below 10⁹, and sums over lights stay finite.
pub const COLOR_LIMIT: f64 = 1e3;

/// `x` as the error messages print it: plain for ordinary magnitudes, scientific for the
/// very large and very small (never the 400 digits of `5e-324`).
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e7).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `[a, b, c]` with [`fmt_num`].
pub fn fmt_list(xs: &[f64]) -> String {
    let parts: Vec<String> = xs.iter().map(|&x| fmt_num(x)).collect();
    format!("[{}]", parts.join(", "))
}

/// A path as messages show it: control characters escaped, so a message stays one line.
pub fn shown_path(path: &Path) -> String {
    path.display()
        .to_string()
        .chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

pub(super) struct Ctx<'a> {
    pub path: &'a Path,
    pub text: &'a str,
    pub warnings: RefCell<Vec<String>>,
}

impl Ctx<'_> {
    pub fn location(&self, span: Option<Range<usize>>) -> String {
        span.map_or_else(String::new, |s| super::locate::line_col(self.text, s.start))
    }

    pub fn err(&self, span: Option<Range<usize>>, message: impl Into<String>) -> Error {
        Error::Scene {
            path: self.path.to_path_buf(),
            location: self.location(span),
            message: message.into(),
        }
    }

    pub fn warn(&self, span: Option<Range<usize>>, message: impl std::fmt::Display) {
        self.warnings.borrow_mut().push(format!(
            "{}{}: {message}",
            self.path.display(),
            self.location(span)
        ));
    }

    /// A 3-vector whose components lie in `[lo, hi]` (`what` names the unit in errors).
    pub fn vec3_in(&self, key: &str, v: &V3, (lo, hi): (f64, f64), what: &str) -> Result<Vec3> {
        let c = *v.get_ref();
        if !c.iter().all(|x| x.is_finite()) {
            return Err(self.err(
                Some(v.span()),
                format!("`{key}` must be finite, got {}", fmt_list(&c)),
            ));
        }
        if let Some(i) = c.iter().position(|x| !(lo..=hi).contains(x)) {
            return Err(self.err(
                Some(v.span()),
                format!(
                    "`{key}` = {}: its {} component is outside [{}, {}]{what}",
                    fmt_list(&c),
                    ["x", "y", "z"][i],
                    fmt_num(lo),
                    fmt_num(hi)
                ),
            ));
        }
        self.f32s(key, v.span(), &c)
            .map(|f| Vec3::new(f[0], f[1], f[2]))
    }

    /// A position, target or direction: components within ±[`COORD_LIMIT`].
    pub fn coord(&self, key: &str, v: &V3) -> Result<Vec3> {
        self.vec3_in(key, v, (-COORD_LIMIT, COORD_LIMIT), " world units")
    }

    pub fn coord_or(&self, key: &str, v: &Option<V3>, default: Vec3) -> Result<Vec3> {
        v.as_ref().map_or(Ok(default), |v| self.coord(key, v))
    }

    /// A colour: components in `[0, COLOR_LIMIT]`.
    pub fn color_or(&self, key: &str, v: &Option<V3>, default: Vec3) -> Result<Vec3> {
        v.as_ref().map_or(Ok(default), |v| {
            self.vec3_in(key, v, (0.0, COLOR_LIMIT), "")
        })
    }

    /// The f32 values of checked f64 values: an error should one not be finite as f32 (the
    /// ranges make that impossible; this keeps it so should a range ever be widened).
    pub fn f32s(&self, key: &str, span: Range<usize>, xs: &[f64]) -> Result<Vec<f32>> {
        let out: Vec<f32> = xs.iter().map(|&x| x as f32).collect();
        if let Some(i) = out.iter().position(|x| !x.is_finite()) {
            return Err(self.err(
                Some(span),
                format!("`{key}` = {} does not fit a 32-bit float", fmt_num(xs[i])),
            ));
        }
        Ok(out)
    }

    /// A finite number inside `[lo, hi]` (use infinities for open ends).
    pub fn num(&self, key: &str, v: &Spanned<f64>, lo: f64, hi: f64) -> Result<f32> {
        let x = *v.get_ref();
        if !x.is_finite() || x < lo || x > hi {
            return Err(self.err(
                Some(v.span()),
                format!(
                    "`{key}` = {} is outside [{}, {}]",
                    fmt_num(x),
                    fmt_num(lo),
                    fmt_num(hi)
                ),
            ));
        }
        Ok(self.f32s(key, v.span(), &[x])?[0])
    }

    pub fn num_or(
        &self,
        key: &str,
        v: &Option<Spanned<f64>>,
        lo: f64,
        hi: f64,
        d: f32,
    ) -> Result<f32> {
        v.as_ref().map_or(Ok(d), |v| self.num(key, v, lo, hi))
    }

    pub fn int(&self, key: &str, v: &Spanned<i64>, lo: i64, hi: i64) -> Result<u32> {
        let x = *v.get_ref();
        if x < lo || x > hi {
            return Err(self.err(
                Some(v.span()),
                format!("`{key}` = {x} is outside [{lo}, {hi}]"),
            ));
        }
        u32::try_from(x).map_err(|_| self.err(Some(v.span()), format!("`{key}` = {x} is negative")))
    }

    pub fn int_or(
        &self,
        key: &str,
        v: &Option<Spanned<i64>>,
        lo: i64,
        hi: i64,
        d: u32,
    ) -> Result<u32> {
        v.as_ref().map_or(Ok(d), |v| self.int(key, v, lo, hi))
    }

    pub fn required<'v, T>(&self, key: &str, v: &'v Option<T>, at: Range<usize>) -> Result<&'v T> {
        v.as_ref()
            .ok_or_else(|| self.err(Some(at), format!("missing key `{key}`")))
    }

    pub fn reject<T>(&self, key: &str, v: &Option<Spanned<T>>, why: &str) -> Result<()> {
        match v {
            Some(v) => Err(self.err(Some(v.span()), format!("`{key}` {why}"))),
            None => Ok(()),
        }
    }

    /// The option named by a string key, with `default` when absent.
    pub fn choice<T: Copy>(
        &self,
        key: &str,
        v: &Option<Spanned<String>>,
        options: &[(&str, T)],
        default: T,
    ) -> Result<T> {
        let Some(v) = v else { return Ok(default) };
        options
            .iter()
            .find(|(name, _)| *name == v.get_ref())
            .map(|(_, t)| *t)
            .ok_or_else(|| {
                let names: Vec<String> = options.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                self.err(
                    Some(v.span()),
                    format!(
                        "`{key}` = {:?}: expected one of {}",
                        v.get_ref(),
                        names.join(", ")
                    ),
                )
            })
    }
}

#[cfg(test)]
mod tests {
    use super::fmt_num;

    #[test]
    fn numbers_print_short() {
        assert_eq!(fmt_num(5e-324), "5e-324");
        assert_eq!(fmt_num(1e39), "1e39");
        assert_eq!(fmt_num(-1e-50), "-1e-50");
        assert_eq!(fmt_num(0.002), "0.002");
        assert_eq!(fmt_num(1e6), "1000000");
        assert_eq!(fmt_num(f64::NAN), "NaN");
        assert_eq!(fmt_num(f64::NEG_INFINITY), "-inf");
        assert_eq!(fmt_num(0.0), "0");
    }
}
