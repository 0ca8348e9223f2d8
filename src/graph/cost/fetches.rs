//! Texture fetches per pixel of the shading pass's visibility functions, from the WGSL.
//!
//! Every function that fetches (a `textureLoad`, `textureSample*` or `textureGather*` call,
//! directly or through a callee) declares its fetches per call beside its definition
//! (`// #fetches name: expression`, see [`super::declare`]): `plan` prints them without a GPU.
//! The one function asked for may be undeclared (the shading kernel's generated
//! `light<i>_visibility`): its count is then summed from the calls of its body, which must not
//! loop. A fetching function without a declaration is an error naming it.
//!
//! A declaration is the count of a pixel that takes every lookup (PCSS without a blocker stops
//! after its search; a table lookup at the map's corner skips its zero texels). A test runs the
//! shading kernel with every fetch counted and checks that no pixel exceeds the declaration
//! and that some pixel reaches it (`tests/cost.rs`).

use std::collections::HashMap;

use super::declare;
use super::expr::Expr;
use crate::error::{Error, Result};
use crate::kernels;

/// Fetches per call of functions of one WGSL module, for one light.
pub struct Fetches<'a> {
    label: String,
    module: naga::Module,
    decls: HashMap<String, Expr>,
    consts: HashMap<String, f64>,
    light: &'a [u8],
    memo: HashMap<String, f64>,
    active: Vec<String>,
}

impl<'a> Fetches<'a> {
    /// Reads the declarations of `wgsl` (resolved: imported modules included), a module with
    /// a `struct Light`; `light` holds that struct's bytes (`technique::LightGpu`).
    pub fn new(label: &str, wgsl: &str, light: &'a [u8]) -> Result<Self> {
        let module = kernels::validate(label, wgsl)?;
        Ok(Self {
            label: label.to_string(),
            decls: declare::fetches(label, wgsl)?,
            consts: declare::constants(&module),
            module,
            light,
            memo: HashMap::new(),
            active: Vec::new(),
        })
    }

    fn error(&self, message: String) -> Error {
        Error::Kernel {
            kernel: self.label.clone(),
            message,
        }
    }

    /// Fetches of one call of `function`; it may be undeclared (then summed from its body).
    pub fn count(&mut self, function: &str) -> Result<f64> {
        self.count_of(function, true).map_err(|m| self.error(m))
    }

    /// Fetches of one call of `function` as a callee: a function that fetches must be
    /// declared.
    pub fn count_declared(&mut self, function: &str) -> Result<f64> {
        self.count_of(function, false).map_err(|m| self.error(m))
    }

    /// The declared functions, by name.
    pub fn declared(&self) -> Vec<String> {
        let mut v: Vec<String> = self.decls.keys().cloned().collect();
        v.sort();
        v
    }

    /// Every function of the module by name.
    pub fn functions(&self) -> Vec<String> {
        self.module
            .functions
            .iter()
            .filter_map(|(_, f)| f.name.clone())
            .collect()
    }

    /// The count summed from `function`'s body (callees by their counts), `None` when its body
    /// loops: the check of a declaration against the code it declares.
    pub fn count_from_body(&mut self, function: &str) -> Result<Option<f64>> {
        let f = self.function(function).map_err(|m| self.error(m))?;
        match self.body(&f) {
            Ok(v) => Ok(Some(v)),
            Err(m) if m.starts_with(LOOPS) => Ok(None),
            Err(m) => Err(self.error(m)),
        }
    }

    fn function(&self, name: &str) -> std::result::Result<naga::Function, String> {
        self.module
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(name))
            .map(|(_, f)| f.clone())
            .ok_or_else(|| format!("no function `{name}`"))
    }

    fn count_of(&mut self, name: &str, top: bool) -> std::result::Result<f64, String> {
        if let Some(v) = self.memo.get(name) {
            return Ok(*v);
        }
        if self.active.iter().any(|a| a == name) {
            return Err(format!("`{name}` refers to itself"));
        }
        self.active.push(name.to_string());
        let v = match self.decls.get(name).cloned() {
            Some(e) => e
                .eval(&mut |n| self.value(n))
                .map_err(|m| format!("#fetches {name}: {m}")),
            None => {
                let f = self.function(name)?;
                let v = self.body(&f).map_err(|m| format!("`{name}`: {m}"))?;
                if v > 0.0 && !top {
                    Err(format!(
                        "`{name}` fetches but has no `// #fetches {name}: …` declaration"
                    ))
                } else {
                    Ok(v)
                }
            }
        };
        self.active.pop();
        let v = v?;
        self.memo.insert(name.to_string(), v);
        Ok(v)
    }

    /// A name in a declaration: a light field, a constant, or a function's fetches.
    fn value(&mut self, n: &str) -> std::result::Result<f64, String> {
        if let Some(field) = n.strip_prefix("l.") {
            // The renderer's `Light`, or the exported library's `sg_Light`.
            let ty = declare::named_type(&self.module, "Light")
                .or_else(|| declare::named_type(&self.module, "sg_Light"))
                .ok_or("no `struct Light`")?;
            return declare::struct_field(&self.module, ty, self.light, field);
        }
        if let Some(v) = self.consts.get(n) {
            return Ok(*v);
        }
        self.count_of(n, false)
    }

    fn body(&mut self, f: &naga::Function) -> std::result::Result<f64, String> {
        self.block(f, &f.body)
    }

    fn block(&mut self, f: &naga::Function, b: &naga::Block) -> std::result::Result<f64, String> {
        use naga::Statement as S;
        let mut total = 0.0;
        for s in b.iter() {
            total += match s {
                S::Emit(range) => range
                    .clone()
                    .filter(|h| is_fetch(&f.expressions[*h]))
                    .count() as f64,
                S::Block(inner) => self.block(f, inner)?,
                S::If { accept, reject, .. } => self.block(f, accept)?.max(self.block(f, reject)?),
                S::Switch { cases, .. } => {
                    let mut most: f64 = 0.0;
                    for c in cases {
                        most = most.max(self.block(f, &c.body)?);
                    }
                    most
                }
                S::Loop {
                    body, continuing, ..
                } => {
                    if self.block(f, body)? + self.block(f, continuing)? > 0.0 {
                        return Err(format!(
                            "{LOOPS}: its count depends on the loop, declare it with \
                             `// #fetches <function>: <expression>`"
                        ));
                    }
                    0.0
                }
                S::Call { function, .. } => {
                    let callee = self.module.functions[*function]
                        .name
                        .clone()
                        .unwrap_or_default();
                    self.count_of(&callee, false)?
                }
                _ => 0.0,
            };
        }
        Ok(total)
    }
}

const LOOPS: &str = "fetches inside a loop";

fn is_fetch(e: &naga::Expression) -> bool {
    matches!(
        e,
        naga::Expression::ImageLoad { .. } | naga::Expression::ImageSample { .. }
    )
}
