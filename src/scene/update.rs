//! How often a light's shadow map is redrawn when nothing it depends on changed: the
//! `update` key of a `[[light]]` (docs/SCENES.md).

use toml::Spanned;

use super::ctx::Ctx;
use crate::error::Result;

/// Largest `update = k`: a light redrawn less often than this is `"static"`.
pub const MAX_UPDATE_PERIOD: i64 = 1 << 20;

/// How often the renderer redraws a light's map (its raster and its prefilter) while the
/// light, its casters and its shadow configuration stay the same. A change to any of them
/// redraws it on the frame it happens, whatever the rate: an image is never stale.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpdateRate {
    /// Every frame (`update = 1`, the default).
    #[default]
    EveryFrame,
    /// Every `k`-th frame (`update = k`, k ≥ 2): the frame after `k − 1` frames that reused
    /// the map.
    Every(u32),
    /// Only when something it depends on changed (`update = "static"`).
    Static,
}

impl UpdateRate {
    /// Whether the rate asks for a redraw `frames` frames after the last one (1: the next).
    pub fn due(self, frames: u64) -> bool {
        match self {
            Self::EveryFrame => true,
            Self::Every(k) => frames >= u64::from(k),
            Self::Static => false,
        }
    }

    /// The rate as the scene file writes it: `1`, `k` or `"static"`.
    pub fn name(self) -> String {
        match self {
            Self::EveryFrame => "1".into(),
            Self::Every(k) => k.to_string(),
            Self::Static => "\"static\"".into(),
        }
    }
}

/// Light `i`'s `update` key: a positive integer or `"static"`; absent, every frame.
pub(super) fn update_rate(
    ctx: &Ctx,
    i: usize,
    v: &Option<Spanned<toml::Value>>,
) -> Result<UpdateRate> {
    let Some(v) = v else {
        return Ok(UpdateRate::EveryFrame);
    };
    let rate = match v.get_ref() {
        toml::Value::Integer(1) => Some(UpdateRate::EveryFrame),
        toml::Value::Integer(k) if (2..=MAX_UPDATE_PERIOD).contains(k) => {
            u32::try_from(*k).ok().map(UpdateRate::Every)
        }
        toml::Value::String(s) if s == "static" => Some(UpdateRate::Static),
        _ => None,
    };
    rate.ok_or_else(|| {
        ctx.err(
            Some(v.span()),
            format!(
                "`light[{i}].update` = {}: expected a whole number of frames from 1 to \
                 {MAX_UPDATE_PERIOD} or \"static\"",
                shown(v.get_ref())
            ),
        )
    })
}

/// A TOML value as the error shows it, on one line: numbers as [`super::ctx::fmt_num`] prints
/// them (never the 300 digits of `1e300`), strings cut at 40 characters, the first four
/// elements of an array, a table as `{…}`.
fn shown(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(x) => super::ctx::fmt_num(*x),
        toml::Value::String(s) if s.chars().count() > 40 => {
            format!("{:?}…", s.chars().take(40).collect::<String>())
        }
        toml::Value::String(s) => format!("{s:?}"),
        toml::Value::Array(items) => {
            let mut parts: Vec<String> = items.iter().take(4).map(shown).collect();
            if items.len() > 4 {
                parts.push("…".into());
            }
            format!("[{}]", parts.join(", "))
        }
        toml::Value::Table(_) => "{…}".into(),
        other => other.to_string().replace(['\n', '\r'], " "),
    }
}
