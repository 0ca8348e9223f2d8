//! Writes the procedural scenes (`scenes/forest.toml`, `colonnade.toml`, `city.toml`) and the
//! glTF canopy they use (`scenes/meshes/canopy.gltf` + `.bin`) from the generator in
//! `tests/procedural/`. The files are committed; `tests/procedural_scenes.rs` fails when they
//! differ from what this writes.
//!
//!     cargo run --example make_scenes

#[path = "../tests/procedural/mod.rs"]
mod procedural;

use std::path::Path;

fn main() -> std::io::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for (name, bytes) in procedural::files() {
        let path = root.join(name);
        std::fs::write(&path, &bytes)?;
        println!("wrote {} ({} bytes)", path.display(), bytes.len());
    }
    Ok(())
}
