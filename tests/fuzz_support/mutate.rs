//! TOML-aware mutations of scene files and line-aware mutations of OBJ meshes (glTF files:
//! `mutate_gltf`).

use std::sync::OnceLock;

use rand::Rng;
use rand::rngs::SmallRng;
use rand::seq::IndexedRandom;
use toml::{Table, Value};

/// Numbers that sit on or past a range's edge, or break f32: extremes, tiny, huge, non-finite.
const NUMBERS: &[f64] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    2.0,
    1e-6,
    1e-7,
    1e6,
    1e7,
    1.0000001e6,
    65536.0,
    65537.0,
    16384.0,
    1e30,
    1e38,
    3.5e38,
    1e39,
    -1e39,
    1e300,
    -1e300,
    1e-30,
    1e-38,
    1e-45,
    1e-50,
    -1e-50,
    5e-324,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MAX,
    f64::MIN_POSITIVE,
    0.001,
    0.99,
    3600.0,
    3601.0,
    170.0,
    1024.0,
];

/// Integers around every integer key's limits.
const INTEGERS: &[i64] = &[
    0,
    -1,
    1,
    2,
    3,
    7,
    8,
    16,
    17,
    32,
    33,
    64,
    256,
    1024,
    1025,
    4096,
    16384,
    16385,
    65536,
    65537,
    i32::MAX as i64,
    u32::MAX as i64,
    1 << 40,
    i64::MAX,
    i64::MIN,
];

/// Every key a scene file knows, by table (`""` is the top level, `shadow` is
/// `[light.shadow]`): the library's own list (`scene::keys`, read from the reader's structs and
/// the technique registry), so a new key is fuzzed as soon as it exists.
pub fn keys() -> &'static [(&'static str, Vec<&'static str>)] {
    static KEYS: OnceLock<Vec<(&'static str, Vec<&'static str>)>> = OnceLock::new();
    KEYS.get_or_init(shadowgraph::low_level::scene::keys::tables)
}

/// The techniques' names (the registry's).
pub fn techniques() -> &'static [&'static str] {
    static NAMES: OnceLock<Vec<&'static str>> = OnceLock::new();
    NAMES.get_or_init(shadowgraph::low_level::technique::names)
}

/// Words the string keys take (the library's: techniques, every choice's options, light kinds,
/// shapes), and some they do not (`JUNK`).
pub fn words() -> &'static [&'static str] {
    static WORDS: OnceLock<Vec<&'static str>> = OnceLock::new();
    WORDS.get_or_init(|| {
        let mut w = shadowgraph::low_level::scene::keys::words();
        w.extend(JUNK);
        w
    })
}

/// Strings no key takes, or that break a line, a path or a file name.
const JUNK: &[&str] = &[
    "",
    " ",
    "PCF",
    "x\ny",
    "é",
    "\u{feff}",
    "\u{0}",
    "m.obj",
    "fuzz.obj",
    "missing.obj",
    "dir.obj",
    "../m.obj",
    "fuzz.gltf",
    "x.glb",
    "/",
    ".",
];

/// The mesh files the fuzzer's folder holds (written by `worker`).
pub const MESH_PATHS: &[&str] = &[
    "fuzz.obj",
    "case.obj",
    "missing.obj",
    "dir.obj",
    "fuzz.gltf",
    "case.gltf",
    "case.glb",
    "missing.glb",
];

/// A random number value: an extreme, or a random one (uniform or log-uniform, either sign).
pub fn number(rng: &mut SmallRng) -> Value {
    match rng.random_range(0..10) {
        0..=4 => Value::Float(*NUMBERS.choose(rng).unwrap_or(&0.0)),
        5..=6 => Value::Integer(*INTEGERS.choose(rng).unwrap_or(&0)),
        7 => Value::Float(rng.random_range(-1e3..1e3)),
        8 => {
            let x = 10f64.powf(rng.random_range(-320.0..320.0));
            Value::Float(if rng.random_bool(0.3) { -x } else { x })
        }
        _ => Value::Integer(rng.random_range(-100..5000)),
    }
}

