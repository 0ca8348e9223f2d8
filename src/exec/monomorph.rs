//! A kernel's functions specialized to a global texture it passes them: WGSL passes a storage
//! buffer to a function only through a pointer (which needs its
//! `unrestricted_pointer_parameters` extension), so before `exec::buffers` re-declares a
//! texture as a buffer, every call that hands the texture to a function of the module becomes
//! a call of a copy of that function with the parameter gone and the global named in its place
//! (and so on down the copy's own calls). Each copy is the original's text with one name
//! replaced: the same arithmetic, which the GPU's compiler inlines as it inlined the original.

use super::packed::split_args;

/// Calls specialized at most: a bound on a module's call graph, which a kernel's stays far
/// below (the summed-area lookups nest four deep).
const MAX_COPIES: usize = 256;

/// `wgsl` with every call passing the global `binding` to a function of the module replaced by
/// a call of that function's copy specialized to it (`<function>_<binding>`), recursively.
/// Calls inside a function whose parameter of that name shadows the global are left alone (its
/// copy, once specialized, names the global). `None` where a called function's text does not
/// parse (unbalanced parentheses or braces) or the copies do not end.
pub(super) fn specialize_calls(wgsl: &str, binding: &str) -> Option<String> {
    let mut wgsl = wgsl.to_string();
    for _ in 0..MAX_COPIES {
        let Some(call) = find_call(&wgsl, binding)? else {
            return Some(wgsl);
        };
        let name = format!("{}_{binding}", call.function);
        if !wgsl.contains(&format!("fn {name}(")) {
            let copy = specialized(&wgsl, &call.function, call.index, binding, &name)?;
            wgsl.push('\n');
            wgsl.push_str(&copy);
        }
        let mut args = call.args.clone();
        args.remove(call.index);
        let new = format!("{name}({})", args.join(", "));
        wgsl.replace_range(call.start..call.end, &new);
    }
    None
}

/// A call of a module function with `binding` among its arguments.
struct Call {
    function: String,
    /// The argument that is `binding`.
    index: usize,
    args: Vec<String>,
    /// The call's text, `function(` … `)`.
    start: usize,
    end: usize,
}

/// The first call in `wgsl` of a function the module defines that passes `binding` as an
/// argument, outside functions that shadow it; `Ok(None)` where there is none (the outer
/// `None`: a call's parentheses do not close).
fn find_call(wgsl: &str, binding: &str) -> Option<Option<Call>> {
    for function in functions(wgsl) {
        let open = format!("{function}(");
        let mut from = 0;
        while let Some(found) = wgsl[from..].find(&open) {
            let start = from + found;
            let args_at = start + open.len();
            from = args_at;
            let before = wgsl[..start].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_')
                || wgsl[..start].ends_with("fn ")
                || super::packed::shadowed(&wgsl[..start], binding)
            {
                continue;
            }
            let (args, len) = split_args(&wgsl[args_at..])?;
            if let Some(index) = args.iter().position(|a| *a == binding) {
                return Some(Some(Call {
                    function: function.to_string(),
                    index,
                    args: args.iter().map(|a| a.to_string()).collect(),
                    start,
                    end: args_at + len,
                }));
            }
        }
    }
    Some(None)
}

/// The names of the functions `wgsl` defines (`fn name(` at the start of a line).
fn functions(wgsl: &str) -> Vec<&str> {
    wgsl.lines()
        .filter_map(|l| l.strip_prefix("fn "))
        .filter_map(|l| l.split('(').next())
        .map(str::trim)
        .filter(|n| !n.is_empty())
        .collect()
}

/// The text of function `function` of `wgsl` named `name`, its parameter `index` removed and
/// each use of that parameter's name in its body naming `binding`.
fn specialized(
    wgsl: &str,
    function: &str,
    index: usize,
    binding: &str,
    name: &str,
) -> Option<String> {
    let head = format!("fn {function}(");
    let start = wgsl
        .match_indices(&head)
        .map(|(at, _)| at)
        .find(|&at| at == 0 || wgsl[..at].ends_with('\n'))?;
    let params_at = start + head.len();
    let (params, len) = split_args(&wgsl[params_at..])?;
    let param = params.get(index)?.split(':').next()?.trim().to_string();
    let after_params = params_at + len;
    let body_at = after_params + wgsl[after_params..].find('{')?;
    let body_end = body_at + closing_brace(&wgsl[body_at..])?;
    let ret = &wgsl[after_params..body_at];
    let mut kept: Vec<&str> = params.iter().copied().filter(|p| !p.is_empty()).collect();
    kept.remove(index);
    let body = replace_word(&wgsl[body_at..body_end], &param, binding);
    Some(format!("fn {name}({}){ret}{body}\n", kept.join(", ")))
}

