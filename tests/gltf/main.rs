//! glTF 2.0 meshes (`shape = "mesh"` with a `.gltf` or `.glb` path): small files written here
//! by hand load to the triangles, normals and node transforms worked out by hand (external,
//! `data:` and GLB buffers alike; missing normals computed, NaN normals repaired and warned,
//! mirrored nodes keep their faces' outward side); malformed files (missing or short buffer,
//! bad accessor, out-of-range index, non-triangle mode, NaN position, cycles, damaged GLB, …)
//! are one-line errors naming the glTF file, and through a scene its file, line and key.
//! The bundled canopy is checked against its generator in `tests/procedural_scenes.rs`.

use std::path::{Path, PathBuf};

use base64::Engine;
use glam::Vec3;
use serde_json::{Value, json};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::scene::gltf::load_gltf;

mod loading;
mod malformed;

/// A folder of its own per test.
fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-gltf-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A unit quad in XZ at y = 0 (counter-clockwise seen from +Y), its normals +Y and u16
/// indices, as one buffer: 48 bytes of positions, 48 of normals, 12 of indices.
fn quad_bytes(normal: [f32; 3]) -> Vec<u8> {
    let p: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ];
    let mut b: Vec<u8> = p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    for _ in 0..4 {
        b.extend(normal.iter().flat_map(|x| x.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

fn data_uri(bytes: &[u8]) -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// The quad's document: one node (translated by [1, 2, 3]) holding mesh 0, its buffer in
/// `uri` (views: positions, normals, indices).
fn quad_doc(uri: &str) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [1.0, 2.0, 3.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 0.0, 1.0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 12}
        ],
        "buffers": [{"uri": uri, "byteLength": 108}]
    })
}

/// Writes `doc` as `name` in the test's folder (and `bin`, if given, as `quad.bin`).
fn write(tag: &str, name: &str, doc: &Value, bin: Option<&[u8]>) -> PathBuf {
    let d = dir(tag);
    if let Some(bin) = bin {
        std::fs::write(d.join("quad.bin"), bin).unwrap();
    }
    let path = d.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(doc).unwrap()).unwrap();
    path
}

/// `json` and `bin` as a GLB (buffer 0 the binary chunk).
fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = json.clone();
    json["buffers"][0].as_object_mut().unwrap().remove("uri");
    let text = serde_json::to_vec(&json).unwrap();
    gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: text.into(),
        bin: Some(bin.into()),
    }
    .to_vec()
    .unwrap()
}

#[track_caller]
fn near(a: Vec3, b: Vec3, what: &str) {
    assert!(
        (a - b).abs().max_element() < 1e-6,
        "{what}: {a} against {b}"
    );
}

/// A scene whose second object is the mesh at `path`, with `extra` keys.
fn scene_with(path: &Path, extra: &str) -> Scene {
    let text = scene_text(path, extra);
    Scene::parse(&path.with_extension("toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

fn scene_text(path: &Path, extra: &str) -> String {
    format!(
        "[output]\nwidth = 16\nheight = 12\n\n[camera]\nposition = [0.0, 2.0, 4.0]\n\
         target = [0.0, 0.0, 0.0]\nfov_y_degrees = 50.0\n\n[[light]]\nkind = \"directional\"\n\
         position = [-2.0, 5.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nextent = 3.0\nshadow_map = 64\n\n\
         [[object]]\nshape = \"plane\"\nsize = 6.0\n\n[[object]]\nshape = \"mesh\"\n\
         path = \"{}\"\n{extra}",
        path.file_name().unwrap().to_string_lossy()
    )
}
