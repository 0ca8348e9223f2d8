//! The storage-buffer variant of a kernel: a texture or storage texture bound to a resource the
//! executor keeps in a storage buffer ([`crate::graph::Resource::unfiltered`], in a layout that
//! keeps such intermediates in buffers: [`super::KernelLayout::buffers_intermediates`]) is
//! re-declared as a row-major `array` of the bound format's texels. Each `textureStore` to it
//! becomes a store of its element at `y · width + x` (skipped outside the map, as a texture
//! store is), each `textureLoad` a load clamped to the map and widened to the four channels a
//! texture load returns (`(r, 0, 0, 1)`, `(r, g, 0, 1)`), and `textureDimensions` the map's
//! size, a constant of the variant; functions the kernel passes the texture to are specialized
//! to it first (`exec::monomorph`). One rewrite of any kernel's text, as `exec::packed`'s: the
//! kernels keep one source, and the bits they store and load are the texture's bit for bit
//! (32-bit channels are stored as they are; a packed f16 pair as its `r32uint` word).

use super::packed::{replace_decl, rewrite_calls, shadowed, with_module};

/// How a texel of a bound format lives in a buffer element.
struct Element {
    /// The WGSL type of one element.
    ty: &'static str,
    /// The value stored from the texel `v` a kernel stores.
    store: &'static str,
    /// The texel a kernel loads from element `e`.
    load: &'static str,
}

/// The element of a texture of `format` (the texture's format: `r32uint` for a packed f16
/// pair) bound where the kernel declares a float texel (`float`); `None` for a format a
/// buffer does not hold bit for bit (16- and 8-bit channels, whose stores round).
fn element(format: wgpu::TextureFormat, float: bool) -> Option<Element> {
    use wgpu::TextureFormat as T;
    let e = |ty, store, load| Some(Element { ty, store, load });
    match format {
        T::R32Uint if float => e(
            "u32",
            "pack_f16x2(v).x",
            "unpack_f16x2(vec4<u32>(e, 0u, 0u, 1u))",
        ),
        T::R32Float => e("f32", "v.x", "vec4<f32>(e, 0.0, 0.0, 1.0)"),
        T::Rg32Float => e("vec2<f32>", "v.xy", "vec4<f32>(e, 0.0, 1.0)"),
        T::Rgba32Float => e("vec4<f32>", "v", "e"),
        T::R32Uint => e("u32", "v.x", "vec4<u32>(e, 0u, 0u, 1u)"),
        T::Rg32Uint => e("vec2<u32>", "v.xy", "vec4<u32>(e, 0u, 1u)"),
        T::Rgba32Uint => e("vec4<u32>", "v", "e"),
        _ => None,
    }
}

/// Whether a resource held in a texture of `format` can live in a storage buffer bit for bit
/// (every 32-bit-channel storage format, and the packed f16 pair's `r32uint` word).
pub(crate) fn holds(format: wgpu::TextureFormat) -> bool {
    element(format, false).is_some()
}

/// The texel type a kernel declares: `f32` or `u32` (from `texture_2d<T>` or a storage
/// format's name).
fn texel_kind(declared: &str) -> &'static str {
    if declared.contains("uint") || declared.contains("u32") {
        "u32"
    } else {
        "f32"
    }
}