/// A plausible change of a number: scaled by 0.1–10, sign kept (integers stay integers).
pub fn nearby(v: &Value, rng: &mut SmallRng) -> Value {
    let f = 10f64.powf(rng.random_range(-1.0..1.0));
    match v {
        Value::Integer(i) => Value::Integer((*i as f64 * f).round() as i64),
        Value::Float(x) => Value::Float(if *x == 0.0 { f - 1.0 } else { x * f }),
        other => other.clone(),
    }
}

/// A random value of any type.
pub fn any_value(rng: &mut SmallRng, depth: u32) -> Value {
    match rng.random_range(0..12) {
        0..=3 => number(rng),
        4..=5 => Value::String(words().choose(rng).unwrap_or(&"").to_string()),
        6 => Value::Boolean(rng.random_bool(0.5)),
        7..=9 if depth < 2 => {
            let n = rng.random_range(0..5);
            Value::Array(
                (0..n)
                    .map(|_| {
                        if rng.random_bool(0.8) {
                            number(rng)
                        } else {
                            any_value(rng, depth + 1)
                        }
                    })
                    .collect(),
            )
        }
        10 if depth < 2 => {
            let mut t = Table::new();
            t.insert("a".into(), any_value(rng, depth + 1));
            Value::Table(t)
        }
        _ => number(rng),
    }
}

/// Dotted paths of every value in `t` (array elements as `key.N`).
fn paths(t: &Table, prefix: &str, out: &mut Vec<String>) {
    for (k, v) in t {
        let p = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        out.push(p.clone());
        match v {
            Value::Table(t) => paths(t, &p, out),
            Value::Array(a) => {
                for (i, item) in a.iter().enumerate() {
                    let q = format!("{p}.{i}");
                    out.push(q.clone());
                    if let Value::Table(t) = item {
                        paths(t, &q, out);
                    }
                }
            }
            _ => {}
        }
    }
}

/// Replaces, deletes or renames the value at the dotted `path`.
fn edit(root: &mut Table, path: &str, rng: &mut SmallRng) {
    let steps: Vec<&str> = path.split('.').collect();
    edit_in_table(root, &steps, rng);
}

fn edit_in_table(t: &mut Table, steps: &[&str], rng: &mut SmallRng) {
    match steps {
        [last] => {
            let op = rng.random_range(0..12);
            let numeric = t.get(*last).is_some_and(|v| v.is_float() || v.is_integer());
            match op {
                10..=11 if numeric => {
                    if let Some(v) = t.get_mut(*last) {
                        *v = nearby(v, rng);
                    }
                }
                0..=5 | 10..=11 => {
                    let v = if op < 4 && numeric {
                        number(rng)
                    } else {
                        any_value(rng, 0)
                    };
                    t.insert(last.to_string(), v);
                }
                6..=7 => {
                    t.remove(*last);
                }
                _ => {
                    if let Some(v) = t.remove(*last) {
                        t.insert(random_key(rng), v);
                    }
                }
            }
        }
        [first, rest @ ..] => {
            if let Some(v) = t.get_mut(*first) {
                edit_in_value(v, rest, rng);
            }
        }
        [] => {}
    }
}

fn edit_in_value(v: &mut Value, steps: &[&str], rng: &mut SmallRng) {
    match v {
        Value::Table(t) => edit_in_table(t, steps, rng),
        Value::Array(a) => match steps {
            [last] => {
                let i = last.parse::<usize>().unwrap_or(usize::MAX);
                match rng.random_range(0..12) {
                    10..=11 if i < a.len() => a[i] = nearby(&a[i], rng),
                    0..=5 if i < a.len() => a[i] = number(rng),
                    6..=7 if i < a.len() => {
                        a.remove(i);
                    }
                    _ => a.push(number(rng)),
                }
            }
            [first, rest @ ..] => {
                let item = first.parse::<usize>().ok().and_then(|i| a.get_mut(i));
                if let Some(item) = item {
                    edit_in_value(item, rest, rng);
                }
            }
            [] => {}
        },
        _ => {}
    }
}

