//! The kernel graph as data: nodes name a kernel, their named input and output resources
//! (format and size rule) and their parameters. [`plan()`] turns a graph and the outputs a
//! scene asks for into an ordered, pruned [`Plan`] with resource lifetimes and texture reuse.

mod check;
pub mod cost;
mod plan;
pub mod print;

pub use plan::{Plan, PlannedResource, Slot, Step, plan};

use crate::error::GraphError;

/// How big a resource is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SizeRule {
    /// An explicit extent in texels.
    Fixed {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// The size of another resource divided by `2^shift` (rounded up, at least 1).
    Reduced {
        /// The resource whose size this follows.
        of: String,
        /// Halvings.
        shift: u32,
    },
    /// The number of `x × y` blocks covering another resource: [`block_count`] along each
    /// axis. One texel per block of a blocked pass, e.g. the per-row block totals of a scan
    /// (`x` = block length, `y` = 1).
    Blocks {
        /// The resource whose size this follows.
        of: String,
        /// Block width in texels (0: the whole width).
        x: u32,
        /// Block height in texels (0: the whole height).
        y: u32,
    },
    /// The blocks of [`SizeRule::Blocks`] for `across × down` maps of the size of `of`, laid
    /// side by side: `[block_count(width, x)·across, block_count(height, y)·down]`. The edges
    /// of several summed-area tables stacked in one texture ([`crate::sat::layers`]).
    Stacked {
        /// The resource whose size this follows.
        of: String,
        /// Block width in texels (0: the whole width).
        x: u32,
        /// Block height in texels (0: the whole height).
        y: u32,
        /// Copies along x.
        across: u32,
        /// Copies along y.
        down: u32,
    },
}

/// A named, typed texture in the graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Resource {
    /// Unique name, `light<i>.<what>` by convention (e.g. `light0.linear`).
    pub name: String,
    /// Texel format.
    pub format: wgpu::TextureFormat,
    /// Size rule.
    pub size: SizeRule,
    /// Mip levels (1 for a plain map; 0 asks the planner for the full chain down to 1×1).
    pub mips: u32,
    /// Provided from outside the graph (the rasterized shadow map); never allocated by it.
    pub imported: bool,
    /// The light this resource belongs to, if any.
    pub light: Option<usize>,
    /// The tables interleaved along x in this texture ([`Graph::interleaved`]): texel
    /// `(x·n + k, y)` is texel `(x, y)` of `layers[k]` (n = `layers.len()`). Empty for a
    /// plain resource.
    pub layers: Vec<String>,
    /// Never filtered: written by `textureStore` and read only by `textureLoad` at level 0
    /// (by graph kernels, or as an output by the renderer's shading, e.g. a fixed-point
    /// summed-area table). In a layout that keeps such maps in storage buffers
    /// ([`crate::exec::KernelLayout::buffers_intermediates`]) the executor may hold it in a
    /// row-major buffer instead of a texture ([`Graph::intermediate`],
    /// [`crate::exec::buffer_slots`]; a requested output only for a caller that allows it).
    pub unfiltered: bool,
}

