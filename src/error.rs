//! The library's error type: every failure a user or a device can cause is one of these.

use std::path::PathBuf;

/// Result alias used throughout shadowgraph.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in shadowgraph, each variant naming what is wrong.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// No GPU adapter was found (not even a software one).
    #[error(
        "no GPU adapter found{detail}: on a machine without a GPU install Mesa's software Vulkan \
         driver (Debian/Ubuntu: `apt-get install mesa-vulkan-drivers`)"
    )]
    NoAdapter {
        /// Extra context (e.g. the `WGPU_ADAPTER_NAME` that matched nothing).
        detail: String,
    },
    /// The adapter refused to create a device.
    #[error("could not create a device on adapter `{adapter}`: {message}")]
    RequestDevice {
        /// Adapter name.
        adapter: String,
        /// wgpu's message.
        message: String,
    },
    /// A WGSL kernel failed to parse, validate or import.
    #[error("kernel `{kernel}`: {message}")]
    Kernel {
        /// Kernel name (`kernels/<name>.wgsl`).
        kernel: String,
        /// What went wrong, with source location where naga gives one.
        message: String,
    },
    /// Pipeline creation failed on the device.
    #[error("pipeline `shadowgraph.{kernel}`: {message}")]
    Pipeline {
        /// Kernel name.
        kernel: String,
        /// wgpu's validation message.
        message: String,
    },
    /// Executing recorded GPU work failed.
    #[error("GPU error during {stage}: {message}")]
    Gpu {
        /// What was running (e.g. `render`, `shade`).
        stage: String,
        /// wgpu's message.
        message: String,
    },
    /// The kernel graph is malformed.
    #[error("graph: {0}")]
    Graph(GraphError),
    /// The executor cannot run a plan over the textures it was given.
    #[error("executor: {0}")]
    Exec(ExecError),
    /// A scene file could not be read or is invalid.
    #[error("{path}{location}: {message}")]
    Scene {
        /// The scene file.
        path: PathBuf,
        /// `:line:column` when known, else empty.
        location: String,
        /// What is wrong, naming the key.
        message: String,
    },
    /// A scene needs more of the device than it offers (a texture side, bindings, a buffer, or
    /// memory past the budget), found before anything was created; names the scene key that
    /// would fix it, with its line.
    #[error("{path}{location}: {message}")]
    SceneLimit {
        /// The scene file.
        path: PathBuf,
        /// `:line:column` of the key (or of its table), else empty.
        location: String,
        /// What is too large, the device's limit, and the key to change.
        message: String,
    },
    /// A mesh referenced by a scene could not be loaded.
    #[error("mesh `{path}`: {message}")]
    Mesh {
        /// The mesh file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A requested size exceeds what the device allows.
    #[error("{what} is {requested}, but this device allows at most {limit}")]
    Limit {
        /// What was too large (e.g. `light[0].shadow_map`).
        what: String,
        /// The size asked for.
        requested: u64,
        /// The device limit.
        limit: u64,
    },
    /// What a host handed the plug-in stage is unusable (see [`crate::Prefilter`]).
    #[error("plug-in stage: {0}")]
    Stage(StageError),
    /// The scene needs a device feature the adapter does not offer.
    #[error("{what} needs the device feature {feature}, which this adapter does not offer")]
    MissingFeature {
        /// The scene key or API input that needs it.
        what: String,
        /// The wgpu feature's name.
        feature: &'static str,
    },
    /// An argument is invalid (zero size, mismatched lengths, ...).
    #[error("invalid argument: {0}")]
    Invalid(String),
    /// Reading or writing a file failed.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        error: std::io::Error,
    },
    /// Encoding an output image failed.
    #[error("writing image `{path}`: {message}")]
    Image {
        /// The output path.
        path: PathBuf,
        /// Encoder message.
        message: String,
    },
}

// The wrapped errors are part of the message and not also a `source()`: a chain printed cause
// by cause (anyhow's `{:#}`) would print them twice.
impl From<GraphError> for Error {
    fn from(e: GraphError) -> Self {
        Self::Graph(e)
    }
}

impl From<ExecError> for Error {
    fn from(e: ExecError) -> Self {
        Self::Exec(e)
    }
}

impl From<StageError> for Error {
    fn from(e: StageError) -> Self {
        Self::Stage(e)
    }
}

