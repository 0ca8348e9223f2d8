//! What can go wrong when a host plugs the stage in, each variant naming what is wrong.

/// A mistake in what a host hands the plug-in stage (wrapped in [`crate::Error::Stage`]).
/// Sizes past the device's limits are [`crate::Error::Limit`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StageError {
    /// A configuration value is outside the range a scene file accepts, or does not apply to
    /// the technique. `field` uses the scene file's key names.
    #[error("config `{field}`: {message}")]
    Config {
        /// The offending field (scene key name, e.g. `bleed_reduction`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// The per-frame light parameters are out of range or contradict each other.
    #[error("light params `{field}`: {message}")]
    LightParams {
        /// The offending field of [`super::LightParams`].
        field: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// The depth texture's format is not one the `linearize` kernel can read.
    #[error("depth texture format {format:?} is not readable by the stage (accepted: {accepted})")]
    DepthFormat {
        /// The texture's format.
        format: wgpu::TextureFormat,
        /// The formats the stage accepts.
        accepted: String,
    },
    /// The depth texture cannot be bound for reading.
    #[error(
        "depth texture usage {usage:?} lacks TEXTURE_BINDING, which the stage reads it through"
    )]
    DepthUsage {
        /// The texture's usage flags.
        usage: wgpu::TextureUsages,
    },
    /// The depth texture is not square (shadow maps are `size × size`).
    #[error("depth texture is {width}x{height}; the stage's maps are square")]
    DepthNotSquare {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// The depth texture is not one single-sampled 2-D layer.
    #[error(
        "depth texture must be a single-sampled 2-D texture with one layer; it is {dimension:?} \
         with {layers} layer(s) and {samples} sample(s)"
    )]
    DepthLayout {
        /// Its dimension.
        dimension: wgpu::TextureDimension,
        /// Its array layers.
        layers: u32,
        /// Its sample count.
        samples: u32,
    },
    /// The device was created without a feature that was asked for.
    #[error("{needed_for} needs the device feature {feature}, which this device lacks")]
    MissingFeature {
        /// The feature.
        feature: wgpu::Features,
        /// What needs it.
        needed_for: &'static str,
    },
}