/// How many workgroups a node dispatches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Dispatch {
    /// One invocation per texel of this resource (workgroup size from the kernel).
    Texels(String),
    /// An explicit workgroup count.
    Groups([u32; 3]),
    /// One workgroup per `x × y` block of this resource (one of the node's own):
    /// `[block_count(width, x), block_count(height, y), 1]`, as [`SizeRule::Blocks`] sizes
    /// the blocks' outputs. For passes whose workgroups each own a block of a size that is not
    /// the kernel's workgroup size (several texels per invocation, or one line per invocation).
    Blocks {
        /// The resource whose size counts.
        of: String,
        /// Block width in texels (0: the whole width, one group).
        x: u32,
        /// Block height in texels (0: the whole height, one group).
        y: u32,
    },
    /// [`Dispatch::Blocks`] whose blocks are taller where the kernel compiles in a CPU driver's
    /// layout ([`crate::exec::KernelLayout::Cpu`]): `x × y` texels a workgroup on a GPU, `x ×
    /// cpu_y` on a CPU driver, whose fewer invocations walk a taller tile for less of its halo
    /// (the fused blurs' strips, `CPU_TILE_ROWS` in `kernels/shared/encode_blur.wgsl`).
    /// [`Dispatch::groups`] gives the GPU's count, which the cost model describes;
    /// [`Dispatch::groups_in_layout`] either.
    Tiles {
        /// The resource whose size counts.
        of: String,
        /// Block width in texels.
        x: u32,
        /// Block height in texels on a GPU.
        y: u32,
        /// Block height in texels on a CPU driver.
        cpu_y: u32,
    },
    /// One invocation per column and one per row of this resource:
    /// `[⌈max(width, height) / per_group⌉, 2, 1]`, workgroup row 0 over the columns and row 1
    /// over the rows (work serial along each line, e.g. a summed-area table's carries).
    Lines {
        /// The resource whose size counts.
        of: String,
        /// Lines per workgroup (the kernel's workgroup size).
        per_group: u32,
    },
    /// `base`'s workgroups along x and y, `layers` of them along z (one layer of a stack per
    /// workgroup z, e.g. the layered summed-area tables of [`crate::sat::layers`]).
    Layers {
        /// The dispatch of one layer (not [`Dispatch::Several`]).
        base: Box<Dispatch>,
        /// Workgroups along z.
        layers: u32,
    },
    /// `base`'s workgroups with `layers` of them side by side along x for each:
    /// `[x·layers, y, 1]`, workgroup `X·layers + k` on layer k of `base`'s workgroup X. The
    /// layers of one block run one after another, so that tables interleaved in one texture
    /// ([`Graph::interleaved`]) have each cache line written within a short time
    /// ([`crate::sat::layers`]).
    Interleaved {
        /// The dispatch of one layer (not [`Dispatch::Several`]).
        base: Box<Dispatch>,
        /// Workgroups side by side along x.
        layers: u32,
    },
    /// `shipped` where the kernel compiles in a shipped layout (a GPU's or a CPU driver's) and
    /// `redesign` in [`crate::exec::KernelLayout::Redesign`], whose variant of the kernel
    /// (`override REDESIGN`) covers other blocks a workgroup: e.g. the separable blur's row pass
    /// with its invocations on neighbouring rows (`crate::filter`). [`Dispatch::groups`] and
    /// the cost model read `shipped`; [`Dispatch::groups_in`] either.
    Redesigned {
        /// The dispatch in the shipped layouts (not [`Dispatch::Several`]).
        shipped: Box<Dispatch>,
        /// The dispatch in the redesign layout (not [`Dispatch::Several`]).
        redesign: Box<Dispatch>,
    },
    /// Several dispatches in the node's one compute pass, each with its own parameters, its
    /// bindings of single mip levels and its workgroups: e.g. a mip chain, a few levels per
    /// dispatch, each reading the last level written (`crate::filter` builds them). Planner,
    /// cost model and executor read them as data.
    Several(Vec<SubDispatch>),
}

/// One of the dispatches of a [`Dispatch::Several`] node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SubDispatch {
    /// Its parameters: these bytes of the node's `params`.
    pub params: std::ops::Range<usize>,
    /// Bindings of one mip level each. A write-only storage binding of the kernel that none
    /// names repeats the last one (the kernel does not store through it; the cost model does
    /// not count it); any other binding is bound by the node's slot of its name.
    pub levels: Vec<LevelView>,
    /// Workgroups.
    pub groups: [u32; 3],
}

/// A kernel binding bound to one mip level of the resource of one of the node's slots.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LevelView {
    /// The binding's name in the WGSL.
    pub binding: String,
    /// The node's input or output slot whose resource is bound.
    pub slot: String,
    /// The mip level.
    pub level: u32,
}