/// `wgsl` with storage texture `binding` (declared `texture_storage_2d<…>`) kept in a storage
/// buffer of `format` texels, `size` = `[width, height]`. `None` where the declaration is not
/// found, or the kernel uses the binding otherwise than by `textureStore` and
/// `textureDimensions`.
pub(super) fn store_to_buffer(
    wgsl: &str,
    binding: &str,
    format: wgpu::TextureFormat,
    [w, h]: [u32; 2],
) -> Option<String> {
    let head = format!("var {binding}: texture_storage_2d<");
    let declared = declared_type(wgsl, &head)?;
    let wgsl = &super::monomorph::specialize_calls(wgsl, binding)?;
    let kind = texel_kind(&declared);
    let el = element(format, kind == "f32")?;
    let wgsl = replace_decl(
        wgsl,
        &head,
        &format!("var<storage, read_write> {binding}: array<{}>;", el.ty),
    )?;
    let wgsl = rewrite_calls(&wgsl, "textureStore", binding, |args| {
        let [_, at, value] = args else { return None };
        Some(format!("{binding}_buffer_store(vec2<i32>({at}), {value})"))
    })?;
    let mut wgsl = dimensions(&wgsl, binding)?;
    let store = el.store;
    wgsl.push_str(&format!(
        "\nconst {binding}_buffer_size: vec2<u32> = vec2<u32>({w}u, {h}u);\n\
         fn {binding}_buffer_store(c: vec2<i32>, v: vec4<{kind}>) {{\n    \
         if all(c >= vec2<i32>(0)) && all(vec2<u32>(c) < {binding}_buffer_size) {{\n        \
         {binding}[u32(c.y) * {w}u + u32(c.x)] = {store};\n    }}\n}}\n"
    ));
    finish(wgsl, binding)
}

/// `wgsl` with texture `binding` (declared `texture_2d<f32>` or `texture_2d<u32>`) read from a
/// storage buffer of `format` texels, `size` = `[width, height]`: loads clamped to the map.
/// `None` as for [`store_to_buffer`].
pub(super) fn load_from_buffer(
    wgsl: &str,
    binding: &str,
    format: wgpu::TextureFormat,
    [w, h]: [u32; 2],
) -> Option<String> {
    let head = format!("var {binding}: texture_2d<");
    let declared = declared_type(wgsl, &head)?;
    let wgsl = &super::monomorph::specialize_calls(wgsl, binding)?;
    let kind = texel_kind(&declared);
    let el = element(format, kind == "f32")?;
    let wgsl = replace_decl(
        wgsl,
        &head,
        &format!("var<storage, read> {binding}: array<{}>;", el.ty),
    )?;
    let wgsl = rewrite_calls(&wgsl, "textureLoad", binding, |args| {
        let [_, at, _level] = args else { return None };
        Some(format!("{binding}_buffer_load(vec2<i32>({at}))"))
    })?;
    let mut wgsl = dimensions(&wgsl, binding)?;
    let load = el.load;
    wgsl.push_str(&format!(
        "\nconst {binding}_buffer_size: vec2<u32> = vec2<u32>({w}u, {h}u);\n\
         fn {binding}_buffer_load(c: vec2<i32>) -> vec4<{kind}> {{\n    \
         let q = vec2<u32>(clamp(c, vec2<i32>(0), vec2<i32>({binding}_buffer_size) - vec2<i32>(1)));\n    \
         let e = {binding}[q.y * {w}u + q.x];\n    return {load};\n}}\n"
    ));
    finish(wgsl, binding)
}

/// The declared type after `head` up to the declaration's `;` (`rg32float, write>` or `f32>`).
fn declared_type(wgsl: &str, head: &str) -> Option<String> {
    let at = wgsl.find(head)? + head.len();
    let end = wgsl[at..].find(';')?;
    Some(wgsl[at..at + end].to_string())
}

/// `textureDimensions(binding)` and `textureDimensions(binding, level)` as the buffer's size.
fn dimensions(wgsl: &str, binding: &str) -> Option<String> {
    rewrite_calls(wgsl, "textureDimensions", binding, |_| {
        Some(format!("{binding}_buffer_size"))
    })
}

/// `wgsl` with the packed f16 helpers where an element uses them; `None` where `binding` is
/// still used otherwise than indexed (a texture builtin the rewrite does not know, the texture
/// passed on to a function).
fn finish(wgsl: String, binding: &str) -> Option<String> {
    if used_unindexed(&wgsl, binding) {
        return None;
    }
    Some(if wgsl.contains("pack_f16x2(") {
        with_module(wgsl)
    } else {
        wgsl
    })
}

