//! The wgpu binding type of each WGSL global a kernel binds: buffers, samplers, sampled,
//! depth and storage textures, a float texture filterable only where `textureSample*` reads it.

/// The texture globals that some `textureSample*` without a depth reference reads, directly or
/// through function arguments (followed up the calls to a fixed point): those bind as
/// filterable float, every other float texture as unfilterable, which also admits
/// `depth32float` views and needs no `FLOAT32_FILTERABLE` for 32-bit formats.
pub(super) fn sampled_images(
    module: &naga::Module,
) -> std::collections::HashSet<naga::Handle<naga::GlobalVariable>> {
    use naga::{Expression, Statement};
    use std::collections::HashSet;
    // Functions by index: the module's, then the entry points'.
    let functions: Vec<&naga::Function> = module
        .functions
        .iter()
        .map(|(_, f)| f)
        .chain(module.entry_points.iter().map(|e| &e.function))
        .collect();
    let mut globals = HashSet::new();
    // (function index, argument index) pairs that reach a sample.
    let mut args: HashSet<(usize, u32)> = HashSet::new();
    let mark = |f: &naga::Function,
                fi: usize,
                e: naga::Handle<Expression>,
                globals: &mut HashSet<_>,
                args: &mut HashSet<(usize, u32)>| {
        match f.expressions[e] {
            Expression::GlobalVariable(g) => globals.insert(g),
            Expression::FunctionArgument(a) => args.insert((fi, a)),
            _ => false,
        }
    };
    for (fi, f) in functions.iter().enumerate() {
        for (_, e) in f.expressions.iter() {
            if let Expression::ImageSample {
                image,
                depth_ref: None,
                ..
            } = *e
            {
                mark(f, fi, image, &mut globals, &mut args);
            }
        }
    }
    fn calls<'a>(block: &'a naga::Block, out: &mut Vec<(usize, &'a [naga::Handle<Expression>])>) {
        for st in block.iter() {
            match st {
                Statement::Call {
                    function,
                    arguments,
                    ..
                } => out.push((function.index(), arguments)),
                Statement::Block(b) => calls(b, out),
                Statement::If { accept, reject, .. } => {
                    calls(accept, out);
                    calls(reject, out);
                }
                Statement::Switch { cases, .. } => cases.iter().for_each(|c| calls(&c.body, out)),
                Statement::Loop {
                    body, continuing, ..
                } => {
                    calls(body, out);
                    calls(continuing, out);
                }
                _ => {}
            }
        }
    }
    // Per function: (callee index, arguments) of every call it makes.
    type Calls<'a> = Vec<(usize, &'a [naga::Handle<Expression>])>;
    let call_lists: Vec<Calls> = functions
        .iter()
        .map(|f| {
            let mut out = Vec::new();
            calls(&f.body, &mut out);
            out
        })
        .collect();
    loop {
        let before = (globals.len(), args.len());
        for (fi, list) in call_lists.iter().enumerate() {
            for &(callee, arguments) in list {
                for (a, &e) in arguments.iter().enumerate() {
                    if args.contains(&(callee, a as u32)) {
                        mark(functions[fi], fi, e, &mut globals, &mut args);
                    }
                }
            }
        }
        if (globals.len(), args.len()) == before {
            return globals;
        }
    }
}

pub(super) fn binding_type(
    module: &naga::Module,
    g: &naga::GlobalVariable,
    filterable: bool,
) -> std::result::Result<wgpu::BindingType, String> {
    use naga::{AddressSpace, TypeInner};
    Ok(match (&module.types[g.ty].inner, g.space) {
        (_, AddressSpace::Uniform) => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        (_, AddressSpace::Storage { access }) => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage {
                read_only: !access.contains(naga::StorageAccess::STORE),
            },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        (TypeInner::Sampler { comparison }, _) => wgpu::BindingType::Sampler(if *comparison {
            wgpu::SamplerBindingType::Comparison
        } else {
            wgpu::SamplerBindingType::Filtering
        }),
        (
            TypeInner::Image {
                dim,
                arrayed,
                class,
            },
            _,
        ) => image_type(*dim, *arrayed, class, filterable)?,
        (other, space) => return Err(format!("unsupported binding {other:?} in {space:?}")),
    })
}

/// The binding type of a WGSL image of `class`.
fn image_type(
    dim: naga::ImageDimension,
    arrayed: bool,
    class: &naga::ImageClass,
    filterable: bool,
) -> std::result::Result<wgpu::BindingType, String> {
    use naga::{ImageClass, ScalarKind};
    let view_dimension = match (dim, arrayed) {
        (naga::ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
        (naga::ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
        other => return Err(format!("unsupported image dimension {other:?}")),
    };
    Ok(match class {
        ImageClass::Sampled { kind, multi } => wgpu::BindingType::Texture {
            sample_type: match kind {
                // Filterable only where `textureSample*` reads it (`sampled_images`);
                // unfilterable float also admits depth32float views.
                ScalarKind::Float => wgpu::TextureSampleType::Float { filterable },
                ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                other => return Err(format!("unsupported sample kind {other:?}")),
            },
            view_dimension,
            multisampled: *multi,
        },
        ImageClass::Depth { multi } => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension,
            multisampled: *multi,
        },
        ImageClass::Storage { format, access } => wgpu::BindingType::StorageTexture {
            access: if access.contains(naga::StorageAccess::LOAD | naga::StorageAccess::STORE) {
                wgpu::StorageTextureAccess::ReadWrite
            } else if access.contains(naga::StorageAccess::STORE) {
                wgpu::StorageTextureAccess::WriteOnly
            } else {
                wgpu::StorageTextureAccess::ReadOnly
            },
            format: storage_format(*format)?,
            view_dimension,
        },
        other => return Err(format!("unsupported image class {other:?}")),
    })
}

fn storage_format(f: naga::StorageFormat) -> std::result::Result<wgpu::TextureFormat, String> {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    Ok(match f {
        S::R32Float => T::R32Float,
        S::Rg32Float => T::Rg32Float,
        S::Rgba32Float => T::Rgba32Float,
        S::R16Float => T::R16Float,
        S::Rg16Float => T::Rg16Float,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba16Unorm => T::Rgba16Unorm,
        S::Rgba16Snorm => T::Rgba16Snorm,
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::R32Uint => T::R32Uint,
        S::Rg32Uint => T::Rg32Uint,
        S::Rgba32Uint => T::Rgba32Uint,
        other => return Err(format!("unsupported storage format {other:?}")),
    })
}
