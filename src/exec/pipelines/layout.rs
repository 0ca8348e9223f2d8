//! The layout a kernel compiles in where it has two ([`KernelLayout`]: a GPU's and a CPU
//! driver's), and how its workgroup memory starts ([`WorkgroupInit`]).

use crate::error::{Error, Result};

/// The environment variable that picks [`KernelLayout`] for every device: `gpu`, `cpu` or
/// `redesign` (unset: by the device's type). A/B of the layouts on one machine.
pub const KERNEL_LAYOUT_ENV: &str = "SHADOWGRAPH_KERNEL_LAYOUT";

pub use crate::kernels::{GPU_LAYOUT_CONSTANT, REDESIGN_CONSTANT};

/// Kernels whose redesign is a file of its own, `(shipped, redesign)`: in
/// [`KernelLayout::Redesign`] the executor compiles the redesign's file for every node of the
/// shipped kernel (the same bindings and dispatches; [`KernelLayout::kernel_source`]). A
/// separate file rather than a branch on `REDESIGN`: a kernel's declared workgroup memory costs
/// on a GPU even where the branch using it never runs (`benches/RESULTS.md`, 2026-11-27).
/// The mip chain after AMD FidelityFX SPD: `kernels/shared/mips_spd.wgsl`. The summed-area
/// tables' carries scanned by 8 lanes a line: `kernels/sat_carries_scan.wgsl` (its nodes'
/// dispatch is `graph::Dispatch::Redesigned`: `sat::carries_dispatch`).
pub const REDESIGNED_KERNELS: &[(&str, &str)] = &[
    ("mips", "mips_spd"),
    ("mips_log", "mips_spd_log"),
    ("sat_carries", "sat_carries_scan"),
];

/// Import-only modules whose redesign needs a device feature, `(shipped, redesign, feature)`:
/// in [`KernelLayout::Redesign`] on a device with `feature` every kernel importing `shipped`
/// imports `redesign` instead ([`KernelLayout::module_sources`]); on a device without it the
/// shipped module. The summed-area tables' tile passes by subgroup scans, a lane a column:
/// `kernels/shared/sat_strip.wgsl`.
pub const REDESIGNED_MODULES: &[(&str, &str, wgpu::Features)] = &[
    (
        "shared/sat_tile_sums",
        "shared/sat_tile_sums_subgroup",
        wgpu::Features::SUBGROUP,
    ),
    (
        "shared/sat_tile_scan",
        "shared/sat_tile_scan_subgroup",
        wgpu::Features::SUBGROUP,
    ),
];

/// Which of its two variants a kernel that has two compiles (`override GPU_LAYOUT: bool`): today
/// the summed-area tables' pass 3 (`kernels/shared/sat_tile*.wgsl`), whose second sweep over an
/// invocation's sub-block loads and encodes its texels again on a GPU (from its texture cache:
/// 7–13% faster on an H200 than keeping them) and reads the first sweep's encoded texels kept in
/// private memory on a CPU driver (1.1–1.2× faster on llvmpipe); both give the same tables bit
/// for bit (`tests/sat/`, `tests/csm_sat/`). And the encodings fused into the blur
/// (`kernels/shared/encode_blur.wgsl`): a tile blurred in workgroup memory by 256 invocations on
/// a GPU, walked in strips by 8 on a CPU driver (2–3× less CPU time on llvmpipe), the workgroup
/// size itself an override (`kernels::Reflection::cpu_workgroup_size`); both within
/// `tests/fused.rs`'s tolerances of the f64 reference.
///
/// Variants that staged texels through workgroup memory so that a SIMD group's lanes touch
/// neighbouring texels (the blur's row pass, the fused blurs, the tables' tile passes) were
/// slower on the H200 than each invocation reading its own run or block straight, 1.1–2.7×,
/// and their workgroup memory, declared in both variants, slowed the straight one too
/// (`benches/RESULTS.md`, 2026-11-27): they are gone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelLayout {
    /// A GPU's (`GPU_LAYOUT = true`): recompute from the texture cache.
    Gpu,
    /// A CPU driver's (`GPU_LAYOUT = false`): keep in private memory.
    Cpu,
    /// A GPU's with every redesign not yet decided on a GPU (`GPU_LAYOUT = true`,
    /// `REDESIGN = true`; graph-level redesigns ask [`KernelLayout::is_redesign`]): never a
    /// device's default, chosen by [`KERNEL_LAYOUT_ENV`]` = redesign` or `shadowgraph bench
    /// --layouts gpu,redesign`, which times it against [`KernelLayout::Gpu`] kernel by kernel.
    /// Every redesign is tested in it on lavapipe against the same references as the shipped
    /// kernels; one that wins on a GPU moves into [`KernelLayout::Gpu`]. Intermediates that
    /// are never filtered ([`crate::graph::Resource::unfiltered`]) live in storage buffers here
    /// ([`KernelLayout::buffers_intermediates`]).
    Redesign,
    /// [`KernelLayout::Redesign`] with every intermediate in a texture (`redesign-textures`):
    /// timed against it, it tells what the storage buffers bring alone.
    RedesignTextures,
}

