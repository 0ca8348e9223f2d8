//! The graph nodes a light's technique adds: the imported depth, the linear depth, the
//! encoding(s) and the filter or summed-area table over them.

use crate::filter::{BlurMode, EncodeBlur, add_encode_blur, add_filter};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::{Light, Storage};
use crate::wgsl_mirrors::LinearizeParams;
use crate::{model::SatVariant, sat::add_sat};

use super::light_gpu::{sat_coding, sat_variant};
use super::shade::ShadeInput;

/// Name of light `i`'s rasterized depth map (imported into the graph).
pub fn depth_name(i: usize) -> String {
    format!("light{i}.depth")
}

/// Name of light `i`'s linear depth map.
pub fn linear_name(i: usize) -> String {
    format!("light{i}.linear")
}

/// What a technique's [`super::TechniqueDef::nodes`] builds on: light `i`'s graph with its
/// imported depth and linear depth declared.
pub struct LightNodes<'a> {
    /// The graph.
    pub graph: &'a mut Graph,
    /// The light's index.
    pub i: usize,
    /// The light.
    pub light: &'a Light,
    /// Its rasterized depth (`light{i}.depth`).
    pub depth: String,
    /// Its linear depth (`light{i}.linear`; planned only when read).
    pub linear: String,
    /// How its depth is linearized (the first member of every encoding's params).
    pub lin: LinearizeParams,
}

impl LightNodes<'_> {
    /// The shading reads `resource` alone, of the light's map type ([`map_type`]).
    /// A map of packed f16 pairs ([`crate::graph::PACKED_F16X2`]) is bound as
    /// [`PACKED_MAP_TYPE`].
    pub fn one(&self, resource: String) -> ShadeInput {
        let packed = self
            .graph
            .find(&resource)
            .is_some_and(|r| crate::graph::is_packed(r.format));
        ShadeInput {
            maps: vec![resource],
            wgsl_type: if packed {
                PACKED_MAP_TYPE
            } else {
                map_type(self.light)
            },
        }
    }

    /// The encoding `kernel` (raw depth → representation, named after the kernel) with
    /// `params`, then the light's filter over it in `mode`: what the shading reads. A linear
    /// blur of an encoding that has a fused kernel (`fused_blur`) reads the depth itself
    /// (`filter::add_encode_blur`); the unfused encoding stays in the graph for whatever else
    /// reads it (the planner drops it otherwise).
    pub fn encoded(
        &mut self,
        kernel: KernelId,
        format: wgpu::TextureFormat,
        params: &[u8],
        mode: BlurMode,
    ) -> ShadeInput {
        let out = encode(
            self.graph,
            self.i,
            kernel,
            kernel.name(),
            &self.depth,
            format,
            params.to_vec(),
        );
        let fused = fused_blur(kernel).filter(|_| mode == BlurMode::Linear);
        if let (Some(fused), None, Some(filter)) = (
            fused,
            sat_variant(self.light),
            self.light.shadow.technique.filter(),
        ) {
            let e = EncodeBlur {
                kernel: fused,
                depth: &self.depth,
                encoded: &out,
                format,
                params,
                width: self.light.map_dims().0,
            };
            if let Some(filtered) = add_encode_blur(self.graph, self.i, &e, &filter) {
                return self.one(filtered);
            }
        }
        let filtered = self.filtered(&out, mode);
        self.one(filtered)
    }

    /// The filter of the light's representation applied to `input`: the summed-area table of
    /// [`add_sat`] coded by [`sat_coding`] (the `sat` filter and the soft techniques; its errors
    /// `render::plan_lights` reports before any graph is built), else the blur or mip chain of
    /// [`add_filter`].
    pub fn filtered(&mut self, input: &str, mode: BlurMode) -> String {
        let light = self.light;
        if sat_variant(light).is_some() {
            return match sat_coding(light) {
                Ok(Some(coding)) => add_sat(self.graph, self.i, input, &coding),
                _ => input.to_string(),
            };
        }
        match light.shadow.technique.filter() {
            Some(filter) => add_filter(self.graph, self.i, input, &filter, mode),
            None => input.to_string(),
        }
    }

    /// Adds a node writing `outputs` (`dst0`, …) from the depth with `kernel` and `params`.
    pub fn node(
        &mut self,
        name: String,
        kernel: KernelId,
        outputs: Vec<(String, String)>,
        params: Vec<u8>,
    ) {
        self.graph.node(Node {
            name,
            kernel,
            inputs: vec![("src".into(), self.depth.clone())],
            dispatch: Dispatch::Texels(outputs[0].1.clone()),
            outputs,
            params,
            light: Some(self.i),
        });
    }

    /// Declares the light's map `name` (`light{i}.{name}`), the size of the depth.
    pub fn map(&mut self, name: &str, format: wgpu::TextureFormat) -> String {
        self.graph.resource(
            format!("light{}.{name}", self.i),
            format,
            SizeRule::Reduced {
                of: self.depth.clone(),
                shift: 0,
            },
            Some(self.i),
        )
    }
}