/// The length of `s` (which starts with `{`) up to and including its matching `}`.
fn closing_brace(s: &str) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(i + 1);
                }
            }
            _ => {}
        }
    }
    None
}

/// `s` with every whole-word `from` (not a field after `.`) replaced by `to`.
fn replace_word(s: &str, from: &str, to: &str) -> String {
    let word = |c: char| c.is_alphanumeric() || c == '_';
    let mut out = String::with_capacity(s.len());
    let mut done = 0;
    for (at, _) in s.match_indices(from) {
        let end = at + from.len();
        let before = s[..at].chars().next_back();
        let after = s[end..].chars().next();
        if before.is_some_and(|c| word(c) || c == '.') || after.is_some_and(word) {
            continue;
        }
        out.push_str(&s[done..at]);
        out.push_str(to);
        done = end;
    }
    out.push_str(&s[done..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const NESTED: &str = "@group(0) @binding(0) var tab: texture_2d<u32>;\n\
        @group(0) @binding(1) var other: texture_2d<u32>;\n\
        fn corner(map: texture_2d<u32>, p: vec2<i32>) -> vec4<u32> {\n    \
        return textureLoad(map, p, 0);\n}\n\
        fn window(s: u32, map: texture_2d<u32>, p: vec2<i32>) -> vec4<u32> {\n    \
        let size = textureDimensions(map);\n    \
        return corner(map, p) + corner(map, p + 1) + vec4<u32>(size.x + s);\n}\n\
        fn main_body(p: vec2<i32>) -> vec4<u32> {\n    \
        return window(1u, tab, p) + window(2u, other, p) + corner(tab, p);\n}\n";

    #[test]
    fn calls_passing_the_global_get_copies_down_the_call_graph() {
        let s = specialize_calls(NESTED, "tab").unwrap();
        // The call sites name the copies, without the argument; the other texture's calls and
        // the originals stay.
        assert!(s.contains("return window_tab(1u, p) + window(2u, other, p) + corner_tab(p);"));
        assert!(s.contains("fn window_tab(s: u32, p: vec2<i32>) -> vec4<u32> {"));
        assert!(s.contains("let size = textureDimensions(tab);"));
        assert!(s.contains("return corner_tab(p) + corner_tab(p + 1) + vec4<u32>(size.x + s);"));
        assert!(s.contains(
            "fn corner_tab(p: vec2<i32>) -> vec4<u32> {\n    return textureLoad(tab, p, 0);"
        ));
        assert_eq!(
            s.matches("fn corner_tab(").count(),
            1,
            "one copy a function"
        );
        assert!(s.contains("fn corner(map: texture_2d<u32>, p: vec2<i32>)"));
        let module = format!(
            "{s}\n@compute @workgroup_size(1) fn main() {{ _ = main_body(vec2<i32>(0)); }}"
        );
        let parsed = naga::front::wgsl::parse_str(&module).expect("parses");
        naga::valid::Validator::new(Default::default(), naga::valid::Capabilities::all())
            .validate(&parsed)
            .expect("validates");
        // Nothing to do: unchanged.
        assert_eq!(specialize_calls(NESTED, "absent").unwrap(), NESTED);
    }

    #[test]
    fn a_parameter_of_the_globals_name_is_specialized_too() {
        let shadow = "@group(0) @binding(0) var tab: texture_2d<u32>;\n\
            fn get(tab: texture_2d<u32>) -> u32 {\n    return textureLoad(tab, vec2(0), 0).x;\n}\n\
            fn f() -> u32 {\n    return get(tab);\n}\n";
        let s = specialize_calls(shadow, "tab").unwrap();
        assert!(s.contains("return get_tab();"));
        assert!(s.contains("fn get_tab() -> u32 {\n    return textureLoad(tab, vec2(0), 0).x;"));
        // A body whose braces do not close is refused, not guessed at.
        assert!(
            specialize_calls(
                "fn g(t: texture_2d<u32>) -> u32 {\nfn f() { g(tab); }",
                "tab"
            )
            .is_none()
        );
    }
}
