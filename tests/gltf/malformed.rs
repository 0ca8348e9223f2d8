//! Malformed files, damaged containers and odd paths: one-line errors naming the file.

use super::*;

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