impl Node {
    /// The resource bound to the node's input or output slot `slot`.
    pub fn slot_resource(&self, slot: &str) -> Option<&str> {
        self.inputs
            .iter()
            .chain(&self.outputs)
            .find(|(s, _)| s == slot)
            .map(|(_, r)| r.as_str())
    }
}

impl Dispatch {
    /// The lines a workgroup of a [`Dispatch::Lines`] covers (within [`Dispatch::Layers`] or
    /// [`Dispatch::Interleaved`] too, and as the shipped dispatch of a
    /// [`Dispatch::Redesigned`]): the kernel's workgroup size it assumes. `None` for the other
    /// kinds.
    pub fn lines_per_group(&self) -> Option<u32> {
        self.lines_per_group_in(false)
    }

    /// [`Dispatch::lines_per_group`] in the redesign layout too (`redesign`), where a
    /// [`Dispatch::Redesigned`] is its redesign's dispatch, whose kernel is its own file and
    /// may give a line several invocations: `None` there.
    pub fn lines_per_group_in(&self, redesign: bool) -> Option<u32> {
        match self {
            Self::Lines { per_group, .. } => Some(*per_group),
            Self::Layers { base, .. } | Self::Interleaved { base, .. } => {
                base.lines_per_group_in(redesign)
            }
            Self::Redesigned { shipped, .. } if !redesign => shipped.lines_per_group_in(false),
            _ => None,
        }
    }

    /// Workgroup counts of a dispatch of a kernel whose workgroup is `workgroup`, with
    /// `size(resource)` the planned `(width, height)` of a resource, in the GPU's kernel
    /// layout (what the cost model describes: [`Dispatch::groups_in_layout`]); `None` when a
    /// resource it counts is unknown, or for [`Dispatch::Several`] (each of which has its own).
    pub fn groups(
        &self,
        size: impl Fn(&str) -> Option<(u32, u32)>,
        workgroup: [u32; 3],
    ) -> Option<[u32; 3]> {
        self.groups_in_layout(size, workgroup, true)
    }

    /// [`Dispatch::groups`] for a kernel compiled in the GPU's layout (`gpu`) or a CPU
    /// driver's: the same but for [`Dispatch::Tiles`] (within [`Dispatch::Layers`] or
    /// [`Dispatch::Interleaved`] too), whose blocks are `cpu_y` tall on a CPU driver.
    pub fn groups_in_layout(
        &self,
        size: impl Fn(&str) -> Option<(u32, u32)>,
        workgroup: [u32; 3],
        gpu: bool,
    ) -> Option<[u32; 3]> {
        self.groups_in(size, workgroup, gpu, false)
    }

    /// [`Dispatch::groups_in_layout`] in the redesign layout too (`redesign`, with `gpu`
    /// true: [`crate::exec::KernelLayout::Redesign`]), where [`Dispatch::Redesigned`] takes
    /// its `redesign` dispatch.
    pub fn groups_in(
        &self,
        size: impl Fn(&str) -> Option<(u32, u32)>,
        workgroup: [u32; 3],
        gpu: bool,
        redesign: bool,
    ) -> Option<[u32; 3]> {
        Some(match self {
            Self::Groups(g) => *g,
            Self::Texels(r) => {
                let (w, h) = size(r)?;
                [w.div_ceil(workgroup[0]), h.div_ceil(workgroup[1]), 1]
            }
            Self::Blocks { of, x, y } => {
                let (w, h) = size(of)?;
                [block_count(w, *x), block_count(h, *y), 1]
            }
            Self::Tiles { of, x, y, cpu_y } => {
                let (w, h) = size(of)?;
                [
                    block_count(w, *x),
                    block_count(h, if gpu { *y } else { *cpu_y }),
                    1,
                ]
            }
            Self::Lines { of, per_group } => {
                let (w, h) = size(of)?;
                [block_count(w.max(h), *per_group), 2, 1]
            }
            Self::Layers { base, layers } => {
                let [x, y, _] = base.groups_in(size, workgroup, gpu, redesign)?;
                [x, y, *layers]
            }
            Self::Interleaved { base, layers } => {
                let [x, y, _] = base.groups_in(size, workgroup, gpu, redesign)?;
                [x.checked_mul(*layers)?, y, 1]
            }
            Self::Redesigned {
                shipped,
                redesign: r,
            } => {
                let d = if redesign { r } else { shipped };
                return d.groups_in(size, workgroup, gpu, redesign);
            }
            Self::Several(_) => return None,
        })
    }
}

