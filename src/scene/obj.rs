//! Wavefront OBJ meshes: read with a size cap, checked line by line (so a malformed file is an
//! error naming its line), then triangulated by `tobj`.

use std::path::Path;

use glam::Vec3;

use super::ctx::shown_path;
use super::mesh::Mesh;
use super::mesh_file::{LoadedMesh, read_file, with_normals};

/// Loads a Wavefront OBJ (triangulated); smooth normals when the file has none, and the faces'
/// normal wherever the file's is zero or not finite. Errors name the file and, for malformed
/// content, the line.
pub fn load_obj(path: &Path) -> Result<LoadedMesh, String> {
    let text = read_text(path)?;
    let body = text.strip_prefix('\u{feff}').unwrap_or(&text);
    check_lines(body)
        .map_err(|(line, what)| format!("`{}` line {line}: {what}", shown_path(path)))?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut body.as_bytes(), &opts, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("cannot read `{}`: {e}", shown_path(path)))?;
    let mut mesh = Mesh::default();
    let mut given = Vec::new();
    for model in models {
        let mm = &model.mesh;
        let base = mesh.positions.len() as u32;
        let pos = mm
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]));
        let has_normals = mm.normals.len() == mm.positions.len();
        mesh.positions.extend(pos);
        mesh.indices.extend(mm.indices.iter().map(|i| i + base));
        given.extend((0..mm.positions.len() / 3).map(|v| {
            has_normals.then(|| {
                Vec3::new(
                    mm.normals[3 * v],
                    mm.normals[3 * v + 1],
                    mm.normals[3 * v + 2],
                )
            })
        }));
    }
    if mesh.indices.is_empty() {
        return Err(format!("`{}` has no triangles", shown_path(path)));
    }
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        return Err(format!("`{}` has a non-finite vertex", shown_path(path)));
    }
    Ok(with_normals(mesh, &given))
}

/// The file as text: at most [`super::mesh_file::MAX_MESH_BYTES`], a regular file, UTF-8.
fn read_text(path: &Path) -> Result<String, String> {
    let bytes = read_file(path, "mesh file")?;
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "`{}` is not a text file (invalid UTF-8 at byte {})",
            shown_path(path),
            e.utf8_error().valid_up_to()
        )
    })
}

/// Checks what `tobj` accepts silently or reports without a line: vertex and normal lines of
/// three finite numbers, faces of at least three corners whose indices (1-based, or negative
/// from the end) refer to elements defined before them. Returns the 1-based line and the fault.
fn check_lines(text: &str) -> Result<(), (usize, String)> {
    let mut counts = [0usize; 3]; // v, vt, vn
    for (n, line) in text.lines().enumerate() {
        let fail = |what: String| Err((n + 1, what));
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let xs: Vec<&str> = words.collect();
                if xs.len() < 3 || xs[..3].iter().any(|x| x.parse::<f32>().is_err()) {
                    return fail("a vertex needs three numbers".into());
                }
                if let Some(x) = xs[..3]
                    .iter()
                    .find(|x| !x.parse::<f32>().is_ok_and(f32::is_finite))
                {
                    return fail(format!(
                        "vertex coordinate `{x}` is not a finite 32-bit number"
                    ));
                }
                counts[0] += 1;
            }
            Some("vt") => counts[1] += 1,
            Some("vn") => {
                let xs: Vec<&str> = words.collect();
                if xs.len() < 3 || xs[..3].iter().any(|x| x.parse::<f32>().is_err()) {
                    return fail("a normal needs three numbers".into());
                }
                counts[2] += 1;
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return fail(format!(
                        "a face needs at least three corners, found {}",
                        corners.len()
                    ));
                }
                for c in corners {
                    check_corner(c, &counts).or_else(fail)?;
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// One face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` against the elements defined so far.
fn check_corner(corner: &str, counts: &[usize; 3]) -> Result<(), String> {
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err(format!(
            "face corner `{corner}` is not `v`, `v/vt`, `v//vn` or `v/vt/vn`"
        ));
    }
    let names = [
        ("vertex", "vertices"),
        ("texture coordinate", "texture coordinates"),
        ("normal", "normals"),
    ];
    for ((part, &count), (one, many)) in parts.iter().zip(counts).zip(names) {
        if part.is_empty() {
            continue;
        }
        let i: i64 = part
            .parse()
            .map_err(|_| format!("face corner `{corner}`: `{part}` is not an index"))?;
        if i == 0 {
            return Err(format!(
                "face corner `{corner}`: {one} index 0 (OBJ indices start at 1)"
            ));
        }
        let resolved = if i < 0 { count as i64 + i + 1 } else { i };
        if resolved < 1 || resolved > count as i64 {
            let defined = if count == 1 {
                format!("1 {one} is")
            } else {
                format!("{count} {many} are")
            };
            return Err(format!(
                "face corner `{corner}` refers to {one} {i}, but {defined} defined before it"
            ));
        }
    }
    Ok(())
}
