//! Kernels with their workgroup memory poisoned: before `main`'s body runs, every entry of every
//! `var<workgroup>` is filled with the bit pattern [`POISON`] (a NaN as f32, 2 143 289 345 as
//! u32) and the workgroup waits at a barrier. A kernel that reads an entry it has not written
//! in this workgroup then reads the poison instead of what the device left there, so its outputs
//! change; one that writes before it reads gives the same bits (`tests/workgroup_memory.rs`).

use naga::{AddressSpace, ArraySize, Binding, BuiltIn, ScalarKind, TypeInner};
use shadowgraph::low_level::kernels::{self, KernelId, Replacements};

/// The poison's bits.
pub const POISON: u32 = 0x7FC0_0001;

/// WGSL for the poison as a value of scalar or vector type `inner`.
fn poison_value(inner: &TypeInner, what: &str) -> String {
    let scalar = |s: naga::Scalar| -> (&'static str, String) {
        assert_eq!(s.width, 4, "{what}: a {}-byte scalar", s.width);
        match s.kind {
            ScalarKind::Float => ("f32", format!("bitcast<f32>({POISON:#x}u)")),
            ScalarKind::Uint => ("u32", format!("{POISON:#x}u")),
            ScalarKind::Sint => ("i32", format!("bitcast<i32>({POISON:#x}u)")),
            k => panic!("{what}: no poison for {k:?}"),
        }
    };
    match *inner {
        TypeInner::Scalar(s) => scalar(s).1,
        TypeInner::Vector { size, scalar: s } => {
            let (name, v) = scalar(s);
            format!("vec{}<{name}>({v})", size as u8)
        }
        ref other => panic!("{what}: no poison for {other:?}"),
    }
}

/// `wgsl` (a resolved kernel) with its workgroup memory poisoned, or `None` when it declares
/// none. Panics on what it cannot poison (a struct, an atomic, a runtime-sized array, an
/// entry point `main` it cannot find).
pub fn poisoned(name: &str, wgsl: &str) -> Option<String> {
    let module = naga::front::wgsl::parse_str(wgsl).unwrap_or_else(|e| panic!("{name}: {e}"));
    let globals: Vec<_> = module
        .global_variables
        .iter()
        .filter(|(_, g)| g.space == AddressSpace::WorkGroup)
        .collect();
    if globals.is_empty() {
        return None;
    }
    let entry = module
        .entry_points
        .iter()
        .find(|e| e.name == "main")
        .unwrap_or_else(|| panic!("{name}: no entry point `main`"));
    // The workgroup's invocations, a WGSL expression: a number, or where the size is an
    // override of the layout (`shared/encode_blur`'s `LANES`), the override's name.
    let invocations = match entry.workgroup_size_overrides {
        None => format!("{}u", entry.workgroup_size.iter().product::<u32>()),
        Some([Some(x), None, None]) => match module.global_expressions[x] {
            naga::Expression::Override(o) => module.overrides[o].name.clone().expect("named"),
            ref e => panic!("{name}: a workgroup size of {e:?}"),
        },
        Some(sizes) => panic!("{name}: a workgroup size of {sizes:?}"),
    };
    // The invocation's index: `main`'s own argument, or one added.
    let index = entry
        .function
        .arguments
        .iter()
        .find_map(|a| match a.binding {
            Some(Binding::BuiltIn(BuiltIn::LocalInvocationIndex)) => a.name.clone(),
            _ => None,
        });
    let mut block = String::from("\n    // poisoned workgroup memory (tests/common/poison.rs)\n");
    let li = index.clone().unwrap_or_else(|| "sg_poison_li".into());
    for (_, g) in &globals {
        let var = g.name.clone().expect("a named workgroup variable");
        let what = format!("{name}: `{var}`");
        match module.types[g.ty].inner {
            TypeInner::Array {
                base,
                size: ArraySize::Constant(n),
                ..
            } => {
                let v = poison_value(&module.types[base].inner, &what);
                block += &format!(
                    "    for (var sg_i = {li}; sg_i < {n}u; sg_i += {invocations}) {{ {var}[sg_i] = {v}; }}\n"
                );
            }
            ref inner => {
                let v = poison_value(inner, &what);
                block += &format!("    if {li} == 0u {{ {var} = {v}; }}\n");
            }
        }
    }
    block += "    workgroupBarrier();\n";

    assert_eq!(
        wgsl.matches("fn main(").count(),
        1,
        "{name}: one `fn main(`"
    );
    let at = wgsl.find("fn main(").unwrap() + "fn main(".len();
    let mut out = wgsl[..at].to_string();
    if index.is_none() {
        out += "@builtin(local_invocation_index) sg_poison_li: u32";
        if !wgsl[at..].trim_start().starts_with(')') {
            out += ", ";
        }
    }
    let open = at + wgsl[at..].find('{').expect("main's body");
    out += &wgsl[at..=open];
    out += &block;
    out += &wgsl[open + 1..];
    kernels::validate(name, &out).unwrap_or_else(|e| panic!("{name} poisoned: {e}\n{out}"));
    Some(out)
}

/// Every kernel of `kernels/` that declares workgroup memory, poisoned (as replacements of the
/// kernels' files: their imports resolved), by name.
pub fn poisoned_kernels() -> Replacements {
    poisoned_kernels_in(None)
}

/// [`poisoned_kernels`] with the files of `variant` (a benchmark variant's folder, as
/// `kernels::read_replacements` reads it) in place of those they name, and those files too.
pub fn poisoned_kernels_in(variant: Option<&Replacements>) -> Replacements {
    // The variant's own files stay for the kernels without workgroup memory.
    let mut out: Replacements = variant.cloned().unwrap_or_default();
    for id in KernelId::ALL {
        // A kernel with a `// #generated` block (the shading pass) resolves only with one.
        let Ok(wgsl) = kernels::resolve_in(id.name(), None, variant) else {
            continue;
        };
        if let Some(p) = poisoned(id.name(), &wgsl) {
            out.insert(id.name().to_string(), p);
        }
    }
    out
}