/// One kernel invocation in the graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Unique label, e.g. `light0.linearize`; pipelines and passes are labelled with it.
    pub name: String,
    /// The kernel, `kernels/<name>.wgsl`: an id generated from the folder, so a typo does not
    /// compile.
    pub kernel: crate::kernels::KernelId,
    /// `(binding name in the WGSL, resource name)` read by the kernel.
    pub inputs: Vec<(String, String)>,
    /// `(binding name in the WGSL, resource name)` written by the kernel.
    pub outputs: Vec<(String, String)>,
    /// Bytes of the kernel's `params` uniform (a `#[repr(C)]` mirror of its WGSL struct).
    pub params: Vec<u8>,
    /// Dispatch size.
    pub dispatch: Dispatch,
    /// The light this node works for, if any.
    pub light: Option<usize>,
}

/// A set of resources and the nodes that produce and consume them.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    /// Resources in declaration order.
    pub resources: Vec<Resource>,
    /// Nodes in declaration order (the tie-break of the planner's ordering).
    pub nodes: Vec<Node>,
}

impl Graph {
    /// Declares a resource produced inside the graph; returns its name.
    pub fn resource(
        &mut self,
        name: impl Into<String>,
        format: wgpu::TextureFormat,
        size: SizeRule,
        light: Option<usize>,
    ) -> String {
        let name = name.into();
        self.resources.push(Resource {
            name: name.clone(),
            format,
            size,
            mips: 1,
            imported: false,
            light,
            layers: Vec::new(),
            unfiltered: false,
        });
        name
    }

    /// Declares a resource that is never filtered ([`Resource::unfiltered`]): e.g. a separable
    /// blur's row pass output, which only its column pass reads, or a fixed-point table, which
    /// its lookups only load.
    pub fn intermediate(
        &mut self,
        name: impl Into<String>,
        format: wgpu::TextureFormat,
        size: SizeRule,
        light: Option<usize>,
    ) -> String {
        let name = self.resource(name, format, size, light);
        if let Some(r) = self.resources.last_mut() {
            r.unfiltered = true;
        }
        name
    }

    /// Marks resource `name` [`Resource::unfiltered`] (no effect on a name not declared).
    pub fn mark_unfiltered(&mut self, name: &str) {
        if let Some(r) = self.resources.iter_mut().find(|r| r.name == name) {
            r.unfiltered = true;
        }
    }

    /// Declares a texture holding the maps `layers` (each the size of `of`) interleaved along
    /// x: texel `(x, y)` of `layers[k]` at `(x·n + k, y)`, n = `layers.len()`, so that one
    /// texel of every layer sits in one run of memory (a lookup reading the same texel of
    /// several tables touches one cache line, not one a table). The layers are names, not
    /// resources: readbacks split the texture into them ([`Resource::layers`]).
    pub fn interleaved(
        &mut self,
        name: impl Into<String>,
        format: wgpu::TextureFormat,
        of: &str,
        layers: Vec<String>,
        light: Option<usize>,
    ) -> String {
        let size = SizeRule::Stacked {
            of: of.to_string(),
            x: 1,
            y: 1,
            across: layers.len() as u32,
            down: 1,
        };
        let name = self.resource(name, format, size, light);
        if let Some(r) = self.resources.last_mut() {
            r.layers = layers;
        }
        name
    }

