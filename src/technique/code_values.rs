//! Values given in code as the parameter checker's source: the plug-in's config and the
//! registry's defaults ([`Given`], range-checked in f32), and values taken as they are to
//! rebuild a technique ([`Loose`]).

use crate::model::ParamValue;

/// Values given in code (the plug-in's config, a default): the checker's source with plain
/// messages (`"{v} is outside [lo, hi]"`), compared in f32 so that the f32 a bound turns into
/// (0.99 → 0.9900000095) passes as it does in a scene.
pub struct Given<'a>(pub &'a crate::model::ParamValues);

/// A value [`Given`] refuses.
#[derive(Clone, Debug, PartialEq)]
pub struct GivenError {
    /// The key.
    pub key: &'static str,
    /// What is wrong with it.
    pub message: String,
}

impl crate::model::ParamSource for Given<'_> {
    type Error = GivenError;

    fn present(&self, key: &str) -> bool {
        self.0.get(key).is_some()
    }

    fn int(&self, key: &'static str, lo: i64, hi: i64) -> Result<Option<u32>, GivenError> {
        match self.0.get(key) {
            Some(ParamValue::Int(v)) if (lo..=hi).contains(&i64::from(v)) => Ok(Some(v)),
            Some(ParamValue::Int(v)) => Err(GivenError {
                key,
                message: format!("{v} is outside [{lo}, {hi}]"),
            }),
            _ => Ok(None),
        }
    }

    fn float(&self, key: &'static str, lo: f64, hi: f64) -> Result<Option<f32>, GivenError> {
        match self.0.get(key) {
            Some(ParamValue::Float(v)) if v.is_finite() && v >= lo as f32 && v <= hi as f32 => {
                Ok(Some(v))
            }
            Some(ParamValue::Float(v)) => Err(GivenError {
                key,
                message: format!("{v} is outside [{lo}, {hi}]"),
            }),
            _ => Ok(None),
        }
    }

    fn choice(
        &self,
        key: &'static str,
        options: &'static [&'static str],
    ) -> Result<Option<&'static str>, GivenError> {
        match self.0.get(key) {
            Some(ParamValue::Choice(c)) => match options.iter().find(|o| **o == c) {
                Some(o) => Ok(Some(o)),
                None => Err(GivenError {
                    key,
                    message: format!("{c:?}: expected one of {options:?}"),
                }),
            },
            _ => Ok(None),
        }
    }

    fn not_applicable(&self, key: &'static str, why: &str) -> GivenError {
        GivenError {
            key,
            message: why.to_string(),
        }
    }
}

/// Values given in code taken as they are (no range check), for building a technique whose
/// values a later [`Given`] check reports.
pub struct Loose<'a>(pub &'a crate::model::ParamValues);

impl crate::model::ParamSource for Loose<'_> {
    type Error = ();

    fn present(&self, key: &str) -> bool {
        self.0.get(key).is_some()
    }

    fn int(&self, key: &'static str, _: i64, _: i64) -> Result<Option<u32>, ()> {
        match self.0.get(key) {
            Some(ParamValue::Int(v)) => Ok(Some(v)),
            Some(_) => Err(()),
            None => Ok(None),
        }
    }

    fn float(&self, key: &'static str, _: f64, _: f64) -> Result<Option<f32>, ()> {
        match self.0.get(key) {
            Some(ParamValue::Float(v)) => Ok(Some(v)),
            Some(_) => Err(()),
            None => Ok(None),
        }
    }

    fn choice(
        &self,
        key: &'static str,
        options: &'static [&'static str],
    ) -> Result<Option<&'static str>, ()> {
        match self.0.get(key) {
            Some(ParamValue::Choice(c)) => options
                .iter()
                .find(|o| **o == c)
                .map(|o| Some(*o))
                .ok_or(()),
            Some(_) => Err(()),
            None => Ok(None),
        }
    }

    fn not_applicable(&self, _: &'static str, _: &str) {}
}
