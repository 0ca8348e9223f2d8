//! Mesh files: the loader chosen by extension (glTF 2.0 for `.gltf` and `.glb`, Wavefront OBJ
//! otherwise), the capped read they share, and the normals a file gives, lacks or gets wrong.

use std::io::Read;
use std::path::Path;

use glam::Vec3;

use super::ctx::shown_path;
use super::mesh::Mesh;
use super::{gltf, obj};

/// Largest mesh file read, and the most a glTF file's buffers may hold together: a scene's
/// triangle cap (`object::MAX_TRIANGLES`, 4 Mi) written as OBJ is about 160 MiB; the bundled
/// bunny is 110 KiB. Reading stops past it.
pub const MAX_MESH_BYTES: u64 = 256 << 20;

/// A loaded mesh and how many of its normals were repaired.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The triangles, normals unit length.
    pub mesh: Mesh,
    /// Normals the file gave as zero or non-finite, replaced by the faces' normal.
    pub repaired_normals: usize,
}

/// Loads the mesh file at `path`: glTF 2.0 when its extension is `gltf` or `glb` (any case),
/// Wavefront OBJ otherwise. Errors are one line naming the file.
pub fn load(path: &Path) -> Result<LoadedMesh, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("gltf" | "glb") => gltf::load_gltf(path),
        _ => obj::load_obj(path),
    }
}

/// The bytes of the file at `path`: a regular file of at most [`MAX_MESH_BYTES`]. `what` names
/// it in messages (`mesh file`, `buffer file`).
pub(super) fn read_file(path: &Path, what: &str) -> Result<Vec<u8>, String> {
    let shown = shown_path(path);
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => format!("{what} `{shown}` not found"),
        _ => format!("cannot read `{shown}`: {e}"),
    })?;
    if meta.is_dir() {
        return Err(format!("`{shown}` is a directory, not a {what}"));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read `{shown}`: {e}"))?;
    let mut bytes = Vec::new();
    file.take(MAX_MESH_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read `{shown}`: {e}"))?;
    if bytes.len() as u64 > MAX_MESH_BYTES {
        return Err(format!(
            "`{shown}` is larger than {} MiB, the most a {what} may be",
            MAX_MESH_BYTES >> 20
        ));
    }
    Ok(bytes)
}

/// `mesh` with its normals: `given[v]` where the file gave a finite non-zero normal
/// (normalized), the area-weighted normal of the faces around `v` where the file gave none
/// (`None`) or a zero or non-finite one (counted as repaired).
pub(super) fn with_normals(mut mesh: Mesh, given: &[Option<Vec3>]) -> LoadedMesh {
    let faces = mesh.face_normals();
    let mut repaired = 0;
    mesh.normals = given
        .iter()
        .zip(&faces)
        .map(|(n, f)| match n.and_then(|n| n.try_normalize()) {
            Some(n) => n,
            None => {
                repaired += usize::from(n.is_some());
                *f
            }
        })
        .collect();
    LoadedMesh {
        mesh,
        repaired_normals: repaired,
    }
}
