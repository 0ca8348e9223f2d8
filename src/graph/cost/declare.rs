//! Cost declarations written beside the WGSL they describe, and the values they name.
//!
//! A compute kernel declares, in comment lines of its own file, what each of its bindings
//! moves per dispatch:
//!
//! ```text
//! // #traffic src: (WG_SIZE + 2 * params.radius) per group
//! // #traffic dst: all
//! ```
//!
//! `all` is every texel of the bound texture (the bound mip level) once; `E per group` is `E`
//! texels loaded or stored by each workgroup (a tile and its halo: a texel two workgroups both
//! load counts twice, a texel one workgroup loads twice once); `E per texel of b` is `E` texels
//! for every texel of the texture bound to binding `b` (a small table read once per texel of
//! the map); `none` moves nothing worth counting (a counter). `E` is an [`Expr`] over the
//! kernel's WGSL constants, its uniform's fields, `params.<field>`, and the sizes of the
//! textures bound to its bindings, `<binding>.width` and `<binding>.height` (a row workgroup
//! clipped to the map's width).
//!
//! A function of the shading side that reads a map declares its fetches per call:
//!
//! ```text
//! // #fetches vis_pcss: l.blocker_samples + l.filter_samples
//! ```
//!
//! over the fields of the light, `l.<field>` (WGSL's `struct Light`), WGSL constants, and the
//! fetches of other declared functions by name.
//!
//! A kernel may have a pipeline constant set per graph node from the node's parameters,
//! compiling one pipeline for each value (`exec::KernelCache`):
//!
//! ```text
//! // #override STRIP_RADIUS: select(7, 4, params.blur.radius <= 4)
//! ```
//!
//! names an `override` of the kernel and an [`Expr`] over its WGSL constants and
//! `params.<field>`. A CPU driver runs both sides of a branch on a run-time value; a constant
//! folds one away.

use std::collections::HashMap;

use super::expr::Expr;
use crate::error::{Error, Result};

/// What one binding moves per dispatch.
#[derive(Clone, Debug, PartialEq)]
pub enum Pattern {
    /// Every texel of the bound texture (or the whole bound buffer), once.
    All,
    /// Nothing worth counting (e.g. a counter).
    None,
    /// This many texels per workgroup.
    PerGroup(Expr),
    /// This many texels per texel of the texture bound to another binding.
    PerTexelOf(Expr, String),
}

fn kernel_error(kernel: &str, message: String) -> Error {
    Error::Kernel {
        kernel: kernel.to_string(),
        message,
    }
}

/// The `// #<directive> name: value` lines of `text`, as (name, value, line number).
fn directives<'a>(text: &'a str, directive: &str) -> Vec<(&'a str, &'a str, usize)> {
    let prefix = format!("// #{directive} ");
    text.lines()
        .enumerate()
        .filter_map(|(i, line)| {
            let rest = line.trim().strip_prefix(&prefix)?;
            let (name, value) = rest.split_once(':').unwrap_or((rest, ""));
            Some((name.trim(), value.trim(), i + 1))
        })
        .collect()
}

/// The `// #traffic` declarations of kernel `kernel` (its own file's text), by binding name.
pub fn traffic(kernel: &str, text: &str) -> Result<HashMap<String, Pattern>> {
    let mut out = HashMap::new();
    for (name, value, line) in directives(text, "traffic") {
        let expr = |e: &str| {
            Expr::parse(e.trim())
                .map_err(|m| kernel_error(kernel, format!("line {line}: #traffic {name}: {m}")))
        };
        let pattern = match value {
            "all" => Pattern::All,
            "none" => Pattern::None,
            v => match (v.strip_suffix("per group"), v.split_once("per texel of")) {
                (Some(e), _) => Pattern::PerGroup(expr(e)?),
                (None, Some((e, of))) => Pattern::PerTexelOf(expr(e)?, of.trim().to_string()),
                (None, None) => {
                    return Err(kernel_error(
                        kernel,
                        format!(
                            "line {line}: #traffic {name}: expected `all`, `none`, \
                             `<expression> per group` or `<expression> per texel of \
                             <binding>`, found `{v}`"
                        ),
                    ));
                }
            },
        };
        if out.insert(name.to_string(), pattern).is_some() {
            return Err(kernel_error(
                kernel,
                format!("line {line}: binding `{name}` is declared twice"),
            ));
        }
    }
    Ok(out)
}

/// The `// #override` declarations in `text` (a resolved kernel: imports included): the
/// pipeline constants a node's parameters set, as (override name, expression), in order.
pub fn node_overrides(kernel: &str, text: &str) -> Result<Vec<(String, Expr)>> {
    let mut out: Vec<(String, Expr)> = Vec::new();
    for (name, value, line) in directives(text, "override") {
        let e = Expr::parse(value)
            .map_err(|m| kernel_error(kernel, format!("line {line}: #override {name}: {m}")))?;
        if out.iter().any(|(n, _)| n == name) {
            return Err(kernel_error(
                kernel,
                format!("line {line}: override `{name}` is declared twice"),
            ));
        }
        out.push((name.to_string(), e));
    }
    Ok(out)
}

