//! Ways to compile the kernels that one run times side by side: a layout (`--layouts`), the
//! embedded kernels with their workgroup memory zeroed, or a folder of replacement kernels
//! (`--kernel-dirs`).

use crate::error::{Error, Result};
use crate::exec::{Executor, KernelLayout};

/// One way to compile the kernels that [`measure_variants`](super::measure_variants) times beside others: a layout
/// (`--layouts`) or a folder of replacement kernels (`--kernel-dirs`), named in its rows.
pub struct KernelVariant {
    /// The rows' suffix, `<case> [name]`: `gpu`, `cpu`, `shipped` or the folder's name.
    pub name: String,
    layout: Option<KernelLayout>,
    replaced: Option<std::sync::Arc<crate::kernels::Replacements>>,
    /// Workgroup memory zeroed first ([`ZEROED`]).
    zeroed: bool,
    /// Shader modules created without runtime checks ([`UNCHECKED`]).
    unchecked: bool,
}

/// The `--kernel-dirs` entry that stands for the embedded kernels.
pub const SHIPPED: &str = "shipped";

/// The `--kernel-dirs` entry that stands for the embedded kernels with their workgroup memory
/// zeroed first, as wgpu does by default (`exec::WorkgroupInit`): what opting out saves.
pub const ZEROED: &str = "zeroed";

/// The `--kernel-dirs` entry that stands for the embedded kernels with their shader modules
/// created without wgpu's runtime checks (`exec::ShaderChecks::Off`): what the checks cost
/// (`shipped,unchecked`).
pub const UNCHECKED: &str = "unchecked";

impl KernelVariant {
    /// The kernels in `layout` (`exec::KernelLayout`).
    pub fn layout(layout: KernelLayout) -> Self {
        Self {
            name: layout.name().to_string(),
            layout: Some(layout),
            replaced: None,
            zeroed: false,
            unchecked: false,
        }
    }

    /// The embedded kernels, named [`SHIPPED`].
    pub fn shipped() -> Self {
        Self {
            name: SHIPPED.to_string(),
            layout: None,
            replaced: None,
            zeroed: false,
            unchecked: false,
        }
    }

    /// The embedded kernels with unchecked shader modules, named [`UNCHECKED`].
    pub fn unchecked() -> Self {
        Self {
            name: UNCHECKED.to_string(),
            unchecked: true,
            ..Self::shipped()
        }
    }

    /// The embedded kernels with their workgroup memory zeroed first, named [`ZEROED`].
    pub fn zeroed() -> Self {
        Self {
            name: ZEROED.to_string(),
            zeroed: true,
            ..Self::shipped()
        }
    }

    /// The kernels with the `.wgsl` files of `dir` in place of those they name (as
    /// [`crate::kernels::KERNEL_DIR_ENV`] reads a folder), named by the folder's last
    /// component; [`SHIPPED`] is [`KernelVariant::shipped`], [`ZEROED`]
    /// [`KernelVariant::zeroed`], [`UNCHECKED`] [`KernelVariant::unchecked`]. A folder that cannot be read or
    /// replaces nothing, a file naming no kernel, or a replaced kernel that does not validate
    /// is an error naming it. The plan (its dispatches' geometry, the bytes of the rows) is the shipped kernels':
    /// a variant may change a kernel's workgroup size only where its node's dispatch does not
    /// follow it (the tables' tile passes: one workgroup a tile), as a variant's bit-for-bit
    /// test shows; one dispatched a line an invocation is refused by the executor.
    pub fn folder(dir: &std::path::Path) -> Result<Self> {
        if dir.as_os_str() == SHIPPED {
            return Ok(Self::shipped());
        }
        if dir.as_os_str() == ZEROED {
            return Ok(Self::zeroed());
        }
        if dir.as_os_str() == UNCHECKED {
            return Ok(Self::unchecked());
        }
        // Its messages name the environment variable that usually gives the folder.
        let env = format!("{}: ", crate::kernels::KERNEL_DIR_ENV);
        let replaced = crate::kernels::read_replacements(dir)
            .map_err(|e| Error::Invalid(e.replacen(&env, "--kernel-dirs: ", 1)))?;
        if replaced.is_empty() {
            return Err(Error::Invalid(format!(
                "--kernel-dirs {}: replaces no kernel (no `.wgsl` file naming one; `{SHIPPED}` \
                 stands for the embedded kernels)",
                dir.display()
            )));
        }
        // Each replaced kernel validated here, so that an error is one line naming the folder.
        let origin = format!("--kernel-dirs {}", dir.display());
        for name in crate::kernels::KernelId::ALL.iter().map(|k| k.name()) {
            let Ok(variant) = crate::kernels::resolve_in(name, None, Some(&replaced)) else {
                continue; // a kernel with a `// #generated` block (the shading pass)
            };
            if crate::kernels::resolve(name, None).is_ok_and(|shipped| shipped == variant) {
                continue;
            }
            crate::kernels::reflect_replaced(name, &variant, &origin)?;
        }
        let name = dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| dir.display().to_string());
        Ok(Self {
            name,
            layout: None,
            replaced: Some(std::sync::Arc::new(replaced)),
            zeroed: false,
            unchecked: false,
        })
    }

    /// An executor compiling its kernels this way.
    pub(super) fn executor(&self) -> Executor {
        let mut e = Executor::new();
        if let Some(layout) = self.layout {
            e.kernels.set_layout(layout);
        }
        if let Some(replaced) = &self.replaced {
            e.kernels.set_replacements(replaced.clone());
        }
        if self.zeroed {
            e.kernels.set_zeroed_workgroup_memory();
        }
        if self.unchecked {
            e.kernels.set_shader_checks(crate::exec::ShaderChecks::Off);
        }
        e
    }
}

