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

#[test]
fn external_data_uri_and_glb_buffers_load_the_same_quad() {
    let bytes = quad_bytes([0.0, 1.0, 0.0]);
    let doc = quad_doc("quad.bin");
    let external = write("ext", "quad.gltf", &doc, Some(&bytes));
    let embedded = write("data", "quad.gltf", &quad_doc(&data_uri(&bytes)), None);
    let binary = dir("glb").join("quad.glb");
    std::fs::write(&binary, glb(&doc, &bytes)).unwrap();
    // The extension decides the loader, in any case.
    let upper = dir("upper").join("QUAD.GLB");
    std::fs::write(&upper, glb(&doc, &bytes)).unwrap();
    for path in [&external, &embedded, &binary, &upper] {
        let what = path.display().to_string();
        let m = load_gltf(path)
            .unwrap_or_else(|e| panic!("{what}: {e}"))
            .mesh;
        assert_eq!(m.indices, [0, 1, 2, 0, 2, 3], "{what}");
        // The node's translation, applied.
        let want = [
            [1.0, 2.0, 3.0],
            [1.0, 2.0, 4.0],
            [2.0, 2.0, 4.0],
            [2.0, 2.0, 3.0],
        ];
        for (p, w) in m.positions.iter().zip(want) {
            near(*p, Vec3::from(w), &what);
        }
        assert!(m.normals.iter().all(|&n| n == Vec3::Y), "{what}");
        let s = scene_with(path, "");
        assert_eq!(s.objects[1].mesh.indices.len(), 6);
    }
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

#[test]
fn missing_normals_are_computed_and_nan_normals_repaired_with_a_warning() {
    let mut doc = quad_doc(&data_uri(&quad_bytes([0.0, 1.0, 0.0])));
    doc["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .unwrap()
        .remove("NORMAL");
    let path = write("nonormal", "q.gltf", &doc, None);
    let loaded = load_gltf(&path).unwrap();
    assert_eq!(loaded.repaired_normals, 0, "absent normals are not repairs");
    // Counter-clockwise seen from +Y: the computed normal is +Y.
    for n in &loaded.mesh.normals {
        near(*n, Vec3::Y, "computed normal");
    }

    let path = write(
        "nan",
        "q.gltf",
        &quad_doc(&data_uri(&quad_bytes([f32::NAN; 3]))),
        None,
    );
    let loaded = load_gltf(&path).unwrap();
    assert_eq!(loaded.repaired_normals, 4);
    let s = scene_with(&path, "");
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("object[1].path") && w.contains("4 normal(s)")),
        "no warning: {:?}",
        s.warnings
    );
    for n in &s.objects[1].mesh.normals {
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-5, "{n}");
    }
}

#[test]
fn node_hierarchies_matrices_and_mirrors_transform_as_worked_out_by_hand() {
    let bytes = quad_bytes([0.0, 1.0, 0.0]);
    let mut doc = quad_doc(&data_uri(&bytes));
    // Root: translate (10, 0, 0); child: turn 90 degrees about +Y (x → −z), scale 2; its child
    // (as a matrix): mirror x. Scene 1 is the default, scene 0 unused.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    doc["nodes"] = json!([
        {"translation": [10.0, 0.0, 0.0], "children": [1]},
        {"rotation": [0.0, h, 0.0, h], "scale": [2.0, 2.0, 2.0], "mesh": 0, "children": [2]},
        {"matrix": [-1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0],
         "mesh": 0},
        {"mesh": 0, "translation": [99.0, 0.0, 0.0]}
    ]);
    doc["scenes"] = json!([{"nodes": [3]}, {"nodes": [0]}]);
    doc["scene"] = json!(1);
    let path = write("nodes", "q.gltf", &doc, None);
    let m = load_gltf(&path).unwrap().mesh;
    assert_eq!(
        m.positions.len(),
        8,
        "two instances, scene 0's node skipped"
    );
    // (x, y, z) → rotate: (z, y, −x) → scale 2 → translate: (10 + 2z, 2y, −2x).
    let rotated = |x: f32, z: f32| Vec3::new(10.0 + 2.0 * z, 0.0, -2.0 * x);
    let quad = [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)];
    for (k, (x, z)) in quad.iter().enumerate() {
        near(m.positions[k], rotated(*x, *z), "rotated instance");
        near(m.positions[4 + k], rotated(-*x, *z), "mirrored instance");
    }
    // The mirrored instance's winding is reversed, so its computed and given normals agree
    // with its geometry: the face normal of each triangle as loaded points +Y.
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
        let face = (b - a).cross(c - a).normalize();
        near(face, Vec3::Y, "winding");
        near(m.normals[t[0] as usize], Vec3::Y, "normal");
    }
}

