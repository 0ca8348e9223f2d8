//! Scenes (the `cli` feature): the validated `Scene`, loaded from TOML (see `format`) with
//! errors that name the file, the key and the line. Its lights, camera and techniques are the
//! model's types ([`crate::model`]).

#[cfg(feature = "cli")]
mod animation;
#[cfg(feature = "cli")]
mod ctx;
#[cfg(feature = "cli")]
mod file;
#[cfg(feature = "cli")]
pub mod format;
#[cfg(feature = "cli")]
pub mod gltf;
#[cfg(feature = "cli")]
pub mod keys;
#[cfg(feature = "cli")]
pub mod locate;
#[cfg(feature = "cli")]
pub mod mesh;
#[cfg(feature = "cli")]
pub mod mesh_file;
#[cfg(feature = "cli")]
pub mod obj;
#[cfg(feature = "cli")]
mod object;
#[cfg(feature = "cli")]
mod parse;
#[cfg(feature = "cli")]
mod search_cap;
#[cfg(feature = "cli")]
mod update;
#[cfg(feature = "cli")]
mod validate;

#[cfg(feature = "cli")]
pub use animation::{Animated, Animation, MAX_ANIMATION_FRAMES, Track};
#[cfg(feature = "cli")]
pub use ctx::{COLOR_LIMIT, COORD_LIMIT, LENGTH_RANGE, ROTATION_LIMIT, fmt_num};
#[cfg(feature = "cli")]
pub use file::{MAX_SCENE_BYTES, Object, Scene};
#[cfg(feature = "cli")]
pub use locate::Locations;
#[cfg(feature = "cli")]
pub use mesh::Mesh;
#[cfg(feature = "cli")]
pub use object::{MAX_TRIANGLES, WORLD_LIMIT};
#[cfg(feature = "cli")]
pub use update::{MAX_UPDATE_PERIOD, UpdateRate};
