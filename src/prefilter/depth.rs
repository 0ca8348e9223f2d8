//! The depth a host hands the stage: a whole texture or one layer of an array, and what makes
//! it unusable.

use super::LightParams;
use crate::error::StageError;

/// Depth formats the `linearize` kernel reads (as unfilterable float, depth aspect only).
pub const DEPTH_FORMATS: [wgpu::TextureFormat; 5] = [
    wgpu::TextureFormat::Depth32Float,
    wgpu::TextureFormat::Depth32FloatStencil8,
    wgpu::TextureFormat::Depth24Plus,
    wgpu::TextureFormat::Depth24PlusStencil8,
    wgpu::TextureFormat::Depth16Unorm,
];

/// The depth a light's maps are filtered from: a whole 2-D depth texture of one layer
/// (`&wgpu::Texture` converts to it), or one layer of a 2-D array texture (a host's layered
/// shadow maps: one layer per light or cascade), named with [`DepthLayer::new`] and read in
/// place through a view of that layer. An array of several layers passed whole is refused
/// ([`StageError::DepthArray`]): which layer is meant is the host's to say.
#[derive(Clone, Copy, Debug)]
pub struct DepthLayer<'a> {
    texture: &'a wgpu::Texture,
    /// The array layer named, or `None` for a texture passed whole.
    layer: Option<u32>,
}

impl<'a> DepthLayer<'a> {
    /// Layer `layer` of `texture` (a 2-D texture of one or more array layers).
    pub fn new(texture: &'a wgpu::Texture, layer: u32) -> Self {
        Self {
            texture,
            layer: Some(layer),
        }
    }

    /// The depth texture.
    pub(super) fn texture(&self) -> &'a wgpu::Texture {
        self.texture
    }

    /// The array layer read (0 for a texture passed whole).
    pub(super) fn layer(&self) -> u32 {
        self.layer.unwrap_or(0)
    }
}

impl<'a> From<&'a wgpu::Texture> for DepthLayer<'a> {
    fn from(texture: &'a wgpu::Texture) -> Self {
        Self {
            texture,
            layer: None,
        }
    }
}

/// The map size of `depth` for `light`: its side (square), or a point light's face side (an
/// atlas of three faces by two); or what makes it unusable.
pub(super) fn check_depth(depth: DepthLayer<'_>, light: &LightParams) -> Result<u32, StageError> {
    let DepthLayer {
        texture: depth,
        layer,
    } = depth;
    if !DEPTH_FORMATS.contains(&depth.format()) {
        let accepted: Vec<String> = DEPTH_FORMATS.iter().map(|f| format!("{f:?}")).collect();
        return Err(StageError::DepthFormat {
            format: depth.format(),
            accepted: accepted.join(", "),
        });
    }
    if !depth.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
        return Err(StageError::DepthUsage {
            usage: depth.usage(),
        });
    }
    let (dimension, layers, samples) = (
        depth.dimension(),
        depth.depth_or_array_layers(),
        depth.sample_count(),
    );
    if dimension != wgpu::TextureDimension::D2 || samples != 1 {
        return Err(StageError::DepthLayout {
            dimension,
            layers,
            samples,
        });
    }
    match layer {
        None if layers > 1 => return Err(StageError::DepthArray { layers }),
        Some(layer) if layer >= layers => return Err(StageError::DepthLayer { layer, layers }),
        _ => {}
    }
    let (w, h) = (depth.width(), depth.height());
    if light.point {
        let face = h / 2;
        if face == 0 || w != 3 * face || h != 2 * face {
            return Err(StageError::DepthNotAtlas {
                width: w,
                height: h,
            });
        }
        return Ok(face);
    }
    if w != h {
        return Err(StageError::DepthNotSquare {
            width: w,
            height: h,
        });
    }
    Ok(w)
}