#[test]
fn non_indexed_and_u8_u32_indexed_primitives_load() {
    let bytes = quad_bytes([0.0, 1.0, 0.0]);
    // Non-indexed: the first three vertices.
    let mut doc = quad_doc(&data_uri(&bytes));
    doc["meshes"][0]["primitives"][0]
        .as_object_mut()
        .unwrap()
        .remove("indices");
    doc["accessors"][0]["count"] = json!(3);
    doc["accessors"][1]["count"] = json!(3);
    let m = load_gltf(&write("noindex", "q.gltf", &doc, None))
        .unwrap()
        .mesh;
    assert_eq!(m.indices, [0, 1, 2]);
    // u8 and u32 indices in a buffer of their own.
    for (tag, ty, idx) in [
        (
            "u8",
            5121,
            [0u8, 2, 3]
                .iter()
                .flat_map(|i| i.to_le_bytes())
                .collect::<Vec<u8>>(),
        ),
        (
            "u32",
            5125,
            [0u32, 2, 3].iter().flat_map(|i| i.to_le_bytes()).collect(),
        ),
    ] {
        let mut doc = quad_doc(&data_uri(&bytes));
        doc["buffers"]
            .as_array_mut()
            .unwrap()
            .push(json!({"uri": data_uri(&idx), "byteLength": idx.len()}));
        doc["bufferViews"][2] = json!({"buffer": 1, "byteLength": idx.len()});
        doc["accessors"][2] =
            json!({"bufferView": 2, "componentType": ty, "count": 3, "type": "SCALAR"});
        let m = load_gltf(&write(tag, "q.gltf", &doc, None)).unwrap().mesh;
        assert_eq!(m.indices, [0, 2, 3], "{tag}");
    }
}

/// One malformation: a name, an edit of the quad's document (or of its files), and words the
/// one-line error must hold.
struct Case {
    name: &'static str,
    edit: fn(&mut Value, &mut Vec<u8>),
    expect: &'static [&'static str],
}

