//! glTF 2.0 meshes (`.gltf` with external or `data:` buffers, and `.glb`): every triangle
//! primitive of every mesh in the default scene, under its node's transform, as one mesh.
//!
//! The `gltf` crate parses the JSON or GLB container and checks that every index into the
//! document's arrays exists. What it leaves to the reader is checked here before any accessor
//! is read, so that a malformed file is a one-line error naming it: buffers are read by this
//! module (capped at [`MAX_MESH_BYTES`], no images, `data:` URIs decoded) and must hold their
//! `byteLength`; every index into the document's arrays must fit in 32 bits (the crate wraps
//! wider ones); every accessor read must have the element type its role needs, lie inside its
//! buffer view, and that view inside its buffer; indices must refer to the primitive's
//! vertices; positions must be finite; the node hierarchy must be a tree. Normals that are zero
//! or not finite are repaired (and counted), missing ones computed, as for OBJ files.

use std::collections::HashSet;
use std::path::Path;

use base64::Engine;
use glam::{DMat4, DQuat, DVec3, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::ctx::shown_path;
use super::mesh::Mesh;
use super::mesh_file::{LoadedMesh, MAX_MESH_BYTES, read_file, with_normals};
use super::object::MAX_TRIANGLES;

/// Most vertices a glTF file may expand to once its meshes are instanced by its nodes (three
/// per triangle of the scene's cap): one small accessor referenced by many nodes cannot ask
/// for gigabytes.
const MAX_VERTICES: usize = 3 * MAX_TRIANGLES;

/// Loads a glTF 2.0 file (`.gltf` or `.glb`): the triangles of the default scene (or the first
/// scene when none is named) with their node transforms applied. Errors name the file.
pub fn load_gltf(path: &Path) -> Result<LoadedMesh, String> {
    let shown = shown_path(path);
    let bytes = read_file(path, "mesh file")?;
    check_glb_header(&bytes).map_err(|e| format!("`{shown}`: {e}"))?;
    let doc = parse(&bytes).map_err(|e| format!("`{shown}`: {e}"))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let buffers = load_buffers(&doc, dir).map_err(|e| format!("`{shown}`: {e}"))?;
    let (mesh, given) = flatten(&doc, &buffers).map_err(|e| format!("`{shown}`: {e}"))?;
    if mesh.indices.is_empty() {
        return Err(format!("`{shown}` has no triangles in its scene"));
    }
    Ok(with_normals(mesh, &given))
}

/// The document, validated by the crate once the references its validation itself follows
/// unchecked are known to exist: gltf-json 1.4.1 indexes `accessors` with a primitive's
/// `POSITION` before it checks that index, and panics on a dangling one.
fn parse(bytes: &[u8]) -> Result<gltf::Gltf, String> {
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| brief(&e))?;
    check_index_widths(bytes)?;
    let json = raw.document.into_json();
    let positions = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            match primitive.attributes.get(&positions) {
                Some(a) if a.value() >= json.accessors.len() => {
                    return Err(format!(
                        "invalid glTF: `meshes[{m}].primitives[{p}].attributes[\"POSITION\"]` \
                         refers to accessor {}, but the file has {} accessors",
                        a.value(),
                        json.accessors.len()
                    ));
                }
                _ => {}
            }
        }
    }
    let document = gltf::Document::from_json(json).map_err(|e| brief(&e))?;
    Ok(gltf::Gltf {
        document,
        blob: raw.blob,
    })
}