fn random_key(rng: &mut SmallRng) -> String {
    let Some((_, keys)) = keys().choose(rng) else {
        return "x".into();
    };
    let k = keys.choose(rng).unwrap_or(&"x").to_string();
    if rng.random_bool(0.1) {
        format!("{k}_")
    } else {
        k
    }
}

/// The tables of `[[light]]`, `[light.shadow]` and `[[object]]` in `root`.
fn tables<'a>(root: &'a mut Table, which: &str) -> Vec<&'a mut Table> {
    let mut out = Vec::new();
    let (array, sub) = match which {
        "shadow" => ("light", Some("shadow")),
        other => (other, None),
    };
    if let Some(Value::Array(items)) = root.get_mut(array) {
        for item in items {
            if let Value::Table(t) = item {
                match sub {
                    Some(s) => {
                        if let Some(Value::Table(st)) = t.get_mut(s) {
                            out.push(st);
                        }
                    }
                    None => out.push(t),
                }
            }
        }
    }
    out
}

/// One structural mutation: values, keys, sections, or a mesh object.
pub fn mutate(root: &mut Table, rng: &mut SmallRng) {
    match rng.random_range(0..20) {
        0..=8 => {
            let mut all = Vec::new();
            paths(root, "", &mut all);
            if let Some(p) = all.choose(rng).cloned() {
                edit(root, &p, rng);
            }
        }
        9..=10 => {
            // A key of a random table with a random value (often one that does not apply).
            let which = ["output", "camera", "light", "shadow", "object"]
                .choose(rng)
                .copied();
            let key = random_key(rng);
            let v = any_value(rng, 0);
            let targets = tables(root, which.unwrap_or("light"));
            if let Some(t) = targets.into_iter().last() {
                t.insert(key, v);
            } else if let Some(Value::Table(t)) = root.get_mut(which.unwrap_or("output")) {
                t.insert(key, v);
            }
        }
        11 => {
            let word = *words().choose(rng).unwrap_or(&"hard");
            let (which, key) = *[
                ("shadow", "technique"),
                ("light", "kind"),
                ("object", "shape"),
            ]
            .choose(rng)
            .unwrap_or(&("shadow", "technique"));
            if let Some(t) = tables(root, which).into_iter().next() {
                t.insert(key.into(), Value::String(word.into()));
            }
        }
        12..=13 => duplicate_or_drop(root, rng),
        14..=15 => {
            // An object made a mesh from one of the fuzz folder's files.
            if let Some(t) = tables(root, "object").into_iter().next() {
                t.retain(|k, _| !matches!(k, "size" | "radius" | "height"));
                t.insert("shape".into(), Value::String("mesh".into()));
                let p = MESH_PATHS.choose(rng).unwrap_or(&"fuzz.obj");
                t.insert("path".into(), Value::String((*p).into()));
            }
        }
        16 => {
            let key = ["output", "camera", "ambient", "light", "object"]
                .choose(rng)
                .copied();
            root.remove(key.unwrap_or("output"));
        }
        17 => {
            let mut t = Table::new();
            t.insert(random_key(rng), any_value(rng, 0));
            root.insert(random_key(rng), Value::Table(t));
        }
        _ => {
            if let Some(t) = tables(root, "light").into_iter().next() {
                let mut s = Table::new();
                s.insert(
                    "technique".into(),
                    Value::String(techniques().choose(rng).unwrap_or(&"hard").to_string()),
                );
                s.insert(random_key(rng), number(rng));
                t.insert("shadow".into(), Value::Table(s));
            }
        }
    }
}

/// Copies or removes `[[light]]`/`[[object]]` tables (many lights exceed device limits).
fn duplicate_or_drop(root: &mut Table, rng: &mut SmallRng) {
    let which = if rng.random_bool(0.5) {
        "light"
    } else {
        "object"
    };
    if let Some(Value::Array(items)) = root.get_mut(which) {
        if items.is_empty() {
            return;
        }
        match rng.random_range(0..4) {
            0 => items.clear(),
            1 => {
                items.remove(rng.random_range(0..items.len()));
            }
            _ => {
                let n = if rng.random_bool(0.2) {
                    rng.random_range(8..40)
                } else {
                    1
                };
                let item = items[rng.random_range(0..items.len())].clone();
                for _ in 0..n {
                    items.push(item.clone());
                }
            }
        }
    }
}