/// Refuses two variants of one name: their rows could not be told apart. The error names the
/// flag that gave them and the second entry.
pub(super) fn check_distinct(variants: &[KernelVariant]) -> Result<()> {
    if let Some((k, v)) = variants
        .iter()
        .enumerate()
        .find(|(k, v)| variants[..*k].iter().any(|u| u.name == v.name))
    {
        let flag = if v.layout.is_some() {
            "--layouts"
        } else {
            "--kernel-dirs"
        };
        return Err(Error::Invalid(format!(
            "{flag} names `{}` twice (entry {})",
            v.name,
            k + 1
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{BenchRow, CASES, COPY_FORMATS, Inputs, measure_layouts, run};
    use crate::gpu::Gpu;

    fn gpu() -> Gpu {
        match Gpu::new() {
            Ok(g) => g,
            Err(e) => panic!("GPU tests need an adapter (lavapipe on CI): {e}"),
        }
    }
    /// `--layouts gpu,cpu`: each case once per layout, in that order, side by side, named by
    /// its layout, with the same bytes (one plan); the copies once; the report's header names
    /// the layouts, or the device's one without them.
    #[test]
    fn each_case_runs_in_each_layout_side_by_side() {
        let gpu = gpu();
        let only = vec!["sat fixed".to_string(), "blur rg32f r4".to_string()];
        let layouts = [KernelLayout::Gpu, KernelLayout::Cpu];
        let rows = measure_layouts(
            &gpu.device,
            &gpu.queue,
            &[32],
            1,
            &only,
            Inputs::Random,
            &layouts,
        )
        .unwrap();
        let cases: Vec<&BenchRow> = rows
            .iter()
            .filter(|r| !r.kernel.starts_with("copy"))
            .collect();
        let want: Vec<String> = CASES
            .iter()
            .map(|c| c.name)
            .filter(|n| n.contains("sat fixed") || n.contains("blur rg32f r4"))
            .flat_map(|n| [format!("{n} [gpu]"), format!("{n} [cpu]")])
            .collect();
        let names: Vec<&str> = cases.iter().map(|r| r.kernel.as_str()).collect();
        assert_eq!(names, want);
        for pair in cases.chunks(2) {
            assert_eq!(
                pair[0].bytes_moved, pair[1].bytes_moved,
                "{}",
                pair[0].kernel
            );
        }
        let copies = rows
            .iter()
            .filter(|r| r.kernel.starts_with("copy texture"))
            .count();
        assert_eq!(copies, 2 * COPY_FORMATS.len());
        // The report's first line says which layout the kernels ran in.
        let only = ["linearize".to_string()];
        let both = run(&gpu, &[32], 1, &only, Inputs::Random, false, &layouts, &[]).unwrap();
        let first = both.lines().next().unwrap_or_default();
        assert!(
            first.ends_with("(kernel layouts gpu, cpu, each kernel in each)"),
            "{first}"
        );
        let device = KernelLayout::for_device(&gpu.device).unwrap().name();
        let one = run(&gpu, &[32], 1, &only, Inputs::Random, false, &[], &[]).unwrap();
        let first = one.lines().next().unwrap_or_default();
        assert!(
            first.ends_with(&format!("(kernel layout {device})")),
            "{first}"
        );
    }

    /// `--kernel-dirs shipped,unchecked`: the embedded kernels with checked and with unchecked
    /// shader modules (`exec::ShaderChecks`), each case in both side by side; `on` and `off`
    /// are the environment variable's values, anything else an error naming the value.
    #[test]
    fn shader_checks_run_side_by_side() {
        use crate::bench::measure_variants;
        use crate::exec::ShaderChecks;
        let gpu = gpu();
        let dirs = [SHIPPED, UNCHECKED].map(|d| KernelVariant::folder(d.as_ref()).unwrap());
        let only = ["linearize".to_string()];
        let (d, q) = (&gpu.device, &gpu.queue);
        let rows = measure_variants(d, q, &[32], 1, &only, Inputs::Random, &dirs).unwrap();
        let names: Vec<&str> = rows
            .iter()
            .filter(|r| !r.kernel.starts_with("copy"))
            .map(|r| r.kernel.as_str())
            .collect();
        assert_eq!(names, ["linearize [shipped]", "linearize [unchecked]"]);
        assert_eq!(ShaderChecks::parse("off"), Ok(ShaderChecks::Off));
        assert_eq!(ShaderChecks::parse("on"), Ok(ShaderChecks::On));
        let e = ShaderChecks::parse("no").unwrap_err();
        assert!(e.contains("`no`") && e.contains("`off`"), "{e}");
    }
}
