//! The packed variant of a kernel: a float storage texture or float texture bound to a
//! [`crate::graph::PACKED_F16X2`] resource (an `r32uint` texture) is re-declared as `r32uint`,
//! each `textureStore` to it packs its value (`pack_f16x2`) and each `textureLoad` from it
//! unpacks (`unpack_f16x2`, `kernels/shared/packed.wgsl`). One rewrite of any kernel's text, so
//! every kernel that writes or reads a representation (encodings, fused blurs, blur passes, mip
//! chains, summed-area tables' tile passes) has its packed variant without a copy.

/// `wgsl` with storage texture `binding` (declared `texture_storage_2d<from, …>`) stored packed.
pub(super) fn pack_stores(wgsl: &str, binding: &str, from: &str) -> Option<String> {
    let decl = format!("var {binding}: texture_storage_2d<{from},");
    let new = format!("var {binding}: texture_storage_2d<r32uint,");
    let wgsl = replace_once(wgsl, &decl, &new)?;
    let wgsl = rewrite_calls(&wgsl, "textureStore", binding, |args| {
        let (value, head) = args.split_last()?;
        Some(format!(
            "textureStore({}, pack_f16x2({}))",
            head.join(", "),
            value.trim()
        ))
    })?;
    Some(with_module(wgsl))
}

/// `wgsl` with float texture `binding` (declared `texture_2d<f32>`) read packed.
pub(super) fn unpack_loads(wgsl: &str, binding: &str) -> Option<String> {
    let decl = format!("var {binding}: texture_2d<f32>;");
    let new = format!("var {binding}: texture_2d<u32>;");
    let wgsl = replace_once(wgsl, &decl, &new)?;
    let wgsl = rewrite_calls(&wgsl, "textureLoad", binding, |args| {
        Some(format!("unpack_f16x2(textureLoad({}))", args.join(", ")))
    })?;
    Some(with_module(wgsl))
}

/// `wgsl` with the declaration that starts with `head` (up to and including its `;`) replaced
/// by `new`.
pub(super) fn replace_decl(wgsl: &str, head: &str, new: &str) -> Option<String> {
    let at = wgsl.find(head)?;
    let end = at + wgsl[at..].find(';')? + 1;
    Some(format!("{}{new}{}", &wgsl[..at], &wgsl[end..]))
}

fn replace_once(wgsl: &str, from: &str, to: &str) -> Option<String> {
    let at = wgsl.find(from)?;
    Some(format!("{}{to}{}", &wgsl[..at], &wgsl[at + from.len()..]))
}

/// `wgsl` with the helpers of `shared/packed` appended (once).
pub(super) fn with_module(mut wgsl: String) -> String {
    if !wgsl.contains("fn pack_f16x2(") {
        if let Ok(module) = crate::kernels::source("shared/packed") {
            wgsl.push('\n');
            wgsl.push_str(module);
        }
    }
    wgsl
}

/// Every call `f(binding, …)` in `wgsl` replaced by `call(args)` (the call's arguments,
/// trimmed, split at top-level commas), except inside a function with a parameter of that
/// name (it shadows the binding). `None` if a call's parentheses do not close.
pub(super) fn rewrite_calls(
    wgsl: &str,
    f: &str,
    binding: &str,
    call: impl Fn(&[&str]) -> Option<String>,
) -> Option<String> {
    let mut out = String::with_capacity(wgsl.len());
    let mut done = 0;
    let open = format!("{f}(");
    let mut from = 0;
    while let Some(found) = wgsl[from..].find(&open) {
        let at = from + found;
        let args_start = at + open.len();
        from = args_start;
        let preceded = wgsl[..at]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_');
        if preceded
            || identifier_after(&wgsl[args_start..]) != binding
            || shadowed(&wgsl[..at], binding)
        {
            continue;
        }
        let (args, len) = split_args(&wgsl[args_start..])?;
        out.push_str(&wgsl[done..at]);
        out.push_str(&call(&args)?);
        done = args_start + len;
        from = done;
    }
    out.push_str(&wgsl[done..]);
    Some(out)
}

/// Whether the function that `before` ends inside (WGSL functions are module-scope, declared
/// at the start of a line here) has a parameter named `binding`.
pub(super) fn shadowed(before: &str, binding: &str) -> bool {
    let Some(start) = before
        .rfind("\nfn ")
        .map(|at| at + 1)
        .or_else(|| before.starts_with("fn ").then_some(0))
    else {
        return false;
    };
    let header = &before[start..];
    let header = &header[..header.find('{').unwrap_or(header.len())];
    header
        .split(['(', ','])
        .skip(1)
        .any(|p| p.split(':').next().is_some_and(|n| n.trim() == binding) && p.contains(':'))
}

/// The identifier at the start of `s` (after whitespace).
fn identifier_after(s: &str) -> &str {
    let s = s.trim_start();
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The arguments of a call whose text after `(` is `s`, split at top-level commas and
/// trimmed, and the length of `s` up to and including the closing `)`.
pub(super) fn split_args(s: &str) -> Option<(Vec<&str>, usize)> {
    let mut depth = 0usize;
    let mut start = 0;
    let mut args = Vec::new();
    for (i, c) in s.char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' if depth > 0 => depth -= 1,
            ')' => {
                args.push(s[start..i].trim());
                return Some((args, i + 1));
            }
            ',' if depth == 0 => {
                args.push(s[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stores_and_loads_are_rewritten_only_for_their_binding() {
        let wgsl = "@group(0) @binding(0) var src: texture_2d<f32>;\n\
                    @group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;\n\
                    @group(0) @binding(2) var srcb: texture_2d<f32>;\n\
                    fn f(p: vec2<i32>) {\n\
                    textureStore(dst, p, vec4<f32>(g(textureLoad(src, p, 0).r, 1.0), 0.0, 0.0));\n\
                    let b = textureLoad(srcb, p, 0);\n}\n";
        let s = pack_stores(wgsl, "dst", "rg32float").unwrap();
        let s = unpack_loads(&s, "src").unwrap();
        assert!(s.contains("var dst: texture_storage_2d<r32uint, write>;"));
        assert!(s.contains("var src: texture_2d<u32>;"));
        assert!(s.contains("var srcb: texture_2d<f32>;"));
        assert!(s.contains(
            "textureStore(dst, p, pack_f16x2(vec4<f32>(g(unpack_f16x2(textureLoad(src, p, 0)).r, 1.0), 0.0, 0.0)))"
        ));
        assert!(s.contains("let b = textureLoad(srcb, p, 0);"));
        assert_eq!(s.matches("fn pack_f16x2(").count(), 1);
        assert!(pack_stores(wgsl, "nothing", "rg32float").is_none());
        // A parameter of the binding's name shadows it.
        let shadow = "@group(0) @binding(0) var src: texture_2d<f32>;\n\
                      fn g(src: texture_2d<f32>, p: vec2<i32>) -> f32 { return textureLoad(src, p, 0).r; }\n\
                      fn h(p: vec2<i32>) -> f32 { return textureLoad(src, p, 0).r; }\n";
        let s = unpack_loads(shadow, "src").unwrap();
        assert!(s.contains("{ return textureLoad(src, p, 0).r; }\nfn h"));
        assert!(s.contains("{ return unpack_f16x2(textureLoad(src, p, 0)).r; }"));
    }
}