/// The `// #fetches` declarations in `text` (a resolved module: imports included), by function.
pub fn fetches(label: &str, text: &str) -> Result<HashMap<String, Expr>> {
    let mut out = HashMap::new();
    for (name, value, line) in directives(text, "fetches") {
        let e = Expr::parse(value)
            .map_err(|m| kernel_error(label, format!("line {line}: #fetches {name}: {m}")))?;
        if out.insert(name.to_string(), e).is_some() {
            return Err(kernel_error(
                label,
                format!("line {line}: function `{name}` is declared twice"),
            ));
        }
    }
    Ok(out)
}

/// The module's named constants with a numeric value (`const WG_SIZE: u32 = 128u;`).
pub fn constants(module: &naga::Module) -> HashMap<String, f64> {
    module
        .constants
        .iter()
        .filter_map(|(_, c)| {
            let v = match module.global_expressions[c.init] {
                naga::Expression::Literal(l) => literal(l)?,
                _ => return None,
            };
            Some((c.name.clone()?, v))
        })
        .collect()
}

fn literal(l: naga::Literal) -> Option<f64> {
    use naga::Literal as L;
    Some(match l {
        L::U32(v) => f64::from(v),
        L::I32(v) => f64::from(v),
        L::F32(v) => f64::from(v),
        L::F64(v) => v,
        L::AbstractInt(v) => v as f64,
        L::AbstractFloat(v) => v,
        _ => return None,
    })
}

/// Reads the scalar field `field` (a dotted path into nested structs, e.g. `blur.radius`) of a
/// value of WGSL struct type `ty` from `bytes` (its
/// `#[repr(C)]` mirror, laid out as naga lays out the struct).
pub fn struct_field(
    module: &naga::Module,
    ty: naga::Handle<naga::Type>,
    bytes: &[u8],
    field: &str,
) -> std::result::Result<f64, String> {
    // A dotted path (`blur.radius`) walks into nested structs, adding their offsets.
    let mut ty = ty;
    let mut at = 0usize;
    for part in field.split('.') {
        let naga::TypeInner::Struct { members, .. } = &module.types[ty].inner else {
            return Err(format!("`{field}`: not a struct before `{part}`"));
        };
        let m = members
            .iter()
            .find(|m| m.name.as_deref() == Some(part))
            .ok_or_else(|| format!("no field `{field}`"))?;
        at += m.offset as usize;
        ty = m.ty;
    }
    let word: [u8; 4] = bytes
        .get(at..at + 4)
        .and_then(|b| b.try_into().ok())
        .ok_or_else(|| format!("field `{field}` lies past the {} bytes given", bytes.len()))?;
    match module.types[ty].inner {
        naga::TypeInner::Scalar(s) if s.width == 4 => Ok(match s.kind {
            naga::ScalarKind::Uint => f64::from(u32::from_le_bytes(word)),
            naga::ScalarKind::Sint => f64::from(i32::from_le_bytes(word)),
            naga::ScalarKind::Float => f64::from(f32::from_le_bytes(word)),
            _ => return Err(format!("field `{field}` is not a number")),
        }),
        _ => Err(format!("field `{field}` is not a 32-bit scalar")),
    }
}

/// The value of name `n` in a kernel's declarations: one of its constants (`consts`, as
/// [`constants`] reads them), or `params.<field>` of its `params` uniform (`params`: the
/// uniform's type and the bytes a dispatch binds). Other names are the caller's to resolve.
pub fn constant_or_param(
    n: &str,
    consts: &HashMap<String, f64>,
    module: &naga::Module,
    params: Option<(naga::Handle<naga::Type>, &[u8])>,
) -> std::result::Result<f64, String> {
    if let Some(v) = consts.get(n) {
        return Ok(*v);
    }
    match (n.strip_prefix("params."), params) {
        (Some(field), Some((ty, bytes))) => struct_field(module, ty, bytes, field),
        _ => Err(format!("`{n}` is neither a constant nor `params.<field>`")),
    }
}

/// The type of the global variable `name` (e.g. the kernel's `params` uniform).
pub fn global_type(module: &naga::Module, name: &str) -> Option<naga::Handle<naga::Type>> {
    module
        .global_variables
        .iter()
        .find(|(_, g)| g.name.as_deref() == Some(name))
        .map(|(_, g)| g.ty)
}

/// The struct type named `name` (e.g. `Light`).
pub fn named_type(module: &naga::Module, name: &str) -> Option<naga::Handle<naga::Type>> {
    module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .map(|(h, _)| h)
}
