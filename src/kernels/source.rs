//! Where a kernel's text comes from: the embedded `kernels/` files, a folder of replacements
//! ([`KERNEL_DIR_ENV`], or one [`Replacements`] set), and the resolver of `// #import` and
//! `// #generated` lines.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use super::SOURCES;
use crate::error::{Error, Result};

/// The environment variable naming a folder of replacement kernels: its `<name>.wgsl` (and
/// `shared/<name>.wgsl`) files take the place of the embedded files of the same name for the
/// whole process. Every file must name an embedded kernel or module; the replaced names are
/// said once on stderr.
pub const KERNEL_DIR_ENV: &str = "SHADOWGRAPH_KERNEL_DIR";

/// The replacement kernels of [`KERNEL_DIR_ENV`], read at the first kernel looked up: name →
/// text, or the one-line error that every kernel lookup then reports.
pub(super) fn replacements()
-> std::result::Result<&'static HashMap<String, &'static str>, &'static str> {
    static REPLACED: OnceLock<std::result::Result<HashMap<String, &'static str>, String>> =
        OnceLock::new();
    let loaded = REPLACED.get_or_init(|| {
        let Some(dir) = std::env::var_os(KERNEL_DIR_ENV) else {
            return Ok(HashMap::new());
        };
        let dir = PathBuf::from(dir);
        let replaced = read_replacements(&dir)?;
        let mut names: Vec<&str> = replaced.keys().map(String::as_str).collect();
        names.sort_unstable();
        eprintln!(
            "note: {KERNEL_DIR_ENV}={}: kernels replaced: {}",
            dir.display(),
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        );
        Ok(replaced
            .into_iter()
            .map(|(k, v)| (k, &*Box::leak(v.into_boxed_str())))
            .collect())
    });
    loaded.as_ref().map_err(String::as_str)
}

/// The `.wgsl` files below `dir` (one level of folders: `shared/`), each by its path below
/// `dir` without the extension; an error names a file that is no embedded kernel or module, or
/// a folder that cannot be read.
pub fn read_replacements(dir: &Path) -> std::result::Result<HashMap<String, String>, String> {
    let mut out = HashMap::new();
    let mut folders = vec![(dir.to_path_buf(), String::new())];
    while let Some((folder, prefix)) = folders.pop() {
        let entries = std::fs::read_dir(&folder)
            .map_err(|e| format!("{KERNEL_DIR_ENV}: {}: {e}", folder.display()))?;
        for entry in entries {
            let entry =
                entry.map_err(|e| format!("{KERNEL_DIR_ENV}: {}: {e}", folder.display()))?;
            let path = entry.path();
            let file_name = entry.file_name().to_string_lossy().into_owned();
            if path.is_dir() {
                if prefix.is_empty() {
                    folders.push((path, format!("{file_name}/")));
                }
                continue;
            }
            let Some(stem) = file_name.strip_suffix(".wgsl") else {
                continue;
            };
            let name = format!("{prefix}{stem}");
            if !SOURCES.iter().any(|s| s.name == name) {
                return Err(format!(
                    "{KERNEL_DIR_ENV}: {}: names no kernel or module in kernels/",
                    path.display()
                ));
            }
            let text = std::fs::read_to_string(&path)
                .map_err(|e| format!("{KERNEL_DIR_ENV}: {}: {e}", path.display()))?;
            out.insert(name, text);
        }
    }
    Ok(out)
}

/// A set of replacement kernels (name below `kernels/` without `.wgsl` → text), as
/// [`read_replacements`] reads a folder: what one [`crate::exec::KernelCache`] compiles instead
/// of the embedded files (`shadowgraph bench --kernel-dirs`: variants side by side in one
/// process).
pub type Replacements = HashMap<String, String>;

/// The text of `kernels/<name>.wgsl`: from `extra` if it replaces it, else [`source`].
pub fn source_in<'a>(name: &str, extra: Option<&'a Replacements>) -> Result<&'a str> {
    if let Some(text) = extra.and_then(|r| r.get(name)) {
        return Ok(text);
    }
    source(name)
}

/// The text of `kernels/<name>.wgsl`: embedded, or its replacement from [`KERNEL_DIR_ENV`].
pub fn source(name: &str) -> Result<&'static str> {
    let replaced = replacements().map_err(|message| Error::Kernel {
        kernel: name.to_string(),
        message: message.to_string(),
    })?;
    if let Some(text) = replaced.get(name) {
        return Ok(text);
    }
    SOURCES
        .iter()
        .find(|s| s.name == name)
        .map(|s| s.text)
        .ok_or_else(|| Error::Kernel {
            kernel: name.to_string(),
            message: "no such kernel in kernels/".into(),
        })
}

/// Resolves `// #import` lines (and `// #generated`, replaced by `generated`, whose own
/// imports are resolved too) of kernel `name`.
pub fn resolve(name: &str, generated: Option<&str>) -> Result<String> {
    resolve_in(name, generated, None)
}

/// [`resolve`], with the kernel and its imports taken from `extra` where it replaces them.
pub fn resolve_in(
    name: &str,
    generated: Option<&str>,
    extra: Option<&Replacements>,
) -> Result<String> {
    let mut seen = HashSet::from([name.to_string()]);
    let mut out = String::new();
    resolve_text(
        name,
        source_in(name, extra)?,
        generated,
        extra,
        &mut seen,
        &mut out,
    )?;
    Ok(out)
}

/// Resolves the `// #import` lines of `text`, WGSL that is not a file in `kernels/` (e.g. the
/// plug-in stage's exported library); `name` labels errors.
pub fn resolve_source(name: &str, text: &str) -> Result<String> {
    let mut seen = HashSet::new();
    let mut out = String::new();
    resolve_text(name, text, None, None, &mut seen, &mut out)?;
    Ok(out)
}

fn resolve_text(
    name: &str,
    text: &str,
    generated: Option<&str>,
    extra: Option<&Replacements>,
    seen: &mut HashSet<String>,
    out: &mut String,
) -> Result<()> {
    for line in text.lines() {
        let t = line.trim();
        if let Some(module) = t.strip_prefix("// #import ") {
            let module = module.trim();
            if seen.insert(module.to_string()) {
                let imported = source_in(module, extra).map_err(|e| Error::Kernel {
                    kernel: name.to_string(),
                    message: format!("import `{module}`: {e}"),
                })?;
                resolve_text(module, imported, None, extra, seen, out)?;
            }
        } else if t == "// #generated" {
            let block = generated.ok_or_else(|| Error::Kernel {
                kernel: name.to_string(),
                message: "has a `// #generated` block but none was supplied".into(),
            })?;
            resolve_text(name, block, None, extra, seen, out)?;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(())
}
