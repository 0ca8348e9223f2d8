//! Writing images: PNG previews and 32-bit float OpenEXR with named channels, and the output
//! folders they go into.

use std::path::Path;

use crate::error::{Error, Result};

/// Makes the output folder `dir` (and its parents) if missing. A path that exists as something
/// other than a folder is refused naming it (the OS says only "File exists").
pub fn make_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|error| {
        if dir.exists() && !dir.is_dir() {
            Error::Invalid(format!(
                "{}: exists and is not a folder; name a folder for the output",
                dir.display()
            ))
        } else {
            Error::Io {
                path: dir.to_path_buf(),
                error,
            }
        }
    })
}

/// Writes 8-bit RGBA pixels as PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    image::save_buffer(path, rgba, width, height, image::ColorType::Rgba8).map_err(|e| {
        Error::Image {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    })
}

/// Writes one 32-bit float OpenEXR layer with the given named channels (row-major, y down),
/// the same bytes for the same pixels.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    channels: Vec<(String, Vec<f32>)>,
) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, LineOrder,
        SmallVec, WritableImage,
    };
    let n = (width as usize) * (height as usize);
    if let Some((name, c)) = channels.iter().find(|(_, c)| c.len() != n) {
        return Err(Error::Invalid(format!(
            "EXR channel `{name}` has {} samples, expected {n}",
            c.len()
        )));
    }
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, data)| AnyChannel::new(name.as_str(), FlatSamples::F32(data)))
        .collect();
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named("shadowgraph"),
        // Blocks in increasing order (compressed in parallel all the same): the same pixels
        // give the same file, so two dumps compare with `cmp`.
        Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        },
        AnyChannels::sort(list),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| Error::Image {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
}

/// Splits interleaved `stride`-channel data into one channel per name.
pub fn deinterleave(data: &[f32], stride: usize, names: &[&str]) -> Vec<(String, Vec<f32>)> {
    names
        .iter()
        .enumerate()
        .map(|(c, n)| {
            (
                n.to_string(),
                data.iter().skip(c).step_by(stride).copied().collect(),
            )
        })
        .collect()
}