impl KernelLayout {
    /// [`KERNEL_LAYOUT_ENV`] if set, else [`KernelLayout::Cpu`] on a CPU driver
    /// ([`wgpu::DeviceType::Cpu`]) and [`KernelLayout::Gpu`] on anything else.
    pub fn for_device(device: &wgpu::Device) -> Result<Self> {
        match std::env::var(KERNEL_LAYOUT_ENV) {
            Ok(v) => {
                Self::parse(&v).map_err(|e| Error::Invalid(format!("{KERNEL_LAYOUT_ENV}: {e}")))
            }
            Err(_) if crate::timer::is_gpu(device) => Ok(Self::Gpu),
            Err(_) => Ok(Self::Cpu),
        }
    }

    /// `gpu`, `cpu`, `redesign` or `redesign-textures`, as [`KERNEL_LAYOUT_ENV`] and
    /// `shadowgraph bench --layouts` spell it; else what is wrong with `name`.
    pub fn parse(name: &str) -> std::result::Result<Self, String> {
        match name {
            "gpu" => Ok(Self::Gpu),
            "cpu" => Ok(Self::Cpu),
            "redesign" => Ok(Self::Redesign),
            "redesign-textures" => Ok(Self::RedesignTextures),
            _ => Err(format!(
                "`{name}`: expected `gpu`, `cpu`, `redesign` or `redesign-textures`"
            )),
        }
    }

    /// Whether kernels compile their GPU variant (`GPU_LAYOUT = true`): [`KernelLayout::Gpu`]
    /// and [`KernelLayout::Redesign`].
    pub fn is_gpu(self) -> bool {
        !matches!(self, Self::Cpu)
    }

    /// Whether the undecided redesigns run ([`KernelLayout::Redesign`],
    /// [`KernelLayout::RedesignTextures`]).
    pub fn is_redesign(self) -> bool {
        matches!(self, Self::Redesign | Self::RedesignTextures)
    }

    /// Whether the executor keeps intermediates that are never filtered
    /// ([`crate::graph::Resource::unfiltered`]) in storage buffers, row-major, instead of
    /// textures ([`KernelLayout::Redesign`]): kernels read and write them through the rewrite
    /// of `exec::buffers`.
    pub fn buffers_intermediates(self) -> bool {
        matches!(self, Self::Redesign)
    }

    /// The kernel file compiled for kernel `name` in this layout: in [`KernelLayout::Redesign`]
    /// a redesign with a file of its own ([`REDESIGNED_KERNELS`]), else `name` itself.
    pub fn kernel_source(self, name: &str) -> &str {
        match self {
            Self::Redesign | Self::RedesignTextures => REDESIGNED_KERNELS
                .iter()
                .find(|(shipped, _)| *shipped == name)
                .map_or(name, |(_, redesign)| redesign),
            Self::Gpu | Self::Cpu => name,
        }
    }

