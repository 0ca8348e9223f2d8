//! The validated scene of a file: its camera, lights and world-space objects.

use std::io::Read;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::{Locations, Mesh, parse};
use crate::error::{Error, Result};
use crate::model::{Camera, Light};
use crate::wgsl_mirrors::Vertex;

/// A loaded, validated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The file it came from.
    pub path: PathBuf,
    /// Output image size.
    pub width: u32,
    /// Output image height.
    pub height: u32,
    /// Background colour (linear RGB).
    pub background: Vec3,
    /// Ambient light (linear RGB).
    pub ambient: Vec3,
    /// The camera.
    pub camera: Camera,
    /// Lights, each with its own shadow technique.
    pub lights: Vec<Light>,
    /// Objects, already turned into world-space triangle meshes.
    pub objects: Vec<Object>,
    /// Values validation changed (e.g. exponents clamped to the storage's safe limit).
    pub warnings: Vec<String>,
    /// Where each key was written, for errors found later (device limits, memory).
    pub locations: Locations,
    /// Per light, how often its map is redrawn (`update`; a light past the list's end: every
    /// frame). See [`Scene::update_rate`].
    pub updates: Vec<super::UpdateRate>,
    /// The `[animation]`, if any ([`Scene::at_frame`]).
    pub animation: Option<super::Animation>,
}

/// Largest scene file read (the bundled ones are 1–3 KiB); reading stops past it.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// A scene object: its world-space mesh and colour.
#[derive(Clone, Debug)]
pub struct Object {
    /// World-space triangles.
    pub mesh: Mesh,
    /// Albedo (linear RGB).
    pub color: Vec3,
}

impl Scene {
    /// Reads and validates a scene file (at most [`MAX_SCENE_BYTES`], UTF-8); meshes are loaded
    /// relative to it.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let io = |error| Error::Io {
            path: path.to_path_buf(),
            error,
        };
        let whole = |message: String| Error::Scene {
            path: path.to_path_buf(),
            location: String::new(),
            message,
        };
        if std::fs::metadata(path).map_err(io)?.is_dir() {
            return Err(whole("is a directory, not a scene file".into()));
        }
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_SCENE_BYTES + 1).read_to_end(&mut bytes))
            .map_err(io)?;
        if bytes.len() as u64 > MAX_SCENE_BYTES {
            return Err(whole(format!(
                "larger than {} KiB, the most a scene file may be",
                MAX_SCENE_BYTES >> 10
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            whole(format!(
                "not a text file (invalid UTF-8 at byte {})",
                e.utf8_error().valid_up_to()
            ))
        })?;
        Self::parse(path, &text)
    }

    /// Parses scene text; `path` names the file in errors and anchors relative mesh paths.
    pub fn parse(path: &Path, text: &str) -> Result<Self> {
        parse::parse(path, text.strip_prefix('\u{feff}').unwrap_or(text))
    }

    /// How often light `i`'s map is redrawn (every frame unless its `update` says otherwise).
    pub fn update_rate(&self, i: usize) -> super::UpdateRate {
        self.updates.get(i).copied().unwrap_or_default()
    }

    /// All objects' triangles as one vertex list (material = object index).
    pub fn vertices(&self) -> Vec<Vertex> {
        self.objects
            .iter()
            .enumerate()
            .flat_map(|(i, o)| o.mesh.vertices(i as u32))
            .collect()
    }
}
