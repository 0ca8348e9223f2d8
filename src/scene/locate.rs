//! Where each key of a scene file is written, and the TOML reader's errors rewritten to name
//! the key (`output.height: expected an integer, found a string`).

use std::collections::HashMap;
use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::ctx::fmt_num;

/// `:line:col` (1-based) of byte `at` in `text`.
pub fn line_col(text: &str, at: usize) -> String {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    format!(":{line}:{col}")
}

/// The dotted path of every key in a scene file (`output.width`, `light[1].shadow.radius`,
/// `light[1]` for the table itself) and where it is written, so that errors found after
/// validation (device limits, memory) point at the key that would fix them.
#[derive(Clone, Debug, Default)]
pub struct Locations {
    spans: Vec<(String, Range<usize>, Range<usize>)>,
    at: HashMap<String, String>,
    /// Keys whose value a command line or a sweep set after the file was read, with what set
    /// them (`evaluate --image 4000x3000`): an error about such a key names that, not the
    /// file's line, which the user did not write.
    set_by: Vec<(String, String)>,
}

impl Locations {
    /// The keys of `text` (empty when it is not valid TOML).
    pub fn of(text: &str) -> Self {
        let mut out = Self::default();
        if let Ok(root) = DeTable::parse(text) {
            out.walk(text, "", root.get_ref());
        }
        out
    }

    fn walk(&mut self, text: &str, prefix: &str, table: &DeTable) {
        for (k, v) in table.iter() {
            let path = if prefix.is_empty() {
                k.get_ref().to_string()
            } else {
                format!("{prefix}.{}", k.get_ref())
            };
            self.add(text, path, k.span(), v);
        }
    }

    fn add(&mut self, text: &str, path: String, key: Range<usize>, v: &Spanned<DeValue>) {
        self.at.insert(path.clone(), line_col(text, key.start));
        self.spans.push((path.clone(), key.clone(), v.span()));
        match v.get_ref() {
            DeValue::Table(t) => self.walk(text, &path, t),
            DeValue::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    let p = format!("{path}[{i}]");
                    // An element of `[[light]]` is located at its own header, not the first one.
                    let start = if matches!(item.get_ref(), DeValue::Table(_)) {
                        header_before(text, item.span().start)
                    } else {
                        item.span().start
                    };
                    self.add(text, p, start..start, item);
                }
            }
            _ => {}
        }
    }

    /// Where the value of `key` comes from, to follow the scene file's path in an error: where
    /// `key` or a key enclosing it was set after reading ([`Locations::set_by`]),
    /// `` (`output.width` from evaluate --image 4000x3000)``; else `:line:col` of `key`, else
    /// of the nearest enclosing key written (`light[0].shadow_map` falls back to `light[0]`),
    /// else empty.
    pub fn get(&self, key: &str) -> String {
        let set = enclosing(key).find_map(|k| self.set_by.iter().rev().find(|(set, _)| set == k));
        match set {
            Some((set, by)) => format!(" (`{set}` from {by})"),
            None => enclosing(key)
                .find_map(|k| self.at.get(k))
                .cloned()
                .unwrap_or_default(),
        }
    }

    /// Records that `key`'s value (and every key under it) was set by `by` after the file was
    /// read, e.g. `("output.width", "evaluate --image 4000x3000")`: [`Locations::get`] then
    /// names `by` instead of the file's line. The latest record for a key wins.
    pub fn set_by(&mut self, key: impl Into<String>, by: impl Into<String>) {
        self.set_by.push((key.into(), by.into()));
    }

    /// The deepest key whose key or value contains `span`.
    pub fn key_at(&self, span: &Range<usize>) -> Option<&str> {
        let inside = |r: &Range<usize>| r.start <= span.start && span.end <= r.end.max(r.start + 1);
        self.spans
            .iter()
            .filter(|(_, k, v)| inside(k) || inside(v))
            .max_by_key(|(p, _, _)| p.len())
            .map(|(p, _, _)| p.as_str())
    }
}

/// `key`, then each key enclosing it, nearest first: `light[0].shadow_map`, `light[0]`,
/// `light`.
fn enclosing(key: &str) -> impl Iterator<Item = &str> {
    std::iter::successors(Some(key), |k| k.rfind(['.', '[']).map(|i| &k[..i]))
}