    /// The modules kernels import in place of others in this layout on a device with
    /// `features`, `(shipped, redesign)`: those of [`REDESIGNED_MODULES`] the features allow in
    /// [`KernelLayout::Redesign`], none elsewhere.
    pub fn module_sources(self, features: wgpu::Features) -> Vec<(&'static str, &'static str)> {
        if !self.is_redesign() {
            return Vec::new();
        }
        REDESIGNED_MODULES
            .iter()
            .filter(|(_, _, needs)| features.contains(*needs))
            .map(|(shipped, redesign, _)| (*shipped, *redesign))
            .collect()
    }

    /// The name [`KernelLayout::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gpu => "gpu",
            Self::Cpu => "cpu",
            Self::Redesign => "redesign",
            Self::RedesignTextures => "redesign-textures",
        }
    }
}

/// How a kernel's workgroup memory starts. WebGPU guarantees zeros, and wgpu keeps the
/// guarantee by default: each workgroup first stores its whole declared workgroup memory and
/// waits at a barrier (the driver's zeroing, or code naga writes where the driver has none),
/// whichever of its entries the kernel reads. Every kernel in `kernels/` writes each entry of
/// its workgroup memory before it reads it, so [`KernelCache`](super::KernelCache) compiles them
/// [`WorkgroupInit::AsLeft`]: `tests/workgroup_memory.rs` fills that memory with NaN bit
/// patterns before each kernel's body runs, and every map of every plan that runs the kernels
/// stays the same bit for bit. (On the H200 a kernel's declared workgroup memory cost time even
/// where the branch using it never ran: `benches/RESULTS.md`, 2026-11-27;
/// `shadowgraph bench --kernel-dirs shipped,zeroed` times both.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WorkgroupInit {
    /// Zeroed before the kernel's body runs (wgpu's default).
    #[default]
    Zeroed,
    /// Left as the device leaves it: for kernels that write before they read.
    AsLeft,
}

/// The environment variable that compiles every kernel's module without wgpu's runtime checks
/// (`off`; `on` or unset: checked, the default): [`ShaderChecks`], an A/B on one machine.
pub const SHADER_CHECKS_ENV: &str = "SHADOWGRAPH_SHADER_CHECKS";

/// How a kernel's shader module is created. wgpu's `create_shader_module` has naga bound every
/// index and loop of the WGSL it translates (clamping an index into a private array, counting a
/// loop's iterations), which can keep a driver from unrolling a loop over a private array into
/// registers. [`ShaderChecks::Off`] creates the module with `create_shader_module_trusted` and
/// `wgpu::ShaderRuntimeChecks::unchecked()` instead, to time what the checks cost
/// ([`SHADER_CHECKS_ENV`]` = off`, or `shadowgraph bench --kernel-dirs shipped,unchecked`);
/// it is never a default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShaderChecks {
    /// wgpu's checked modules (the default).
    #[default]
    On,
    /// Unchecked modules: sound only because every kernel in `kernels/` indexes within bounds,
    /// bounds its loops and never divides an integer by zero (`gpu_objects::
    /// shader_module_unchecked` gives the reasons); for measurements.
    Off,
}

impl ShaderChecks {
    /// [`SHADER_CHECKS_ENV`]: `off` is [`ShaderChecks::Off`], `on` or unset
    /// [`ShaderChecks::On`]; any other value an error naming the variable.
    pub fn from_env() -> Result<Self> {
        match std::env::var(SHADER_CHECKS_ENV) {
            Err(_) => Ok(Self::On),
            Ok(v) => {
                Self::parse(&v).map_err(|e| Error::Invalid(format!("{SHADER_CHECKS_ENV}: {e}")))
            }
        }
    }

    /// `on` or `off`, as [`SHADER_CHECKS_ENV`] spells it; else what is wrong with `name`.
    pub fn parse(name: &str) -> std::result::Result<Self, String> {
        match name {
            "on" => Ok(Self::On),
            "off" => Ok(Self::Off),
            _ => Err(format!("`{name}`: expected `on` or `off`")),
        }
    }
}
