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
    Graph(#[from] crate::graph::GraphError),
    /// The executor cannot run a plan over the textures it was given.
    #[error("executor: {0}")]
    Exec(#[from] ExecError),
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
    /// What a host handed the plug-in stage is unusable (see [`crate::prefilter`]).
    #[error("plug-in stage: {0}")]
    Stage(#[from] crate::prefilter::StageError),
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

/// Why the executor (`exec`) cannot record a plan, beyond the plan's own shape
/// ([`crate::graph::GraphError::BadPlan`]) and the device's pipeline errors ([`Error::Pipeline`]).
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