fn cases() -> Vec<Case> {
    fn prim(d: &mut Value) -> &mut Value {
        &mut d["meshes"][0]["primitives"][0]
    }
    vec![
        Case {
            name: "missing buffer file",
            edit: |d, _| d["buffers"][0]["uri"] = json!("gone.bin"),
            expect: &["buffer 0", "gone.bin", "not found"],
        },
        Case {
            name: "short buffer",
            edit: |_, b| b.truncate(100),
            expect: &["buffer 0 holds 100 bytes", "byteLength"],
        },
        Case {
            name: "accessor past its view",
            edit: |d, _| d["accessors"][0]["count"] = json!(9),
            expect: &[
                "POSITION (accessor 0)",
                "reach past buffer view 0's 48 bytes",
            ],
        },
        Case {
            name: "view past its buffer",
            edit: |d, _| d["bufferViews"][2]["byteLength"] = json!(40),
            expect: &[
                "buffer view 2 (bytes 96 to 136)",
                "past buffer 0's 108 bytes",
            ],
        },
        Case {
            name: "huge accessor count",
            edit: |d, _| d["accessors"][2]["count"] = json!(1u64 << 62),
            expect: &["indices (accessor 2)", "reach past"],
        },
        Case {
            name: "wrong accessor type",
            edit: |d, _| d["accessors"][0]["type"] = json!("SCALAR"),
            expect: &["POSITION (accessor 0) is SCALAR of FLOAT, expected VEC3 of FLOAT"],
        },
        Case {
            name: "float indices",
            edit: |d, _| d["accessors"][2]["componentType"] = json!(5126),
            expect: &["indices (accessor 2) is SCALAR of FLOAT", "UNSIGNED_SHORT"],
        },
        Case {
            name: "index out of range",
            edit: |_, b| b[104] = 7,
            expect: &["index 7", "out of range", "4 vertices"],
        },
        Case {
            name: "lines",
            edit: |d, _| prim(d)["mode"] = json!(1),
            expect: &["mode 1 (LINES) is not supported", "only triangle lists"],
        },
        Case {
            name: "triangle strip",
            edit: |d, _| prim(d)["mode"] = json!(5),
            expect: &["mode 5 (TRIANGLE_STRIP)"],
        },
        Case {
            name: "NaN position",
            edit: |_, b| b[12..16].copy_from_slice(&f32::NAN.to_le_bytes()),
            expect: &["POSITION (accessor 0) element 1 is not finite"],
        },
        Case {
            name: "infinite translation",
            edit: |d, _| d["nodes"][0]["translation"] = json!([1e39, 0.0, 0.0]),
            expect: &["node 0", "not finite"],
        },
        Case {
            name: "zero quaternion",
            edit: |d, _| d["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 0.0]),
            expect: &["node 0's rotation", "unit quaternion"],
        },
        Case {
            name: "cycle",
            edit: |d, _| d["nodes"][0]["children"] = json!([0]),
            expect: &["node 0 appears twice"],
        },
        Case {
            name: "no POSITION",
            edit: |d, _| {
                prim(d)["attributes"]
                    .as_object_mut()
                    .unwrap()
                    .remove("POSITION");
            },
            expect: &["`meshes[0].primitives[0].attributes[\"POSITION\"]`: Missing data"],
        },
        Case {
            name: "sparse",
            edit: |d, _| d["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": 2, "componentType": 5123}, "values": {"bufferView": 0}}),
            expect: &["sparse"],
        },
        Case {
            name: "no buffer view",
            edit: |d, _| {
                d["accessors"][0]
                    .as_object_mut()
                    .unwrap()
                    .remove("bufferView");
            },
            expect: &["`accessors[0].bufferView`: Missing data"],
        },
        Case {
            name: "zero count",
            edit: |d, _| d["accessors"][2]["count"] = json!(0),
            expect: &["no elements"],
        },
        Case {
            name: "partial triangle",
            edit: |d, _| d["accessors"][2]["count"] = json!(4),
            expect: &["4 indices do not make whole triangles"],
        },
        Case {
            name: "normal count",
            edit: |d, _| d["accessors"][1]["count"] = json!(3),
            expect: &["NORMAL (accessor 1) has 3 elements"],
        },
        Case {
            name: "dangling reference",
            edit: |d, _| prim(d)["indices"] = json!(7),
            expect: &["invalid glTF", "indices"],
        },
        // gltf-json 1.4.1 indexes `accessors` with POSITION before checking it (found by
        // `examples/fuzz_scenes.rs`: a panic).
        Case {
            name: "dangling POSITION",
            edit: |d, _| prim(d)["attributes"]["POSITION"] = json!(9),
            expect: &[
                "`meshes[0].primitives[0].attributes[\"POSITION\"]`",
                "refers to accessor 9, but the file has 3 accessors",
            ],
        },
        Case {
            name: "no accessors",
            edit: |d, _| {
                d.as_object_mut().unwrap().remove("accessors");
            },
            expect: &["refers to accessor 0, but the file has 0 accessors"],
        },
        Case {
            name: "no scene",
            edit: |d, _| {
                let o = d.as_object_mut().unwrap();
                o.remove("scene");
                o.remove("scenes");
            },
            expect: &["no scene"],
        },
        Case {
            name: "http buffer",
            edit: |d, _| d["buffers"][0]["uri"] = json!("https://example.com/q.bin"),
            expect: &["only `data:` URIs"],
        },
        Case {
            name: "data URI not base64",
            edit: |d, _| d["buffers"][0]["uri"] = json!("data:text/plain,abc"),
            expect: &["not base64"],
        },
        Case {
            name: "bad base64",
            edit: |d, _| {
                d["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@")
            },
            expect: &["bad base64"],
        },
        Case {
            name: "bad percent escape",
            edit: |d, _| d["buffers"][0]["uri"] = json!("q%zz.bin"),
            expect: &["%"],
        },
        // Indices past 2³², which the gltf crate wraps modulo 2³² (4294967297: view 1, the normals).
        Case {
            name: "wide bufferView",
            edit: |d, _| d["accessors"][0]["bufferView"] = json!(4_294_967_297u64),
            expect: &["`accessors[0].bufferView` = 4294967297", "not an index"],
        },
        Case {
            name: "wide scene node",
            edit: |d, _| d["scenes"][0]["nodes"][0] = json!(1u64 << 32),
            expect: &["`scenes[0].nodes[0]` = 4294967296"],
        },
        Case {
            name: "wide node mesh",
            edit: |d, _| d["nodes"][0]["mesh"] = json!(1u64 << 32),
            expect: &["`nodes[0].mesh`"],
        },
        Case {
            name: "wide indices",
            edit: |d, _| prim(d)["indices"] = json!((1u64 << 32) + 2),
            expect: &["`meshes[0].primitives[0].indices`"],
        },
        Case {
            name: "wide buffer",
            edit: |d, _| d["bufferViews"][1]["buffer"] = json!(u64::MAX),
            expect: &["`bufferViews[1].buffer`", "18446744073709551615"],
        },
        Case {
            name: "wide attribute",
            edit: |d, _| prim(d)["attributes"]["NORMAL"] = json!((1u64 << 32) + 1),
            expect: &["`meshes[0].primitives[0].attributes.NORMAL`"],
        },
    ]
}