/// Start of the `[[…]]` header line at or before `at` (an array-of-tables element's span
/// begins at its first key).
fn header_before(text: &str, at: usize) -> usize {
    let at = at.min(text.len());
    let mut line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    loop {
        if text[line_start..].trim_start().starts_with("[[") {
            return line_start + (text[line_start..].len() - text[line_start..].trim_start().len());
        }
        if line_start == 0 {
            return at;
        }
        line_start = text[..line_start - 1].rfind('\n').map_or(0, |i| i + 1);
    }
}

/// The dotted path (`light[1].shadow.radius`, `output` for a table) of the key written at
/// `span` of `text`, read from the text itself: the TOML reader refuses a duplicated key or
/// table before it builds the tree [`Locations`] walks, and says only "duplicate key".
pub fn written_key(text: &str, span: &Range<usize>) -> Option<String> {
    let start = span.start.min(text.len());
    let line_start = text.get(..start)?.rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("").trim_start();
    // The table the key is in: the nearest header above it, with the index of every array of
    // tables (`[[light]]`) on its path counted from the headers before it.
    let mut arrays: HashMap<String, usize> = HashMap::new();
    let mut table = String::new();
    for l in text[..line_start].lines().map(str::trim_start) {
        if let Some(name) = header_name(l) {
            if l.starts_with("[[") {
                *arrays.entry(name.clone()).or_default() += 1;
            }
            table = resolve(&name, &arrays);
        }
    }
    if let Some(name) = header_name(line) {
        // A table written twice (or over an array of tables): its parent with indices.
        return Some(match name.rsplit_once('.') {
            Some((parent, last)) => format!("{}.{last}", resolve(parent, &arrays)),
            None => name,
        });
    }
    let key = line.split('=').next()?;
    let key: Vec<&str> = key
        .split('.')
        .map(|k| k.trim().trim_matches(['"', '\'']))
        .collect();
    let key = key.join(".");
    match (key.is_empty(), table.is_empty()) {
        (true, _) => None,
        (false, true) => Some(key),
        (false, false) => Some(format!("{table}.{key}")),
    }
}

/// `light.shadow` of a header line `[light.shadow]` or `[[light]]` (comments after it dropped).
fn header_name(line: &str) -> Option<String> {
    let inner = line.strip_prefix('[')?;
    let inner = inner.strip_prefix('[').unwrap_or(inner);
    let name = &inner[..inner.find(']')?];
    let parts: Vec<&str> = name
        .split('.')
        .map(|k| k.trim().trim_matches(['"', '\'']))
        .collect();
    Some(parts.join("."))
}

/// A header's dotted name with the current element of each array of tables on its path:
/// `light.shadow` after two `[[light]]` is `light[1].shadow`.
fn resolve(name: &str, arrays: &HashMap<String, usize>) -> String {
    let mut out = String::new();
    let mut prefix = String::new();
    for part in name.split('.') {
        if !prefix.is_empty() {
            prefix.push('.');
            out.push('.');
        }
        prefix.push_str(part);
        out.push_str(part);
        if let Some(n) = arrays.get(&prefix) {
            out.push_str(&format!("[{}]", n.saturating_sub(1)));
        }
    }
    out
}

/// The TOML reader's message made one line that names `key`, in the scene's own words:
/// serde's `invalid type: string "x", expected i64` becomes
/// `expected an integer, found a string "x"`; numbers print with [`fmt_num`].
pub fn rewrite(message: &str, key: Option<&str>) -> String {
    let message = message.trim().replace(['\n', '\r'], " ");
    let said = if let Some(rest) = message.strip_prefix("invalid type: ") {
        match rest.rsplit_once(", expected ") {
            Some((found, expected)) => {
                format!(
                    "expected {}, found {}",
                    expected_name(expected),
                    found_name(found)
                )
            }
            None => message.clone(),
        }
    } else if let Some(rest) = message.strip_prefix("invalid length ") {
        match rest.split_once(", expected ") {
            Some((n, expected)) => format!(
                "expected {}, found {n} element{}",
                expected_name(expected),
                if n == "1" { "" } else { "s" }
            ),
            None => message.clone(),
        }
    } else if message.starts_with("data did not match any variant of untagged enum Num") {
        "expected a number or a list of numbers".to_string()
    } else if let Some(rest) = message.strip_prefix("unknown field ") {
        format!("unknown key {rest}")
    } else if let Some(rest) = message.strip_prefix("missing field ") {
        format!("missing key {rest}")
    } else {
        message.clone()
    };
    match key {
        Some(k) if !k.is_empty() => format!("`{k}`: {said}"),
        _ => said,
    }
}