    /// Declares a resource with a full mip chain (level count resolved by the planner).
    pub fn mip_resource(
        &mut self,
        name: impl Into<String>,
        format: wgpu::TextureFormat,
        size: SizeRule,
        light: Option<usize>,
    ) -> String {
        let name = self.resource(name, format, size, light);
        if let Some(r) = self.resources.last_mut() {
            r.mips = 0;
        }
        name
    }

    /// Declares a resource provided from outside (e.g. a rasterized depth map).
    pub fn import(
        &mut self,
        name: impl Into<String>,
        format: wgpu::TextureFormat,
        width: u32,
        height: u32,
        light: Option<usize>,
    ) -> String {
        let name = name.into();
        self.resources.push(Resource {
            name: name.clone(),
            format,
            size: SizeRule::Fixed { width, height },
            mips: 1,
            imported: true,
            light,
            layers: Vec::new(),
            unfiltered: false,
        });
        name
    }

    /// Adds a node.
    pub fn node(&mut self, node: Node) {
        self.nodes.push(node);
    }

    /// The resource named `name`.
    pub fn find(&self, name: &str) -> Option<&Resource> {
        self.resources.iter().find(|r| r.name == name)
    }
}

/// Layer `k` of `layers` interleaved along x ([`Graph::interleaved`]) from a texture's values
/// read back row-major, `per_texel` values a texel: that layer's values, row-major.
pub fn layer_of<T: Copy>(data: &[T], per_texel: usize, layers: usize, k: usize) -> Vec<T> {
    data.chunks_exact(per_texel * layers)
        .flat_map(|group| group[k * per_texel..(k + 1) * per_texel].iter().copied())
        .collect()
}

/// Blocks of `block` texels covering `len` texels, rounded up, at least 1; a `block` of 0
/// spans the whole length (one block).
pub fn block_count(len: u32, block: u32) -> u32 {
    if block == 0 {
        1
    } else {
        len.div_ceil(block).max(1)
    }
}

/// Two f16 values a texel (`Rg16Float` in a graph): a representation stored in 4 bytes.
/// `rg16float` is no core WebGPU storage format, so its texture is `r32uint`, each word
/// `pack2x16float(v.xy)`; kernels compiled for it pack on store and unpack on load
/// ([`crate::exec::KernelCache::get_specialized`]), the shading reads it through
/// `kernels/shared/sampling_packed.wgsl`.
pub const PACKED_F16X2: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;

/// Whether a resource of `format` is stored packed ([`PACKED_F16X2`]).
pub fn is_packed(format: wgpu::TextureFormat) -> bool {
    format == PACKED_F16X2
}

/// The format of the texture that holds a resource of `format`: `r32uint` for
/// [`PACKED_F16X2`], else `format` itself.
pub fn texture_format(format: wgpu::TextureFormat) -> wgpu::TextureFormat {
    if is_packed(format) {
        wgpu::TextureFormat::R32Uint
    } else {
        format
    }
}

/// How `plan` and the dump's manifest name a resource's format: its texture's format, and for
/// packed f16 pairs ([`PACKED_F16X2`]) what its words hold (`R32Uint f16x2`).
pub fn format_label(format: wgpu::TextureFormat) -> String {
    if is_packed(format) {
        format!("{:?} f16x2", texture_format(format))
    } else {
        format!("{format:?}")
    }
}

/// Bytes of one texel of `format` (0 where the format has no fixed size).
pub fn texel_bytes(format: wgpu::TextureFormat) -> u64 {
    u64::from(
        format
            .block_copy_size(None)
            .or_else(|| format.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)))
            .unwrap_or(0),
    )
}

#[cfg(test)]
mod tests;
