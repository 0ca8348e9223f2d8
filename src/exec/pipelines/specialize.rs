//! A kernel's WGSL re-declared for the textures a node binds: a storage texture re-typed to the
//! bound format, f16 pairs packed into (or unpacked from) an `r32uint` word, and a constant
//! marked `// #channels <binding>` set to the bound format's channel count.

use crate::error::{Error, Result};
use crate::exec::{buffers, packed};
use crate::kernels::{self, Reflection};

/// The WGSL of kernel `name` as [`KernelCache::get_specialized`](super::KernelCache::get_specialized) compiles it for the texture
/// formats `formats` bound by binding name (no GPU needed: `tests/kernels_validate/`
/// validates every variant a technique can bind).
pub fn specialized_source(name: &str, formats: &[(String, wgpu::TextureFormat)]) -> Result<String> {
    specialized_buffer_source(name, formats, &[], None)
}

/// [`specialized_source`] with the bindings in `buffers` bound to storage buffers of maps of
/// `[width, height]` texels of their format in `formats` (`exec::buffers`), its modules
/// resolved with `modules` in place of the embedded ones where given (a layout's redesigned
/// modules, [`super::KernelLayout::module_sources`]).
pub fn specialized_buffer_source(
    name: &str,
    formats: &[(String, wgpu::TextureFormat)],
    buffers: &[(String, [u32; 2])],
    modules: Option<&kernels::Replacements>,
) -> Result<String> {
    let (_, reflection) = kernels::reflect(name, &kernels::resolve_in(name, None, modules)?)?;
    apply(
        name,
        &changes(name, &reflection, formats, buffers)?,
        modules,
    )
}

/// The changes binding `formats` to kernel `name` needs, the bindings of `buffers` bound to
/// storage buffers of maps of that size.
pub(super) fn changes(
    name: &str,
    reflection: &Reflection,
    formats: &[(String, wgpu::TextureFormat)],
    buffers: &[(String, [u32; 2])],
) -> Result<Vec<Change>> {
    let mut changes = Vec::new();
    for (binding, format) in formats {
        if let Some(b) = reflection.binding(binding) {
            let buffer = buffers.iter().find(|(n, _)| n == binding);
            if let Some(&(_, size)) = buffer {
                changes.push(buffer_change(name, binding, b.ty, *format, size)?);
            } else if let Some(change) = change_for(name, binding, b.ty, *format)? {
                changes.push(change);
            }
            if let Some(change) = channels_for(binding, b.ty, *format) {
                changes.push(change);
            }
        }
    }
    Ok(changes)
}

/// Kernel `name`'s resolved WGSL (with `extra`'s replacements) with `changes` applied.
pub(super) fn apply(
    name: &str,
    changes: &[Change],
    extra: Option<&kernels::Replacements>,
) -> Result<String> {
    apply_changes(name, kernels::resolve_in(name, None, extra)?, changes)
}

/// Kernel `name`'s text `wgsl` with `changes` applied.
pub(super) fn apply_changes(name: &str, mut wgsl: String, changes: &[Change]) -> Result<String> {
    for change in changes {
        wgsl = change.apply(&wgsl).ok_or_else(|| Error::Kernel {
            kernel: name.to_string(),
            message: format!(
                "cannot re-declare `{}` for its bound format",
                change.binding()
            ),
        })?;
    }
    Ok(wgsl)
}

/// How a kernel's binding is re-declared for the texture bound to it.
#[derive(Debug)]
pub(super) enum Change {
    /// A storage texture of another format of the same texel kind.
    Retype {
        binding: String,
        from: &'static str,
        to: &'static str,
    },
    /// A float storage texture bound to a packed texture.
    PackStores { binding: String, from: &'static str },
    /// A float texture bound to a packed texture.
    UnpackLoads { binding: String },
    /// The channel count of a storage texture bound with another count than declared, where
    /// the kernel reads it: `const NAME: u32 = N; // #channels <binding>` (e.g. `blur`'s run
    /// length along columns).
    Channels { binding: String, count: u32 },
    /// A storage texture bound to a storage buffer of a map of `size` texels of `format`.
    StoreToBuffer {
        binding: String,
        format: wgpu::TextureFormat,
        size: [u32; 2],
    },
    /// A texture bound to a storage buffer of a map of `size` texels of `format`.
    LoadFromBuffer {
        binding: String,
        format: wgpu::TextureFormat,
        size: [u32; 2],
    },
}

impl Change {
    fn binding(&self) -> &str {
        match self {
            Change::Retype { binding, .. }
            | Change::PackStores { binding, .. }
            | Change::UnpackLoads { binding }
            | Change::Channels { binding, .. }
            | Change::StoreToBuffer { binding, .. }
            | Change::LoadFromBuffer { binding, .. } => binding,
        }
    }