/// Where the glTF 2.0 schema puts an index into one of the document's arrays (`[]` an array's
/// element, `*` any key of a map): gltf-json reads each as `u64 as u32`, so an index of 2³² or
/// more would silently name another element (`bufferView = 4294967297` is view 1).
const INDEX_PATHS: &[&str] = &[
    "scene",
    "scenes[].nodes[]",
    "nodes[].children[]",
    "nodes[].mesh",
    "nodes[].camera",
    "nodes[].skin",
    "meshes[].primitives[].attributes.*",
    "meshes[].primitives[].indices",
    "meshes[].primitives[].material",
    "meshes[].primitives[].targets[].*",
    "accessors[].bufferView",
    "accessors[].sparse.indices.bufferView",
    "accessors[].sparse.values.bufferView",
    "bufferViews[].buffer",
    "images[].bufferView",
    "textures[].source",
    "textures[].sampler",
    "materials[].pbrMetallicRoughness.baseColorTexture.index",
    "materials[].pbrMetallicRoughness.metallicRoughnessTexture.index",
    "materials[].normalTexture.index",
    "materials[].occlusionTexture.index",
    "materials[].emissiveTexture.index",
    "skins[].joints[]",
    "skins[].skeleton",
    "skins[].inverseBindMatrices",
    "animations[].channels[].sampler",
    "animations[].channels[].target.node",
    "animations[].samplers[].input",
    "animations[].samplers[].output",
];

/// Every index of the document's JSON (a GLB's JSON chunk) fits in 32 bits; an error names the
/// first that does not by its JSON path. Runs after the crate parsed the file, so the JSON and
/// the container are known to be well formed.
fn check_index_widths(bytes: &[u8]) -> Result<(), String> {
    let json = if bytes.starts_with(b"glTF") {
        let glb = gltf::binary::Glb::from_slice(bytes).map_err(|e| brief(&e))?;
        serde_json::from_slice::<serde_json::Value>(&glb.json)
    } else {
        serde_json::from_slice::<serde_json::Value>(bytes)
    };
    let json = json.map_err(|e| format!("not valid glTF JSON: {e}").replace(['\n', '\r'], " "))?;
    first_wide_index(&json, "", "").map_or(Ok(()), |(path, n)| {
        Err(format!(
            "invalid glTF: `{path}` = {n} is not an index (the largest is {})",
            u32::MAX
        ))
    })
}

/// The first value at one of [`INDEX_PATHS`] under `v` (at schema path `schema` and JSON path
/// `path`) that is an integer past `u32::MAX`.
fn first_wide_index(v: &serde_json::Value, schema: &str, path: &str) -> Option<(String, u64)> {
    let join = |a: &str, b: &str| {
        if a.is_empty() {
            b.to_string()
        } else {
            format!("{a}.{b}")
        }
    };
    match v {
        serde_json::Value::Object(map) => map.iter().find_map(|(k, child)| {
            // A map of indices (`attributes`, a morph target) is `*` whatever its keys.
            let any = join(schema, "*");
            let s = if INDEX_PATHS.iter().any(|p| p.starts_with(&any)) {
                any
            } else {
                join(schema, k)
            };
            first_wide_index(child, &s, &join(path, k))
        }),
        serde_json::Value::Array(items) => items.iter().enumerate().find_map(|(i, child)| {
            first_wide_index(child, &format!("{schema}[]"), &format!("{path}[{i}]"))
        }),
        serde_json::Value::Number(n) => match n.as_u64() {
            Some(n) if n > u64::from(u32::MAX) && INDEX_PATHS.contains(&schema) => {
                Some((path.to_string(), n))
            }
            _ => None,
        },
        _ => None,
    }
}

/// A GLB's declared length must cover its 12-byte header (the `gltf` crate subtracts before it
/// compares) and not exceed the file.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(len) = bytes.get(8..12) else {
        return Err("truncated GLB header".into());
    };
    let len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
    if len < 12 || len > bytes.len() {
        return Err(format!(
            "GLB header declares {len} bytes, but the file holds {}",
            bytes.len()
        ));
    }
    Ok(())
}

/// The crate's error as one line: its first validation fault (with the JSON path) and how many
/// more there are.
fn brief(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Validation(faults) => {
            let more = match faults.len() {
                0 | 1 => String::new(),
                n => format!(" (and {} more)", n - 1),
            };
            faults.first().map_or_else(
                || "invalid glTF".to_string(),
                |(p, f)| format!("invalid glTF: `{p}`: {f}{more}"),
            )
        }
        gltf::Error::Deserialize(e) => format!("not valid glTF JSON: {e}"),
        gltf::Error::Binary(e) => format!("not a valid GLB file: {e}"),
        e => format!("{e}"),
    }
    .replace(['\n', '\r'], " ")
}

