//! naga's parse and validation of a kernel, its errors naming the kernel: naga's annotated
//! source for the embedded kernels, one line tagged with their origin for replaced ones.

use super::KERNEL_DIR_ENV;
use super::source::replacements;
use crate::error::{Error, Result};

/// Parses and validates WGSL text, returning the module. While [`KERNEL_DIR_ENV`] replaces
/// kernels, an error is one line (naga's message and its line in the kernel with its imports
/// spliced in), as for any other input; the embedded kernels keep naga's annotated source.
pub fn validate(kernel: &str, wgsl: &str) -> Result<naga::Module> {
    let replaced = replacements().is_ok_and(|r| !r.is_empty());
    let origin = format!("kernels replaced by {KERNEL_DIR_ENV}");
    validate_from(kernel, wgsl, replaced.then_some(origin.as_str()))
}

/// [`validate`], its errors one line tagged `[origin]` where `origin` is given (replaced
/// kernels: the folder they came from), else naga's annotated source.
fn validate_from(kernel: &str, wgsl: &str, origin: Option<&str>) -> Result<naga::Module> {
    validate_with_info(kernel, wgsl, origin).map(|(module, _)| module)
}

/// [`validate_from`], with naga's analysis of the module.
pub(super) fn validate_with_info(
    kernel: &str,
    wgsl: &str,
    origin: Option<&str>,
) -> Result<(naga::Module, naga::valid::ModuleInfo)> {
    let one_line = origin.is_some();
    let error = |message: String, line: Option<u32>| Error::Kernel {
        kernel: kernel.to_string(),
        message: match origin {
            Some(origin) => {
                let at = line.map(|l| format!(" (line {l} of the kernel with its imports)"));
                format!(
                    "{}{} [{origin}]",
                    message.lines().next().unwrap_or_default(),
                    at.unwrap_or_default()
                )
            }
            None => message,
        },
    };
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| {
        let line = e.location(wgsl).map(|l| l.line_number);
        error(
            if one_line {
                e.message().to_string()
            } else {
                e.emit_to_string(wgsl)
            },
            line,
        )
    })?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| {
        let line = e.location(wgsl).map(|l| l.line_number);
        let message = if one_line {
            e.as_inner().to_string()
        } else {
            e.emit_to_string(wgsl)
        };
        error(message, line)
    })?;
    Ok((module, info))
}
