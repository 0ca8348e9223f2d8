//! Every key and word a scene file knows, read from where each is defined once: the tables'
//! keys from the reader's own structs (`format`, by asking serde for their fields), a
//! `[light.shadow]` table's from the technique registry's parameter tables, and the words from
//! the registry's names and choices, the light kinds and the shapes. Tools that write scene
//! files (the fuzzer, generators) take their lists from here, so a new key reaches them.

use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};

use super::format::{
    AnimationFile, CameraFile, KeyFile, LightFile, ObjectFile, OutputFile, SceneFile, ShadowFile,
    TrackFile,
};
use crate::model::{ParamKind, ParamSpec};
use crate::technique::{REGISTRY, params};

/// The light kinds (`kind` of a `[[light]]`).
pub const LIGHT_KINDS: [&str; 3] = ["directional", "spot", "point"];

/// Every key of each table, by the name this module calls the table: `""` is the top level,
/// `shadow` is `[light.shadow]`, `track` `[[animation.track]]` and `key` one of its `keys`. A
/// table's keys are its struct's fields as the reader sees them
/// (renames included); `shadow`'s are `technique` and every key of the registry's tables.
pub fn tables() -> Vec<(&'static str, Vec<&'static str>)> {
    vec![
        ("", fields::<SceneFile>().to_vec()),
        ("output", fields::<OutputFile>().to_vec()),
        ("camera", fields::<CameraFile>().to_vec()),
        ("light", fields::<LightFile>().to_vec()),
        ("shadow", shadow_keys()),
        ("object", fields::<ObjectFile>().to_vec()),
        ("animation", fields::<AnimationFile>().to_vec()),
        ("track", fields::<TrackFile>().to_vec()),
        ("key", fields::<KeyFile>().to_vec()),
    ]
}

/// The keys of a `[light.shadow]` table: `technique`, then every key of the registry's tables
/// (the biases, the cascades, each technique's), once each in that order.
pub fn shadow_keys() -> Vec<&'static str> {
    let mut out = vec!["technique"];
    let tables = [params::COMMON, params::CASCADES]
        .into_iter()
        .chain(REGISTRY.iter().flat_map(|d| d.params.iter().copied()));
    for spec in tables.flat_map(|t| t.iter()) {
        if !out.contains(&spec.key) {
            out.push(spec.key);
        }
    }
    out
}

/// The keys of `[light.shadow]` as its reader's struct declares them (`format::ShadowFile`,
/// written by hand: see [`shadow_keys`] for the registry's).
pub fn shadow_file_keys() -> &'static [&'static str] {
    fields::<ShadowFile>()
}

/// Every word a string key takes: the techniques' names, every option of a choice in the
/// registry's tables, the light kinds and the shapes.
pub fn words() -> Vec<&'static str> {
    let mut out: Vec<&'static str> = REGISTRY.iter().map(|d| d.name).collect();
    let specs = [params::COMMON, params::CASCADES]
        .into_iter()
        .chain(REGISTRY.iter().flat_map(|d| d.params.iter().copied()))
        .flat_map(|t| t.iter());
    let choices = specs.flat_map(|s: &ParamSpec| match s.kind {
        ParamKind::Choice(options) => options,
        _ => &[],
    });
    out.extend(choices);
    out.extend(LIGHT_KINDS);
    out.extend(super::object::SHAPE_KEYS.iter().map(|(shape, _)| *shape));
    let mut seen = Vec::new();
    out.retain(|w| {
        let new = !seen.contains(w);
        seen.push(*w);
        new
    });
    out
}

/// The fields serde's derive declares for `T`: its `deserialize` is handed a deserializer that
/// answers `deserialize_struct` with the field list as its "error".
fn fields<'de, T: Deserialize<'de>>() -> &'static [&'static str] {
    match T::deserialize(Probe) {
        Err(Found(f)) => f,
        Ok(_) => &[],
    }
}

/// What [`Probe`] found: a struct's fields (none for anything else).
#[derive(Debug)]
struct Found(&'static [&'static str]);

impl fmt::Display for Found {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "fields {:?}", self.0)
    }
}

impl std::error::Error for Found {}

impl de::Error for Found {
    fn custom<T: fmt::Display>(_: T) -> Self {
        Found(&[])
    }
}

/// A deserializer that reads nothing and reports the fields a struct asks for.
struct Probe;

impl<'de> Deserializer<'de> for Probe {
    type Error = Found;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Found> {
        Err(Found(&[]))
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Found> {
        Err(Found(fields))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map enum identifier
        ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reader's structs give their keys (renames included), and `[light.shadow]`'s struct
    /// declares exactly the registry's keys: a key added to a technique's table without a field
    /// (or a field left behind) fails here.
    #[test]
    fn the_shadow_tables_fields_are_the_registrys_keys() {
        let t = tables();
        for key in ["ambient", "output", "camera", "light", "object"] {
            assert!(t[0].1.contains(&key), "{key} missing from {:?}", t[0].1);
        }
        assert!(t[3].1.contains(&"shadow_map") && t[5].1.contains(&"rotate_degrees"));
        let mut file: Vec<&str> = shadow_file_keys().to_vec();
        let mut registry = shadow_keys();
        file.sort_unstable();
        registry.sort_unstable();
        assert_eq!(
            file, registry,
            "format::ShadowFile against the registry's tables"
        );
        let w = words();
        for must in [
            "smrt",
            "second_depth",
            "midpoint",
            "receiver_plane",
            "spot",
            "cylinder",
        ] {
            assert!(w.contains(&must), "{must} missing from {w:?}");
        }
    }
}