/// Every buffer's bytes, cut to its `byteLength`: the GLB's binary chunk, a `data:` URI
/// (base64) or a file beside the glTF file.
fn load_buffers(doc: &gltf::Gltf, dir: &Path) -> Result<Vec<Vec<u8>>, String> {
    let mut total = 0u64;
    let mut out = Vec::new();
    for b in doc.buffers() {
        let i = b.index();
        let mut data = match b.source() {
            gltf::buffer::Source::Bin => doc.blob.clone().ok_or_else(|| {
                format!("buffer {i} has no `uri` and the file has no GLB binary chunk")
            })?,
            gltf::buffer::Source::Uri(uri) => buffer_from_uri(uri, dir)
                .map_err(|e| format!("buffer {i} (`{}`): {e}", escaped(uri)))?,
        };
        if data.len() < b.length() {
            return Err(format!(
                "buffer {i} holds {} bytes, fewer than its `byteLength` {}",
                data.len(),
                b.length()
            ));
        }
        data.truncate(b.length());
        total += data.len() as u64;
        if total > MAX_MESH_BYTES {
            return Err(format!(
                "its buffers hold more than {} MiB",
                MAX_MESH_BYTES >> 20
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// A URI as messages show it: at most 60 characters, control characters escaped.
fn escaped(uri: &str) -> String {
    let short: String = uri.chars().take(60).collect();
    let cut = if short.len() < uri.len() { "…" } else { "" };
    shown_path(Path::new(&short)) + cut
}

/// A buffer's bytes from a base64 `data:` URI or a relative reference to a file.
fn buffer_from_uri(uri: &str, dir: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest.split_once(',').ok_or("a `data:` URI without a `,`")?;
        if !header.ends_with(";base64") {
            return Err("a `data:` URI that is not base64".into());
        }
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64: {e}"));
    }
    let scheme = uri
        .split_once(':')
        .is_some_and(|(s, _)| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric()));
    if scheme {
        return Err("only `data:` URIs and relative file references are read".into());
    }
    let name = percent_decode(uri)?;
    read_file(&dir.join(name), "buffer file")
}

/// `%XX` escapes of a URI reference decoded (RFC 3986), as UTF-8.
fn percent_decode(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or("a `%` not followed by two hex digits")?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "a reference that is not UTF-8 once decoded".into())
}

/// The default scene (or the first) walked depth first: each node's mesh under the product of
/// the transforms down to it. Returns the mesh (normals not yet set) and per vertex the normal
/// the file gives, if any.
fn flatten(doc: &gltf::Gltf, buffers: &[Vec<u8>]) -> Result<(Mesh, Vec<Option<Vec3>>), String> {
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or("the file has no scene")?;
    let mut out = Flat {
        buffers,
        mesh: Mesh::default(),
        given: Vec::new(),
        seen: HashSet::new(),
    };
    let mut stack: Vec<(gltf::Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        if !out.seen.insert(node.index()) {
            return Err(format!(
                "node {} appears twice in scene {}'s hierarchy (a cycle or a shared child): \
                 nodes must form trees",
                node.index(),
                scene.index()
            ));
        }
        let world = parent * node_matrix(&node)?;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
                out.primitive(&prim, world)
                    .map_err(|e| format!("{what} (node {}): {e}", node.index()))?;
            }
        }
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok((out.mesh, out.given))
}

/// A node's local transform in f64; an error if any of its numbers is not finite or its
/// rotation is not a quaternion of length near 1.
fn node_matrix(node: &gltf::Node) -> Result<DMat4, String> {
    let bad = || format!("node {}'s transform is not finite", node.index());
    let m = match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
        }
        gltf::scene::Transform::Decomposed {
            translation: t,
            rotation: r,
            scale: s,
        } => {
            let q = DQuat::from_array(r.map(f64::from));
            if !q.is_finite() || (q.length() - 1.0).abs() > 1e-3 {
                return Err(format!(
                    "node {}'s rotation {r:?} is not a unit quaternion",
                    node.index()
                ));
            }
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(s.map(f64::from)),
                q.normalize(),
                DVec3::from_array(t.map(f64::from)),
            )
        }
    };
    if m.is_finite() { Ok(m) } else { Err(bad()) }
}