    fn apply(&self, wgsl: &str) -> Option<String> {
        match self {
            Change::Retype { binding, from, to } => retype_storage(wgsl, binding, from, to),
            Change::PackStores { binding, from } => packed::pack_stores(wgsl, binding, from),
            Change::UnpackLoads { binding } => packed::unpack_loads(wgsl, binding),
            Change::Channels { binding, count } => set_channels(wgsl, binding, *count),
            Change::StoreToBuffer {
                binding,
                format,
                size,
            } => buffers::store_to_buffer(wgsl, binding, *format, *size),
            Change::LoadFromBuffer {
                binding,
                format,
                size,
            } => buffers::load_from_buffer(wgsl, binding, *format, *size),
        }
    }
}

/// The change binding `binding` (of type `ty`) of kernel `name` to a storage buffer of a map of
/// `size` texels of `format` needs: a storage texture's stores or a texture's loads.
fn buffer_change(
    name: &str,
    binding: &str,
    ty: wgpu::BindingType,
    format: wgpu::TextureFormat,
    size: [u32; 2],
) -> Result<Change> {
    let binding = binding.to_string();
    match ty {
        wgpu::BindingType::StorageTexture { .. } => Ok(Change::StoreToBuffer {
            binding,
            format,
            size,
        }),
        wgpu::BindingType::Texture {
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
            ..
        } => Ok(Change::LoadFromBuffer {
            binding,
            format,
            size,
        }),
        _ => Err(Error::Pipeline {
            kernel: name.to_string(),
            message: format!("`{binding}` is no 2-D texture: a storage buffer cannot replace it"),
        }),
    }
}

/// Whether `wgsl` can bind `binding` (of type `ty`) to a storage buffer of a map of `size`
/// texels of `format`: whether the kernel uses it only in ways `exec::buffers` rewrites.
pub(crate) fn rewrites_to_buffer(
    wgsl: &str,
    binding: &str,
    ty: wgpu::BindingType,
    format: wgpu::TextureFormat,
    size: [u32; 2],
) -> bool {
    buffer_change("", binding, ty, format, size).is_ok_and(|c| c.apply(wgsl).is_some())
}

/// Whether `format` is a float texel format.
fn is_float(format: wgpu::TextureFormat) -> bool {
    matches!(
        format.sample_type(None, None),
        Some(wgpu::TextureSampleType::Float { .. })
    )
}

/// The change binding `binding` (of type `ty`) of kernel `name` needs for a texture of
/// `bound` format; refuses a storage texture of another texel kind (float and integer texels
/// are not interchangeable in the kernel's arithmetic) unless it is the packed f16 word.
fn change_for(
    name: &str,
    binding: &str,
    ty: wgpu::BindingType,
    bound: wgpu::TextureFormat,
) -> Result<Option<Change>> {
    let packed = bound == crate::graph::texture_format(crate::graph::PACKED_F16X2);
    match ty {
        wgpu::BindingType::StorageTexture {
            format: declared, ..
        } if declared != bound => {
            if packed && is_float(declared) {
                return Ok(Some(Change::PackStores {
                    binding: binding.to_string(),
                    from: wgsl_storage_format(declared)?,
                }));
            }
            if is_float(declared) != is_float(bound) {
                return Err(Error::Pipeline {
                    kernel: name.to_string(),
                    message: format!(
                        "storage texture `{binding}` is {declared:?}; a {bound:?} texture cannot be bound to it"
                    ),
                });
            }
            Ok(Some(Change::Retype {
                binding: binding.to_string(),
                from: wgsl_storage_format(declared)?,
                to: wgsl_storage_format(bound)?,
            }))
        }
        wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { .. },
            view_dimension: wgpu::TextureViewDimension::D2,
            ..
        } if packed => Ok(Some(Change::UnpackLoads {
            binding: binding.to_string(),
        })),
        _ => Ok(None),
    }
}

/// The channels of a storage texel format as a kernel sees them: a packed
/// [`crate::graph::PACKED_F16X2`] word holds two.
fn channels_of(format: wgpu::TextureFormat) -> u32 {
    if format == crate::graph::texture_format(crate::graph::PACKED_F16X2) {
        2
    } else {
        u32::from(format.components())
    }
}

