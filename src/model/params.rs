//! Parameter specifications: what a technique's keys accept (range or options), their
//! defaults and when they apply, as plain data. The technique registry writes each table once
//! (`crate::technique`); the scene parser and the plug-in's config check values against it
//! through one checker (`technique::check_and_build` over `model::check_params`), each wording its own errors.

/// The values a key accepts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    /// An integer in `[lo, hi]`.
    Int {
        /// Smallest value.
        lo: i64,
        /// Largest value.
        hi: i64,
    },
    /// A finite number in `[lo, hi]`.
    Float {
        /// Smallest value.
        lo: f64,
        /// Largest value.
        hi: f64,
    },
    /// One of these names.
    Choice(&'static [&'static str]),
}

/// A key's value when it is absent.
#[derive(Clone, Copy, Debug)]
pub enum ParamDefault {
    /// This integer.
    Int(u32),
    /// This number.
    Float(f32),
    /// This option.
    Choice(&'static str),
    /// Computed from the keys before it (the spec's doc line says how).
    Rule(fn(&ParamValues) -> ParamValue),
}

/// A condition on an earlier key: the key applies only while `key` is one of `one_of`; else
/// setting it is an error, `why` (e.g. "needs `filter = \"blur\"`").
#[derive(Clone, Copy, Debug)]
pub struct Needs {
    /// The earlier key (a choice).
    pub key: &'static str,
    /// The options it must have.
    pub one_of: &'static [&'static str],
    /// The error's wording when it has another.
    pub why: &'static str,
}

/// One key of a technique's `[light.shadow]` table (and of the plug-in's config).
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// The scene key.
    pub key: &'static str,
    /// What it accepts.
    pub kind: ParamKind,
    /// Its value when absent.
    pub default: ParamDefault,
    /// When it applies (all must hold). A key may have several specs with different
    /// conditions (e.g. `filter_width`'s range per filter); the first that applies is used.
    pub needs: &'static [Needs],
    /// One line for documentation.
    pub doc: &'static str,
}

/// A checked value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    /// An integer.
    Int(u32),
    /// A number (f32: what the kernels read).
    Float(f32),
    /// An option's name.
    Choice(&'static str),
}

/// The checked values of a table, in spec order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamValues(pub Vec<(&'static str, ParamValue)>);

impl ParamValues {
    /// The value of `key`, if checked.
    pub fn get(&self, key: &str) -> Option<ParamValue> {
        self.0.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
    }

    /// The integer `key` (0 when absent or not an integer: the tables make that impossible).
    pub fn int(&self, key: &str) -> u32 {
        match self.get(key) {
            Some(ParamValue::Int(v)) => v,
            _ => 0,
        }
    }

    /// The number `key` (0 when absent or not a number).
    pub fn float(&self, key: &str) -> f32 {
        match self.get(key) {
            Some(ParamValue::Float(v)) => v,
            _ => 0.0,
        }
    }

    /// The option `key` ("" when absent or not a choice).
    pub fn choice(&self, key: &str) -> &'static str {
        match self.get(key) {
            Some(ParamValue::Choice(v)) => v,
            _ => "",
        }
    }

    /// Removes `key` (its default applies again when checked).
    pub fn remove(&mut self, key: &str) {
        self.0.retain(|(k, _)| *k != key);
    }

    /// Sets `key` (appended when new).
    pub fn set(&mut self, key: &'static str, value: ParamValue) {
        match self.0.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => slot.1 = value,
            None => self.0.push((key, value)),
        }
    }
}

/// Where the checker reads raw values and how it words its errors: a scene's `[light.shadow]`
/// table (file:line errors) or the plug-in's config (`StageError::Config`).
pub trait ParamSource {
    /// The front end's error.
    type Error;
    /// Whether `key` was given.
    fn present(&self, key: &str) -> bool;
    /// The integer `key` if given, checked against `[lo, hi]`.
    fn int(&self, key: &'static str, lo: i64, hi: i64) -> Result<Option<u32>, Self::Error>;
    /// The number `key` if given, checked against `[lo, hi]`.
    fn float(&self, key: &'static str, lo: f64, hi: f64) -> Result<Option<f32>, Self::Error>;
    /// The option `key` if given, one of `options`.
    fn choice(
        &self,
        key: &'static str,
        options: &'static [&'static str],
    ) -> Result<Option<&'static str>, Self::Error>;
    /// The error for `key` given where it does not apply (`why`).
    fn not_applicable(&self, key: &'static str, why: &str) -> Self::Error;
}

/// Checks what `source` gives against `tables` (in order) and returns every key that applies
/// with its value or its default. A key given where a condition ([`Needs`]) excludes it is an
/// error; a key of several specs takes the first whose conditions hold. Keys the tables do not
/// name are the front end's to refuse (it knows their spelling and position).
pub fn check_params<S: ParamSource>(
    tables: &[&[ParamSpec]],
    source: &S,
) -> Result<ParamValues, S::Error> {
    let specs: Vec<&ParamSpec> = tables.iter().flat_map(|t| t.iter()).collect();
    let mut values = ParamValues::default();
    let mut done: Vec<&str> = Vec::new();
    for spec in &specs {
        if done.contains(&spec.key) {
            continue;
        }
        done.push(spec.key);
        let holds = |s: &ParamSpec| {
            s.needs
                .iter()
                .find(|n| !n.one_of.contains(&values.choice(n.key)))
                .copied()
        };
        let same_key = specs.iter().filter(|s| s.key == spec.key);
        let Some(applies) = same_key.clone().find(|s| holds(s).is_none()) else {
            if source.present(spec.key) {
                let why = holds(spec).map_or("does not apply", |n| n.why);
                return Err(source.not_applicable(spec.key, why));
            }
            continue;
        };
        let value = match applies.kind {
            ParamKind::Int { lo, hi } => source.int(spec.key, lo, hi)?.map(ParamValue::Int),
            ParamKind::Float { lo, hi } => source.float(spec.key, lo, hi)?.map(ParamValue::Float),
            ParamKind::Choice(options) => source.choice(spec.key, options)?.map(ParamValue::Choice),
        };
        let value = value.unwrap_or_else(|| match applies.default {
            ParamDefault::Int(v) => ParamValue::Int(v),
            ParamDefault::Float(v) => ParamValue::Float(v),
            ParamDefault::Choice(v) => ParamValue::Choice(v),
            ParamDefault::Rule(rule) => rule(&values),
        });
        values.set(spec.key, value);
    }
    Ok(values)
}

/// Every key `tables` name, once, in order.
pub fn keys(tables: &[&[ParamSpec]]) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    for spec in tables.iter().flat_map(|t| t.iter()) {
        if !out.contains(&spec.key) {
            out.push(spec.key);
        }
    }
    out
}
