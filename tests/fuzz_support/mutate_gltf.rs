//! Mutations of a small glTF file: JSON values replaced by extremes or other types, keys and
//! array elements dropped or repeated, the buffer's bytes overwritten (NaN, huge and
//! out-of-range numbers) or cut short, node cycles, the text truncated; written as `.gltf`
//! (buffer as a `data:` URI) or packed into a `.glb` whose header may be damaged.

use base64::Engine;
use rand::Rng;
use rand::rngs::SmallRng;
use rand::seq::IndexedRandom;
use serde_json::{Value, json};

/// A tetrahedron: 4 positions and normals, 12 u16 indices, one node translated.
fn good_parts() -> (Value, Vec<u8>) {
    let p: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut bin: Vec<u8> = p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    let n: [[f32; 3]; 4] = [
        [-0.577, -0.577, -0.577],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    bin.extend(n.iter().flatten().flat_map(|x| x.to_le_bytes()));
    for i in [0u16, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1], "scale": [1.0, 1.0, 1.0]},
                  {"mesh": 0, "translation": [0.0, 0.5, 0.0], "rotation": [0.0, 0.0, 0.0, 1.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
                                    "mode": 4}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 12, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 24}
        ],
        "buffers": [{"byteLength": 120}]
    });
    (doc, bin)
}

fn with_data_uri(mut doc: Value, bin: &[u8]) -> Value {
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bin)
    );
    if let Some(Value::Object(b)) = doc.pointer_mut("/buffers/0") {
        b.insert("uri".into(), Value::String(uri));
    }
    doc
}

/// The unmutated tetrahedron as `.gltf` text.
pub fn good_gltf() -> String {
    let (doc, bin) = good_parts();
    with_data_uri(doc, &bin).to_string()
}

/// Values that break glTF's integers and floats.
const EXTREMES: &[f64] = &[
    0.0,
    -1.0,
    1.0,
    2.0,
    3.0,
    4.0,
    5.0,
    7.0,
    255.0,
    65535.0,
    65536.0,
    2147483648.0,
    4294967296.0,
    9007199254740992.0,
    1e39,
    -1e39,
    1e-45,
    0.5,
    1e300,
];

/// Every path to a value in `v` (object keys and array indices).
fn paths(v: &Value, here: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    out.push(here.clone());
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                here.push(Value::String(k.clone()));
                paths(x, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                here.push(json!(i));
                paths(x, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Value]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, step| match step {
        Value::String(k) => v.get_mut(k.as_str()),
        Value::Number(i) => i.as_u64().and_then(|i| v.get_mut(i as usize)),
        _ => None,
    })
}

/// One mutation of the document or its buffer.
fn mutate(doc: &mut Value, bin: &mut Vec<u8>, rng: &mut SmallRng) {
    let mut all = Vec::new();
    paths(doc, &mut Vec::new(), &mut all);
    let path = all.choose(rng).cloned().unwrap_or_default();
    match rng.random_range(0..8) {
        0..=2 => {
            if let Some(v) = at(doc, &path) {
                *v = match rng.random_range(0..6) {
                    0..=2 => json!(EXTREMES.choose(rng).copied().unwrap_or(0.0)),
                    3 => json!("x"),
                    4 => Value::Null,
                    _ => json!([]),
                };
            }
        }
        3 => {
            // Drop the value at the path from its parent.
            if let Some((last, parent)) = path.split_last() {
                match (at(doc, parent), last) {
                    (Some(Value::Object(m)), Value::String(k)) => {
                        m.remove(k);
                    }
                    (Some(Value::Array(a)), Value::Number(i)) => {
                        if let Some(i) = i.as_u64().filter(|&i| (i as usize) < a.len()) {
                            a.remove(i as usize);
                        }
                    }
                    _ => {}
                }
            }
        }
        4 => {
            // Overwrite four bytes of the buffer: NaN, infinity, a huge float or index.
            let word: [u8; 4] = *[
                f32::NAN.to_le_bytes(),
                f32::INFINITY.to_le_bytes(),
                3e38f32.to_le_bytes(),
                [0xff, 0xff, 0xff, 0xff],
                [9, 0, 9, 0],
            ]
            .choose(rng)
            .unwrap_or(&[0; 4]);
            if bin.len() >= 4 {
                let k = rng.random_range(0..=bin.len() - 4);
                bin[k..k + 4].copy_from_slice(&word);
            }
        }
        5 => bin.truncate(rng.random_range(0..=bin.len())),
        // A node cycle or another primitive mode, where earlier mutations left the place
        // (`Value`'s `IndexMut` would panic on a replaced parent).
        6 => {
            if let Some(Value::Object(n)) = doc.pointer_mut("/nodes/1") {
                n.insert("children".into(), json!([rng.random_range(0..3)]));
            }
        }
        _ => {
            if let Some(Value::Object(p)) = doc.pointer_mut("/meshes/0/primitives/0") {
                p.insert("mode".into(), json!(rng.random_range(0..8)));
            }
        }
    }
}

/// A mutated glTF: `("case.gltf", text)` or `("case.glb", bytes)`.
pub fn mutate_gltf(rng: &mut SmallRng) -> (&'static str, Vec<u8>) {
    let (mut doc, mut bin) = good_parts();
    // None a quarter of the time: valid files must also reach the renderer.
    for _ in 0..rng.random_range(0..=3) {
        mutate(&mut doc, &mut bin, rng);
    }
    if rng.random_bool(0.5) {
        let mut text = with_data_uri(doc, &bin).to_string().into_bytes();
        if rng.random_bool(0.1) {
            text.truncate(rng.random_range(0..=text.len()));
        }
        return ("case.gltf", text);
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: doc.to_string().into_bytes().into(),
        bin: Some(bin.into()),
    };
    let mut bytes = glb.to_vec().unwrap_or_default();
    match rng.random_range(0..10) {
        0 if bytes.len() >= 12 => bytes[8..12].copy_from_slice(&rng.random::<u32>().to_le_bytes()),
        1 => bytes.truncate(rng.random_range(0..=bytes.len())),
        2 if bytes.len() >= 16 => bytes[12..16].copy_from_slice(&rng.random::<u32>().to_le_bytes()),
        _ => {}
    }
    ("case.glb", bytes)
}