/// Adds the nodes light `i`'s technique needs to `graph` and returns what the shading pass
/// reads. The raw depth map and the linear map are always declared; the planner drops what
/// nothing reads: the encodings linearize the depth themselves, so `linearize` runs only for
/// the techniques that shade from the linear depth (hard, PCF but the hardware comparison
/// sampler, PCSS) or when a caller asks for [`linear_name`] (diagnostics).
pub fn add_light_nodes(graph: &mut Graph, i: usize, light: &Light) -> ShadeInput {
    let (width, height) = light.map_dims();
    let depth = graph.import(
        depth_name(i),
        wgpu::TextureFormat::Depth32Float,
        width,
        height,
        Some(i),
    );
    let lin = LinearizeParams::new(light);
    let linear = graph.resource(
        linear_name(i),
        wgpu::TextureFormat::R32Float,
        SizeRule::Reduced {
            of: depth.clone(),
            shift: 0,
        },
        Some(i),
    );
    graph.node(Node {
        name: format!("light{i}.linearize"),
        kernel: KernelId::Linearize,
        inputs: vec![("src".into(), depth.clone())],
        outputs: vec![("dst".into(), linear.clone())],
        params: bytemuck::bytes_of(&lin).to_vec(),
        dispatch: Dispatch::Texels(linear.clone()),
        light: Some(i),
    });
    let mut nodes = LightNodes {
        graph,
        i,
        light,
        depth,
        linear,
        lin,
    };
    (super::of(&light.shadow.technique).nodes)(&mut nodes)
}

/// Channels of the representation behind each table or map the shading reads for `light`
/// (for a summed-area table, those of the table's input: the table itself always has four),
/// in binding order, the tables a texture holds interleaved ([`map_tables`]) one after another.
pub fn map_channels(light: &Light) -> Vec<usize> {
    map_tables(light).into_iter().flatten().collect()
}

/// Per map the shading binds for `light`, the channels of the representation behind each
/// table it holds: one entry for a map or a table of its own, one a table for tables
/// interleaved in one texture ([`Graph::interleaved`]), in slot order.
pub fn map_tables(light: &Light) -> Vec<Vec<usize>> {
    let mut graph = Graph::default();
    let input = add_light_nodes(&mut graph, 0, light);
    let table = sat_coding(light).ok().flatten().is_some();
    let channels = |m: &str| {
        let source = m.strip_suffix(".sat").filter(|_| table);
        graph
            .find(source.unwrap_or(m))
            .map_or(4, |r| crate::sat::format_channels(r.format) as usize)
    };
    input
        .maps
        .iter()
        .map(|m| match graph.find(m).map(|r| r.layers.as_slice()) {
            Some(layers) if !layers.is_empty() => layers.iter().map(|l| channels(l)).collect(),
            _ => vec![channels(m)],
        })
        .collect()
}