/// Byte-level damage to the serialized text (kept UTF-8): lines dropped or repeated,
/// truncation, stray characters, a byte-order mark.
pub fn damage_text(text: &mut String, rng: &mut SmallRng) {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    match rng.random_range(0..7) {
        0 if !lines.is_empty() => {
            lines.remove(rng.random_range(0..lines.len()));
        }
        1 if !lines.is_empty() => {
            let i = rng.random_range(0..lines.len());
            lines.insert(i, lines[i].clone());
        }
        2 => {
            let mut cut = rng.random_range(0..=text.len());
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            text.truncate(cut);
            return;
        }
        3 if !lines.is_empty() => {
            let i = rng.random_range(0..lines.len());
            let junk = [
                "=",
                "[",
                "]",
                "\"",
                "[[light]]",
                "{",
                "#",
                "\\",
                "'''",
                "0x",
                "é",
            ];
            let j = junk.choose(rng).unwrap_or(&"=");
            let mut at = rng.random_range(0..=lines[i].len());
            while !lines[i].is_char_boundary(at) {
                at -= 1;
            }
            lines[i].insert_str(at, j);
        }
        4 => {
            text.insert(0, '\u{feff}');
            return;
        }
        5 => lines.push(format!("{} = {}", random_key(rng), rng.random_range(-5..5))),
        _ => lines.push("[[light]]".into()),
    }
    *text = lines.join("\n");
}

/// A small valid OBJ (a tetrahedron with normals and texture coordinates).
pub const GOOD_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n\
vn 0 0 -1\nvn 0 -1 0\nvn -1 0 0\nvn 0.577 0.577 0.577\n\
f 1/1/1 3/3/1 2/2/1\nf 1/1/2 2/2/2 4/3/2\nf 1/1/3 4/3/3 3/2/3\nf 2/1/4 3/2/4 4/3/4\n";

/// `GOOD_OBJ` with 1–3 line-level mutations: numbers made extreme, indices broken, corners
/// dropped, lines removed or repeated, garbage, a byte-order mark, or nothing at all.
pub fn mutate_obj(rng: &mut SmallRng) -> String {
    let mut lines: Vec<String> = GOOD_OBJ.lines().map(str::to_string).collect();
    for _ in 0..rng.random_range(1..=3) {
        let i = rng.random_range(0..lines.len().max(1));
        let extreme = [
            "nan", "inf", "-inf", "1e39", "0", "1e-45", "-0", "x", "1e38",
        ];
        let index = [
            "0",
            "-1",
            "-9",
            "9",
            "99999999999",
            "1/",
            "1//9",
            "1/9/1",
            "a",
            "/",
        ];
        match rng.random_range(0..10) {
            0..=2 if i < lines.len() => {
                let mut words: Vec<String> =
                    lines[i].split_whitespace().map(str::to_string).collect();
                if words.len() > 1 {
                    let k = rng.random_range(1..words.len());
                    let pool: &[&str] = if words[0] == "f" { &index } else { &extreme };
                    words[k] = pool.choose(rng).unwrap_or(&"0").to_string();
                }
                lines[i] = words.join(" ");
            }
            3 if i < lines.len() => {
                if let Some(last) = lines[i].rfind(' ') {
                    lines[i].truncate(last);
                }
            }
            4 if i < lines.len() => {
                lines.remove(i);
            }
            5 if i < lines.len() => lines.insert(i, lines[i].clone()),
            6 => lines.push(format!(
                "vn {0} {0} {0}",
                extreme.choose(rng).unwrap_or(&"0")
            )),
            7 => lines.push(
                [
                    "f 1 2",
                    "f",
                    "l 1 2",
                    "g x",
                    "usemtl m",
                    "mtllib m.mtl",
                    "s 1",
                    "o",
                ]
                .choose(rng)
                .unwrap_or(&"f")
                .to_string(),
            ),
            8 => lines.insert(0, "\u{feff}".into()),
            _ => lines.clear(),
        }
    }
    lines.join("\n")
}