/// Every malformation is refused with one line naming the glTF file, and through a scene with
/// one line naming the scene file, the `path` key's line and the glTF file.
#[test]
fn malformed_gltf_files_are_one_line_errors_naming_the_file() {
    for (k, case) in cases().into_iter().enumerate() {
        let mut doc = quad_doc("quad.bin");
        let mut bin = quad_bytes([0.0, 1.0, 0.0]);
        (case.edit)(&mut doc, &mut bin);
        let path = write(&format!("bad{k}"), "broken.gltf", &doc, Some(&bin));
        let e = match load_gltf(&path) {
            Ok(m) => panic!(
                "{}: accepted ({} triangles)",
                case.name,
                m.mesh.indices.len() / 3
            ),
            Err(e) => e,
        };
        assert!(!e.contains('\n'), "{}: more than one line: {e}", case.name);
        assert!(
            e.contains("broken.gltf"),
            "{}: does not name the file: {e}",
            case.name
        );
        for word in case.expect {
            assert!(
                e.contains(word),
                "{}: `{word}` missing from: {e}",
                case.name
            );
        }
        let text = scene_text(&path, "");
        let scene_path = path.with_file_name("s.toml");
        let e = Scene::parse(&scene_path, &text)
            .expect_err(case.name)
            .to_string();
        let line = text.lines().position(|l| l.starts_with("path =")).unwrap() + 1;
        assert!(
            !e.contains('\n')
                && e.contains(&format!("s.toml:{line}:"))
                && e.contains("object[1].path")
                && e.contains("broken.gltf"),
            "{}: scene error: {e}",
            case.name
        );
    }
}

#[test]
fn damaged_containers_and_odd_paths_are_one_line_errors() {
    let bytes = quad_bytes([0.0, 1.0, 0.0]);
    let good = glb(&quad_doc(""), &bytes);
    let mut lying = good.clone();
    lying[8..12].copy_from_slice(&5u32.to_le_bytes());
    let mut long = good.clone();
    long[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    let mut no_bin = quad_doc("");
    no_bin["buffers"][0].as_object_mut().unwrap().remove("uri");
    let no_bin = serde_json::to_vec(&no_bin).unwrap();
    let files: [(&str, &str, Vec<u8>, &str); 7] = [
        ("truncated glb", "t.glb", good[..40].to_vec(), "t.glb"),
        (
            "glb length under its header",
            "l.glb",
            lying,
            "header declares 5 bytes",
        ),
        (
            "glb length past the file",
            "p.glb",
            long,
            "declares 4294967295 bytes",
        ),
        (
            "bare magic",
            "m.glb",
            b"glTF".to_vec(),
            "truncated GLB header",
        ),
        (
            "not JSON",
            "n.gltf",
            b"{\"asset\": [1, 2".to_vec(),
            "not valid glTF JSON",
        ),
        ("empty", "e.gltf", Vec::new(), "not valid glTF JSON"),
        ("no binary chunk", "b.gltf", no_bin, "no GLB binary chunk"),
    ];
    let d = dir("containers");
    for (what, name, bytes, expect) in files {
        let path = d.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = load_gltf(&path).expect_err(what);
        assert!(
            !e.contains('\n') && e.contains(name) && e.contains(expect),
            "{what}: {e}"
        );
    }
    let e = load_gltf(&d).expect_err("a directory");
    assert!(e.contains("is a directory"), "{e}");
    let e = load_gltf(&d.join("absent.glb")).expect_err("missing");
    assert!(e.contains("not found") && e.contains("absent.glb"), "{e}");
}

/// A GLB's JSON chunk is checked as a `.gltf` file is: an index past 2³² (which the gltf crate
/// wraps to view 1, the normals, read as positions) is refused naming its JSON path.
#[test]
fn wide_indices_in_a_glb_are_refused() {
    let mut doc = quad_doc("quad.bin");
    doc["accessors"][0]["bufferView"] = json!(4_294_967_297u64);
    let path = dir("wideglb").join("wide.glb");
    std::fs::write(&path, glb(&doc, &quad_bytes([0.0, 1.0, 0.0]))).unwrap();
    let e = load_gltf(&path).map(|_| ()).expect_err("a wide index");
    assert!(
        e.contains("wide.glb") && e.contains("`accessors[0].bufferView` = 4294967297"),
        "{e}"
    );
}