/// Why the executor (`exec`) cannot record a plan, beyond the plan's own shape
/// ([`crate::error::GraphError::BadPlan`]) and the device's pipeline errors ([`Error::Pipeline`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ExecError {
    /// An imported resource has no texture among the caller's imports.
    #[error("imported resource `{0}` was not provided")]
    MissingImport(String),
    /// A texture is not the size the plan planned for its resource.
    #[error("`{resource}` is {width}x{height}, the plan expects {plan_width}x{plan_height}")]
    Size {
        /// The resource.
        resource: String,
        /// The texture's width.
        width: u32,
        /// The texture's height.
        height: u32,
        /// The planned width.
        plan_width: u32,
        /// The planned height.
        plan_height: u32,
    },
    /// A kernel binding that the node leaves unbound.
    #[error("node `{node}` binds nothing to `{binding}`")]
    Unbound {
        /// The node.
        node: String,
        /// The binding (or the node slot a dispatch names).
        binding: String,
    },
    /// A node binds a resource the run has no texture for.
    #[error("node `{node}` binds `{resource}`, which has no texture in this run")]
    NoTexture {
        /// The node.
        node: String,
        /// The resource.
        resource: String,
    },
    /// A dispatch binds a mip level its texture does not have.
    #[error("node `{node}` binds mip level {level} of a texture of {levels}")]
    NoLevel {
        /// The node.
        node: String,
        /// The level asked for.
        level: u32,
        /// The texture's levels.
        levels: u32,
    },
    /// An import is read at an array layer its texture does not have.
    #[error("import `{resource}` is read at layer {layer} of a texture of {layers} layer(s)")]
    NoLayer {
        /// The imported resource.
        resource: String,
        /// The layer asked for.
        layer: u32,
        /// The texture's layers.
        layers: u32,
    },
    /// A dispatch's parameter bytes are not the node's.
    #[error("node `{node}`: a dispatch's parameter bytes are out of range")]
    Params {
        /// The node.
        node: String,
    },
    /// A node's dispatch counts over a resource that is not in the plan.
    #[error("node `{node}` dispatches over a resource that is not in the plan")]
    DispatchOver {
        /// The node.
        node: String,
    },
    /// [`crate::exec::Outputs::view`] of a resource the plan does not have.
    #[error("the plan has no resource `{0}`")]
    NoResource(String),
}

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
        /// The offending field of `prefilter::LightParams`.
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
    /// A point light's depth texture is not an atlas of three faces by two.
    #[error(
        "depth texture is {width}x{height}; a point light's is an atlas of 3 x 2 square faces \
         (3N x 2N texels for N-texel faces: `Prefilter::point_views`)"
    )]
    DepthNotAtlas {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// The depth texture is not a single-sampled 2-D texture (of one or more layers).
    #[error(
        "depth texture must be a single-sampled 2-D texture (a layer of a 2-D array is passed as \
         `DepthLayer::new(texture, layer)`); it is {dimension:?} with {layers} layer(s) and \
         {samples} sample(s)"
    )]
    DepthLayout {
        /// Its dimension.
        dimension: wgpu::TextureDimension,
        /// Its array layers.
        layers: u32,
        /// Its sample count.
        samples: u32,
    },
    /// A depth texture of several array layers was passed whole, which names no layer.
    #[error(
        "depth texture has {layers} array layers and was passed whole: name the light's layer \
         with `DepthLayer::new(&texture, layer)`"
    )]
    DepthArray {
        /// The texture's layers.
        layers: u32,
    },
    /// The layer asked for is past the depth texture's layers.
    #[error("depth layer {layer} asked for, but the depth texture has {layers} layer(s)")]
    DepthLayer {
        /// The layer asked for.
        layer: u32,
        /// The texture's layers.
        layers: u32,
    },
    /// A light slot past what one stage serves.
    #[error("light slot {slot}: one stage serves at most {max} lights (slots 0..{max})")]
    LightSlot {
        /// The slot asked for.
        slot: usize,
        /// The stage's maximum.
        max: usize,
    },
    /// The device runs no compute shaders (its compute limits are zero, as
    /// `wgpu::Limits::downlevel_webgl2_defaults()` makes them): the stage is compute kernels.
    #[error(
        "this device runs no compute shaders ({limit} = 0, as wgpu::Limits::downlevel_webgl2_defaults() \
         gives): the stage runs its prefiltering as compute kernels; create the device with \
         wgpu::Limits::default() or the adapter's own limits (adapter.limits())"
    )]
    NoCompute {
        /// The first compute limit that is zero.
        limit: &'static str,
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

/// A wiring mistake in a graph, found by the planner.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum GraphError {
    /// A node reads or writes a resource that was never declared.
    #[error("node `{node}` uses undeclared resource `{resource}`")]
    UnknownResource {
        /// The node.
        node: String,
        /// The resource name.
        resource: String,
    },
    /// An output was asked for that was never declared.
    #[error("output `{0}` is not a declared resource")]
    UnknownOutput(String),
    /// A needed resource has no node producing it and is not imported.
    #[error("resource `{resource}` (needed by {needed_by}) has no producer and is not imported")]
    MissingProducer {
        /// The resource.
        resource: String,
        /// Who needs it: a node name or `the outputs`.
        needed_by: String,
    },
    /// Two nodes write the same resource.
    #[error("resource `{resource}` is written by both `{first}` and `{second}`")]
    DuplicateProducer {
        /// The resource.
        resource: String,
        /// The first writer.
        first: String,
        /// The second writer.
        second: String,
    },
    /// A node writes an imported resource.
    #[error("node `{node}` writes imported resource `{resource}`")]
    WritesImport {
        /// The node.
        node: String,
        /// The resource.
        resource: String,
    },
    /// Two nodes or two resources share a name.
    #[error("name `{0}` is declared twice")]
    DuplicateName(String),
    /// The needed part of the graph has a cycle.
    #[error("cycle through nodes {}", .0.join(" → "))]
    Cycle(Vec<String>),
    /// A plan (built or edited by hand) breaks what the executor relies on: a slot or a
    /// resource out of range, mismatched, or missing (see [`crate::graph::Plan::check`]).
    #[error("malformed plan: {0}")]
    BadPlan(String),
    /// A size rule refers to a missing resource or to itself.
    #[error("size of `{resource}`: {message}")]
    BadSize {
        /// The resource.
        resource: String,
        /// What is wrong.
        message: String,
    },
}
