//! Pipeline constants set per graph node from its parameters (`// #override NAME: EXPR` in a
//! kernel, `graph::cost::declare::node_overrides`): the executor compiles one pipeline for
//! each set of values, so a kernel can fold away, at compile time, what depends on a node's
//! parameter (the fused blurs' strips: the window of a radius up to 4 or up to 7). A CPU
//! driver such as llvmpipe runs both sides of a branch on a run-time value under masks.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::graph::cost::declare;
use crate::graph::cost::expr::Expr;
use crate::kernels;

/// A kernel's `#override` declarations, with what evaluating them needs.
pub(super) struct NodeOverrides {
    decls: Vec<(String, Expr)>,
    consts: HashMap<String, f64>,
    params: Option<naga::Handle<naga::Type>>,
    /// The kernel's module; none where it declares nothing (not parsed then).
    module: Option<naga::Module>,
}

impl NodeOverrides {
    /// The declarations of kernel `name` (its resolved source `wgsl`); an `#override` naming
    /// no `override` of the kernel is an error naming both.
    pub(super) fn new(name: &str, wgsl: &str) -> Result<Self> {
        let decls = declare::node_overrides(name, wgsl)?;
        if decls.is_empty() {
            return Ok(Self {
                decls,
                consts: HashMap::new(),
                params: None,
                module: None,
            });
        }
        let (module, _) = kernels::reflect(name, wgsl)?;
        for (o, _) in &decls {
            if !module
                .overrides
                .iter()
                .any(|(_, d)| d.name.as_deref() == Some(o.as_str()))
            {
                return Err(Error::Kernel {
                    kernel: name.to_string(),
                    message: format!("`// #override {o}` names no `override {o}` of the kernel"),
                });
            }
        }
        Ok(Self {
            consts: declare::constants(&module),
            params: declare::global_type(&module, "params"),
            decls,
            module: Some(module),
        })
    }

    /// The values for a node of kernel `kernel` named `node` with parameters `params` (its
    /// first dispatch's), in declaration order.
    pub(super) fn values(
        &self,
        kernel: &str,
        node: &str,
        params: &[u8],
    ) -> Result<Vec<(String, f64)>> {
        self.decls
            .iter()
            .map(|(name, e)| {
                let error = |m: String| Error::Kernel {
                    kernel: kernel.to_string(),
                    message: format!("node `{node}`: #override {name}: {m}"),
                };
                let module = self
                    .module
                    .as_ref()
                    .expect("parsed where there are declarations");
                let mut lookup = |n: &str| {
                    let bound = self.params.map(|ty| (ty, params));
                    declare::constant_or_param(n, &self.consts, module, bound)
                };
                let v = e.eval(&mut lookup).map_err(error)?;
                // A pipeline constant wgpu would refuse with its own text.
                if !v.is_finite() {
                    return Err(error(format!("{v} is not a number a pipeline takes")));
                }
                Ok((name.clone(), v))
            })
            .collect()
    }

    /// Whether the kernel declares none.
    pub(super) fn is_empty(&self) -> bool {
        self.decls.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A kernel whose override follows a field of its parameters.
    const KERNEL: &str = "struct P { a: u32, b: f32 }\n\
        @group(0) @binding(0) var<uniform> params: P;\n\
        const LIMIT: u32 = 4u;\n\
        // #override N: select(7, LIMIT, params.a <= LIMIT)\n\
        override N: u32 = 7u;\n\
        @compute @workgroup_size(1)\nfn main() { _ = params.a; }\n";

    #[test]
    fn each_node_gets_the_value_its_parameters_give() {
        let o = NodeOverrides::new("k", KERNEL).unwrap();
        assert!(!o.is_empty());
        for (a, want) in [(0u32, 4.0), (4, 4.0), (5, 7.0), (40, 7.0)] {
            let params = bytemuck::bytes_of(&[a, 0]).to_vec();
            assert_eq!(
                o.values("k", "n", &params).unwrap(),
                [("N".to_string(), want)]
            );
        }
        // Too few bytes: an error naming the node, not a guess.
        let e = o.values("k", "short", &[0u8; 2]).unwrap_err().to_string();
        assert!(e.contains("short") && e.contains("#override N"), "{e}");
        // A value past any number: refused before wgpu sees it.
        let inf = KERNEL.replace("select(7, LIMIT, params.a <= LIMIT)", "1 / params.b");
        let o = NodeOverrides::new("k", &inf).unwrap();
        let params = bytemuck::bytes_of(&[1u32, 0]).to_vec();
        let e = o.values("k", "zero", &params).unwrap_err().to_string();
        assert!(e.contains("zero") && e.contains("not a number"), "{e}");
    }

    #[test]
    fn an_override_that_is_not_declared_is_refused() {
        let none = "@compute @workgroup_size(1)\nfn main() {}\n";
        assert!(NodeOverrides::new("k", none).unwrap().is_empty());
        let bad = "// #override M: 1\n@compute @workgroup_size(1)\nfn main() {}\n";
        let e = NodeOverrides::new("k", bad).err().unwrap().to_string();
        assert!(e.contains("override M") && e.contains('k'), "{e}");
        let twice = format!("// #override N: 1\n{KERNEL}");
        let e = NodeOverrides::new("k", &twice).err().unwrap().to_string();
        assert!(e.contains("declared twice"), "{e}");
    }
}