fn expected_name(expected: &str) -> String {
    match expected {
        "i64" | "u32" | "u64" | "i32" => "an integer".into(),
        "f64" | "f32" => "a number".into(),
        "a string" | "a borrowed string" => "a string".into(),
        "a sequence" => "an array".into(),
        "an array of length 3" => "an array of 3 numbers".into(),
        e if e.starts_with("struct ") => "a table".into(),
        e => e.into(),
    }
}

fn found_name(found: &str) -> String {
    // serde quotes the number in backticks, sometimes with a suffix (`` `1e22` as i128 ``).
    let number = |s: &str| {
        let s = s.split('`').find(|p| !p.is_empty()).unwrap_or(s);
        match s.parse::<f64>() {
            Ok(x) if s.len() > 20 => fmt_num(x),
            _ => s.to_string(),
        }
    };
    if let Some(s) = found.strip_prefix("string ") {
        format!("a string {}", clip(s))
    } else if let Some(n) = found.strip_prefix("floating point ") {
        format!("a decimal number ({})", number(n))
    } else if let Some(n) = found.strip_prefix("integer ") {
        let big = n.ends_with("as i128") || n.ends_with("as u128");
        let what = if big {
            "an integer too large"
        } else {
            "an integer"
        };
        format!("{what} ({})", number(n))
    } else if let Some(b) = found.strip_prefix("boolean ") {
        format!("a boolean ({})", b.trim_matches('`'))
    } else if found == "map" {
        "a table".into()
    } else if found == "sequence" {
        "an array".into()
    } else {
        clip(found)
    }
}

/// At most 40 characters of a quoted value.
fn clip(s: &str) -> String {
    if s.chars().count() <= 40 {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(40).collect::<String>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_and_locations() {
        let text = "a = 1\n[output]\nwidth = 3\n\n[[light]]\nkind = \"x\"\n[light.shadow]\n\
                    technique = \"pcf\"\n[[light]]\nkind = \"y\"\n";
        let l = Locations::of(text);
        assert_eq!(l.get("output.width"), ":3:1");
        assert_eq!(l.get("light[0]"), ":5:1");
        assert_eq!(l.get("light[1]"), ":9:1");
        assert_eq!(l.get("light[0].shadow.technique"), ":8:1");
        assert_eq!(l.get("light[1].shadow_map"), ":9:1");
        assert_eq!(l.get("nothing.here"), "");
        let at = text.find("\"y\"").unwrap();
        assert_eq!(l.key_at(&(at..at + 3)), Some("light[1].kind"));
    }

    /// A key set after reading is named with what set it, and so are the keys under it; its
    /// neighbours keep their lines, and the latest setter wins.
    #[test]
    fn keys_set_after_reading_name_their_setter() {
        let text = "[output]\nwidth = 3\nheight = 2\n[[light]]\nshadow_map = 64\n\
                    [light.shadow]\ntechnique = \"pcf\"\n";
        let mut l = Locations::of(text);
        l.set_by("output.width", "--image 9x9");
        l.set_by("light[0].shadow", "configuration `a`");
        l.set_by("light[0].shadow", "configuration `b`");
        assert_eq!(l.get("output.width"), " (`output.width` from --image 9x9)");
        assert_eq!(l.get("output.height"), ":3:1");
        assert_eq!(
            l.get("light[0].shadow.technique"),
            " (`light[0].shadow` from configuration `b`)"
        );
        assert_eq!(l.get("light[0].shadow_map"), ":5:1");
    }

    #[test]
    fn serde_messages_name_the_key() {
        assert_eq!(
            rewrite(
                "invalid type: string \"x\", expected i64",
                Some("output.height")
            ),
            "`output.height`: expected an integer, found a string \"x\""
        );
        assert_eq!(
            rewrite(
                "invalid type: floating point `0.00000000000000000000000000000000000000000000000000000000001`, expected i64",
                Some("output.width")
            ),
            "`output.width`: expected an integer, found a decimal number (1e-59)"
        );
        assert_eq!(
            rewrite(
                "invalid length 2, expected an array of length 3",
                Some("camera.target")
            ),
            "`camera.target`: expected an array of 3 numbers, found 2 elements"
        );
    }
}