/// The mesh being built while the scene is walked.
struct Flat<'a> {
    buffers: &'a [Vec<u8>],
    mesh: Mesh,
    given: Vec<Option<Vec3>>,
    seen: HashSet<usize>,
}

impl Flat<'_> {
    /// Appends one primitive under `world`; a mirroring transform reverses its winding so that
    /// computed normals still face out.
    fn primitive(&mut self, prim: &gltf::Primitive, world: DMat4) -> Result<(), String> {
        let mode = match prim.mode() {
            Mode::Triangles => None,
            Mode::Points => Some("POINTS"),
            Mode::Lines => Some("LINES"),
            Mode::LineLoop => Some("LINE_LOOP"),
            Mode::LineStrip => Some("LINE_STRIP"),
            Mode::TriangleStrip => Some("TRIANGLE_STRIP"),
            Mode::TriangleFan => Some("TRIANGLE_FAN"),
        };
        if let Some(name) = mode {
            return Err(format!(
                "mode {} ({name}) is not supported: only triangle lists (mode 4)",
                prim.mode().as_gl_enum()
            ));
        }
        let positions_acc = prim
            .get(&gltf::Semantic::Positions)
            .ok_or("no POSITION attribute")?;
        let n = checked(
            &positions_acc,
            "POSITION",
            &[(Dimensions::Vec3, DataType::F32)],
        )?;
        let normals_acc = prim.get(&gltf::Semantic::Normals);
        if let Some(a) = &normals_acc {
            let m = checked(a, "NORMAL", &[(Dimensions::Vec3, DataType::F32)])?;
            if m != n {
                return Err(format!(
                    "NORMAL (accessor {}) has {m} elements, POSITION (accessor {}) {n}",
                    a.index(),
                    positions_acc.index()
                ));
            }
        }
        let index_types =
            [DataType::U8, DataType::U16, DataType::U32].map(|t| (Dimensions::Scalar, t));
        if let Some(a) = prim.indices() {
            checked(&a, "indices", &index_types)?;
        }
        let reader = prim.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<[f32; 3]> = reader
            .read_positions()
            .ok_or("POSITION cannot be read")?
            .collect();
        if let Some(k) = positions
            .iter()
            .position(|p| !p.iter().all(|x| x.is_finite()))
        {
            return Err(format!(
                "POSITION (accessor {}) element {k} is not finite: {:?}",
                positions_acc.index(),
                positions[k]
            ));
        }
        let normals: Option<Vec<[f32; 3]>> = match reader.read_normals() {
            Some(r) => Some(r.collect()),
            None if normals_acc.is_some() => return Err("NORMAL cannot be read".into()),
            None => None,
        };
        let indices: Vec<u32> = match reader.read_indices() {
            Some(r) => r.into_u32().collect(),
            None if prim.indices().is_some() => return Err("indices cannot be read".into()),
            None => (0..n as u32).collect(),
        };
        check_indices(&indices, n)?;
        self.append(world, &positions, normals.as_deref(), &indices)
    }

    fn append(
        &mut self,
        world: DMat4,
        positions: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        indices: &[u32],
    ) -> Result<(), String> {
        let triangles = self.mesh.indices.len() / 3 + indices.len() / 3;
        let vertices = self.mesh.positions.len() + positions.len();
        if triangles > MAX_TRIANGLES || vertices > MAX_VERTICES {
            return Err(format!(
                "the scene expands to more than {MAX_TRIANGLES} triangles or {MAX_VERTICES} \
                 vertices"
            ));
        }
        let local = Mesh {
            positions: positions.iter().map(|&p| Vec3::from_array(p)).collect(),
            normals: normals.map_or_else(Vec::new, |n| {
                n.iter().map(|&n| Vec3::from_array(n)).collect()
            }),
            indices: indices.to_vec(),
        };
        let placed = local.transformed_f64(world);
        if let Some(p) = placed.positions.iter().find(|p| !p.is_finite()) {
            return Err(format!("a vertex is not finite once transformed: {p}"));
        }
        let base = self.mesh.positions.len() as u32;
        let mirrored = world.determinant() < 0.0;
        for t in placed.indices.chunks_exact(3) {
            let t = if mirrored {
                [t[0], t[2], t[1]]
            } else {
                [t[0], t[1], t[2]]
            };
            self.mesh.indices.extend(t.map(|i| i + base));
        }
        self.mesh.positions.extend(&placed.positions);
        match normals {
            // Zero after the transform (a degenerate scale) counts as given and repaired.
            Some(_) => self.given.extend(placed.normals.iter().map(|&n| Some(n))),
            None => self
                .given
                .extend(std::iter::repeat_n(None, positions.len())),
        }
        Ok(())
    }
}