/// The [`Change::Channels`] binding a `bound` texture to storage texture `binding` (of type
/// `ty`) needs: where the channel counts differ (applied only where the kernel marks a
/// constant for it).
fn channels_for(
    binding: &str,
    ty: wgpu::BindingType,
    bound: wgpu::TextureFormat,
) -> Option<Change> {
    let wgpu::BindingType::StorageTexture {
        format: declared, ..
    } = ty
    else {
        return None;
    };
    let count = channels_of(bound);
    (count != channels_of(declared)).then(|| Change::Channels {
        binding: binding.to_string(),
        count,
    })
}

/// `wgsl` with the constant marked `// #channels <binding>` (`const NAME: u32 = N;`, the
/// declared format's count) set to `count`; unchanged where no constant is marked. None for
/// a marked line of another shape.
fn set_channels(wgsl: &str, binding: &str, count: u32) -> Option<String> {
    let marker = format!("// #channels {binding}");
    let mut out = String::with_capacity(wgsl.len());
    for line in wgsl.split_inclusive('\n') {
        let Some(code) = line.trim_end().strip_suffix(&marker) else {
            out.push_str(line);
            continue;
        };
        let (decl, value) = code.trim_end().split_once(" = ")?;
        if !decl.trim_start().starts_with("const ") || !decl.ends_with(": u32") {
            return None;
        }
        value.strip_suffix("u;")?.parse::<u32>().ok()?;
        out.push_str(&format!("{decl} = {count}u; {marker}\n"));
    }
    Some(out)
}

/// The WGSL name of a storage texel format.
pub fn wgsl_storage_format(f: wgpu::TextureFormat) -> Result<&'static str> {
    use wgpu::TextureFormat as T;
    Ok(match f {
        T::R32Float => "r32float",
        T::Rg32Float => "rg32float",
        T::Rgba32Float => "rgba32float",
        T::Rgba16Float => "rgba16float",
        T::Rgba16Unorm => "rgba16unorm",
        T::Rgba8Unorm => "rgba8unorm",
        T::R32Uint => "r32uint",
        T::Rg32Uint => "rg32uint",
        T::Rgba32Uint => "rgba32uint",
        other => {
            return Err(Error::Invalid(format!(
                "{other:?} is not a storage format shadowgraph uses"
            )));
        }
    })
}

/// `wgsl` with the storage texture `binding` declared as `to` instead of `from`.
fn retype_storage(wgsl: &str, binding: &str, from: &str, to: &str) -> Option<String> {
    let decl = format!("var {binding}: texture_storage_2d<{from},");
    let at = wgsl.find(&decl)?;
    let new = format!("var {binding}: texture_storage_2d<{to},");
    Some(format!("{}{new}{}", &wgsl[..at], &wgsl[at + decl.len()..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MARKED: &str =
        "const A: u32 = 1u;\nconst DST_CHANNELS: u32 = 2u; // #channels dst\nfn f() {}\n";

    #[test]
    fn set_channels_rewrites_only_the_marked_constant() {
        let out = set_channels(MARKED, "dst", 4).unwrap();
        assert_eq!(
            out,
            "const A: u32 = 1u;\nconst DST_CHANNELS: u32 = 4u; // #channels dst\nfn f() {}\n"
        );
        // Another binding's marker, or none: unchanged.
        assert_eq!(set_channels(MARKED, "src", 4).unwrap(), MARKED);
        // A marked line that is not a u32 constant is refused, not guessed at.
        assert!(set_channels("let c = 2u; // #channels dst\n", "dst", 4).is_none());
        assert!(set_channels("const C: i32 = 2; // #channels dst\n", "dst", 4).is_none());
    }

    #[test]
    fn blur_sees_the_bound_formats_channels() {
        use wgpu::TextureFormat as T;
        let channels = |f: T| {
            let wgsl = specialized_source("blur", &[("dst".to_string(), f)]).unwrap();
            wgsl.lines()
                .find(|l| l.ends_with("// #channels dst"))
                .expect("blur marks DST_CHANNELS")
                .to_string()
        };
        assert!(channels(T::Rg32Float).contains("= 2u;"));
        assert!(channels(T::R32Float).contains("= 1u;"));
        assert!(channels(T::Rgba32Float).contains("= 4u;"));
        assert!(channels(T::Rgba16Float).contains("= 4u;"));
        let packed = crate::graph::texture_format(crate::graph::PACKED_F16X2);
        assert!(channels(packed).contains("= 2u;"));
    }
}