/// Whether `wgsl` (comments aside) names `binding` anywhere but in its declaration
/// (`binding:`), indexed (`binding[`) or where a function's parameter of that name shadows it.
fn used_unindexed(wgsl: &str, binding: &str) -> bool {
    let code: String = wgsl
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let word = |c: char| c.is_alphanumeric() || c == '_';
    let mut from = 0;
    while let Some(found) = code[from..].find(binding) {
        let at = from + found;
        let end = at + binding.len();
        from = end;
        let before = code[..at].chars().next_back().is_some_and(word);
        let after = code[end..].chars().next().is_some_and(word);
        if before || after {
            continue;
        }
        let next = code[end..].trim_start().chars().next();
        if matches!(next, Some('[' | ':')) || shadowed(&code[..at], binding) {
            continue;
        }
        return true;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use wgpu::TextureFormat as T;

    const KERNEL: &str = "@group(0) @binding(0) var src: texture_2d<f32>;\n\
        @group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;\n\
        fn f(p: vec2<u32>) {\n\
        let size = textureDimensions(src);\n\
        textureStore(dst, p, textureLoad(src, min(p, size - 1u), 0) * 2.0);\n}\n";

    #[test]
    fn stores_loads_and_sizes_become_buffer_accesses() {
        let s = store_to_buffer(KERNEL, "dst", T::Rg32Float, [5, 3]).unwrap();
        let s = load_from_buffer(&s, "src", T::Rgba32Float, [5, 3]).unwrap();
        assert!(s.contains("var<storage, read_write> dst: array<vec2<f32>>;"));
        assert!(s.contains("var<storage, read> src: array<vec4<f32>>;"));
        assert!(s.contains("let size = src_buffer_size;"));
        assert!(s.contains(
            "dst_buffer_store(vec2<i32>(p), src_buffer_load(vec2<i32>(min(p, size - 1u))) * 2.0);"
        ));
        assert!(s.contains("dst[u32(c.y) * 5u + u32(c.x)] = v.xy;"));
        assert!(s.contains("let e = src[q.y * 5u + q.x];"));
        naga::front::wgsl::parse_str(&format!(
            "{s}\n@compute @workgroup_size(1) fn main() {{ f(vec2<u32>(0u)); }}"
        ))
        .expect("the rewritten kernel parses");
    }

    #[test]
    fn packed_pairs_keep_their_word_and_other_uses_are_refused() {
        let s = store_to_buffer(KERNEL, "dst", T::R32Uint, [4, 4]).unwrap();
        assert!(s.contains("array<u32>"));
        assert!(s.contains("= pack_f16x2(v).x;"));
        assert_eq!(s.matches("fn pack_f16x2(").count(), 1);
        // 16-bit channels round on a texture store: not held bit for bit, not rewritten.
        assert!(store_to_buffer(KERNEL, "dst", T::Rgba16Float, [4, 4]).is_none());
        // A builtin the rewrite does not know is a use it refuses.
        let levels = "@group(0) @binding(0) var src: texture_2d<f32>;\n\
                      fn f() -> u32 { return textureNumLevels(src); }\n";
        assert!(load_from_buffer(levels, "src", T::R32Float, [4, 4]).is_none());
        // The texture passed on to a function: the function specialized to it, then
        // rewritten (`exec::monomorph`); the original, which a parameter of the binding's name
        // shadows, is left as it is.
        let passed = "@group(0) @binding(0) var src: texture_2d<f32>;\n\
                      fn g(src: texture_2d<f32>) -> f32 { return textureLoad(src, vec2(0), 0).x; }\n\
                      fn f() -> f32 { return g(src); } // src\n";
        let s = load_from_buffer(passed, "src", T::R32Float, [4, 4]).unwrap();
        assert!(s.contains("{ return textureLoad(src, vec2(0), 0).x; }"));
        assert!(s.contains("fn f() -> f32 { return g_src(); }"));
        assert!(s.contains("fn g_src() -> f32 { return src_buffer_load(vec2<i32>(vec2(0))).x; }"));
        assert!(load_from_buffer(KERNEL, "nothing", T::R32Float, [4, 4]).is_none());
    }
}