/// Checks that accessor `a` (read as `role`) has one of the `types`, is not sparse, has a
/// buffer view, and lies inside that view, which lies inside its buffer; returns its count.
fn checked(
    a: &gltf::Accessor,
    role: &str,
    types: &[(Dimensions, DataType)],
) -> Result<usize, String> {
    let name = format!("{role} (accessor {})", a.index());
    let ty = (a.dimensions(), a.data_type());
    if !types.contains(&ty) {
        let want: Vec<String> = types.iter().map(|&t| type_name(t)).collect();
        return Err(format!(
            "{name} is {}, expected {}",
            type_name(ty),
            want.join(" or ")
        ));
    }
    if a.sparse().is_some() {
        return Err(format!("{name} is sparse, which is not supported"));
    }
    let view = a
        .view()
        .ok_or_else(|| format!("{name} has no buffer view"))?;
    let count = a.count();
    if count == 0 {
        return Err(format!("{name} has no elements"));
    }
    let size = a.size() as u64;
    let stride = view.stride().map_or(size, |s| s as u64);
    if stride < size {
        return Err(format!(
            "{name}: buffer view {} has a stride of {stride} bytes, less than the {size}-byte element",
            view.index()
        ));
    }
    let end = (count as u64 - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(size))
        .and_then(|x| x.checked_add(a.offset() as u64));
    if end.is_none_or(|e| e > view.length() as u64) {
        return Err(format!(
            "{name}: {count} elements from byte {} reach past buffer view {}'s {} bytes",
            a.offset(),
            view.index(),
            view.length()
        ));
    }
    let buffer = view.buffer();
    if view.offset() as u64 + view.length() as u64 > buffer.length() as u64 {
        return Err(format!(
            "buffer view {} (bytes {} to {}) reaches past buffer {}'s {} bytes",
            view.index(),
            view.offset(),
            view.offset() as u64 + view.length() as u64,
            buffer.index(),
            buffer.length()
        ));
    }
    Ok(count)
}

/// An accessor's element type as the file spells it (`VEC3` of `FLOAT`).
fn type_name((d, t): (Dimensions, DataType)) -> String {
    let d = match d {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    };
    let t = match t {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    };
    format!("{d} of {t}")
}

/// Triangle lists: a multiple of three indices, each below the vertex count.
fn check_indices(indices: &[u32], vertices: usize) -> Result<(), String> {
    if !indices.len().is_multiple_of(3) {
        return Err(format!(
            "{} indices do not make whole triangles",
            indices.len()
        ));
    }
    if let Some(k) = indices.iter().position(|&i| i as usize >= vertices) {
        return Err(format!(
            "index {} (element {k}) is out of range: the primitive has {vertices} vertices",
            indices[k]
        ));
    }
    Ok(())
}