/// The WGSL type of a map of packed f16 pairs ([`crate::graph::PACKED_F16X2`]), read through
/// `sample_map_packed` (`kernels/shared/sampling_packed.wgsl`).
pub const PACKED_MAP_TYPE: &str = "texture_2d<u32>";

/// Whether the shading reads `light`'s maps as packed f16 pairs ([`PACKED_MAP_TYPE`]): f16
/// storage of a two-moment representation that is not summed into a table.
pub fn maps_packed(light: &Light) -> bool {
    let mut graph = Graph::default();
    let input = add_light_nodes(&mut graph, 0, light);
    input
        .maps
        .first()
        .and_then(|m| graph.find(m))
        .is_some_and(|r| crate::graph::is_packed(r.format))
}

/// The WGSL type of a prefiltered technique's maps: `texture_2d<u32>` for a fixed-point
/// summed-area table, else `texture_2d<f32>` (a map of packed f16 pairs is bound as
/// [`PACKED_MAP_TYPE`] instead: [`LightNodes::one`]).
pub fn map_type(light: &Light) -> &'static str {
    match sat_variant(light) {
        Some(SatVariant::Fixed) => "texture_2d<u32>",
        _ => "texture_2d<f32>",
    }
}

/// The kernel that fuses encoding `kernel` into a linear blur (`kernels/shared/encode_blur.wgsl`),
/// if it has one.
pub fn fused_blur(kernel: KernelId) -> Option<KernelId> {
    match kernel {
        KernelId::Vsm => Some(KernelId::VsmBlur),
        KernelId::Evsm => Some(KernelId::EvsmBlur),
        KernelId::Msm => Some(KernelId::MsmBlur),
        _ => None,
    }
}

/// The texel format of a `channels`-channel representation (1–4) at `storage` precision: two
/// f16 channels in 4 bytes ([`crate::graph::PACKED_F16X2`]: `rg16float` is no core storage
/// format, so an `r32uint` word each), more in `rgba16float`.
pub fn moments_format(storage: Storage, channels: u32) -> wgpu::TextureFormat {
    match (storage, channels) {
        (Storage::F16, 1 | 2) => crate::graph::PACKED_F16X2,
        _ => float_moments_format(storage, channels),
    }
}

/// [`moments_format`] in a float texture format (f16 in `rgba16float` whatever the channels):
/// for CSM, whose light binds every basis map as one WGSL type although its last map may hold
/// one pair of terms.
pub fn float_moments_format(storage: Storage, channels: u32) -> wgpu::TextureFormat {
    match (storage, channels) {
        (Storage::F32, 1) => wgpu::TextureFormat::R32Float,
        (Storage::F32, 2) => wgpu::TextureFormat::Rg32Float,
        (Storage::F32, _) => wgpu::TextureFormat::Rgba32Float,
        (Storage::F16, _) => wgpu::TextureFormat::Rgba16Float,
        (Storage::Unorm16, _) => wgpu::TextureFormat::Rgba16Unorm,
    }
}

/// Adds the encoding node `kernel` (raw depth → representation, the kernel linearizing the
/// depth itself) of light `i`, writing `light{i}.{name}`; the output's format picks the
/// kernel's storage variant. `params` start with the depth's [`LinearizeParams`].
fn encode(
    graph: &mut Graph,
    i: usize,
    kernel: KernelId,
    name: &str,
    depth: &str,
    format: wgpu::TextureFormat,
    params: Vec<u8>,
) -> String {
    let out = graph.resource(
        format!("light{i}.{name}"),
        format,
        SizeRule::Reduced {
            of: depth.to_string(),
            shift: 0,
        },
        Some(i),
    );
    graph.node(Node {
        name: format!("light{i}.{name}"),
        kernel,
        inputs: vec![("src".into(), depth.to_string())],
        outputs: vec![("dst".into(), out.clone())],
        params,
        dispatch: Dispatch::Texels(out.clone()),
        light: Some(i),
    });
    out
}
