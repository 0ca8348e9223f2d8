//! Well-formed files load to the triangles, normals and transforms worked out by hand.

use super::*;

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
