//! Filters that work on any prefiltered representation: the separable blur and the mip chain.

use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::scene::{BlurKernel, Filter};

/// Taps each side the blur kernel's workgroup tile can hold.
pub const MAX_BLUR_RADIUS: u32 = 32;

/// How the blur combines texels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlurMode {
    /// Weighted sum (moments, basis images).
    Linear,
    /// `log Σ wᵢ exp(vᵢ)`, stably (the texels hold logarithms, e.g. ESM's `c·z`).
    LogSumExp,
}

/// Parameters of `kernels/blur.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BlurParams {
    /// 0 horizontal, 1 vertical.
    pub axis: u32,
    /// Taps each side.
    pub radius: u32,
    /// 0 linear, 1 log-sum-exp.
    pub mode: u32,
    /// Padding.
    pub _pad: u32,
    /// One-sided weights, offset `i` at `[i / 4][i % 4]`; `w0 + 2 Σ wi = 1`.
    pub weights: [[f32; 4]; 9],
}

/// Taps each side and normalized one-sided weights (`w[0]` centre) of a blur.
pub fn blur_weights(radius: f32, sigma: f32, kernel: BlurKernel) -> Vec<f32> {
    let taps = (radius.ceil() as u32).min(MAX_BLUR_RADIUS);
    let raw: Vec<f64> = (0..=taps)
        .map(|i| {
            let x = f64::from(i);
            match kernel {
                BlurKernel::Gaussian => (-x * x / (2.0 * f64::from(sigma).powi(2))).exp(),
                BlurKernel::Box => (f64::from(radius) - x + 1.0).clamp(0.0, 1.0),
            }
        })
        .collect();
    let total = raw[0] + 2.0 * raw[1..].iter().sum::<f64>();
    raw.iter().map(|w| (w / total) as f32).collect()
}

impl BlurParams {
    /// The pass along `axis` of `filter`'s blur.
    pub fn new(axis: u32, radius: f32, sigma: f32, kernel: BlurKernel, mode: BlurMode) -> Self {
        let w = blur_weights(radius, sigma, kernel);
        let mut weights = [[0.0; 4]; 9];
        for (i, v) in w.iter().enumerate() {
            weights[i / 4][i % 4] = *v;
        }
        Self {
            axis,
            radius: w.len() as u32 - 1,
            mode: u32::from(mode == BlurMode::LogSumExp),
            _pad: 0,
            weights,
        }
    }
}

/// Adds the nodes of `filter` over `input` (a resource of `light`), named `<input>.<pass>`;
/// returns the filtered resource (the input itself when there is nothing to do).
pub fn add_filter(
    graph: &mut Graph,
    light: usize,
    input: &str,
    filter: &Filter,
    mode: BlurMode,
) -> String {
    let Some(format) = graph.find(input).map(|r| r.format) else {
        return input.to_string();
    };
    let (radius, sigma, kernel) = match *filter {
        // The table needs the technique's value ranges: `technique::filtered` adds it.
        Filter::None | Filter::Sat { .. } => return input.to_string(),
        Filter::Mips { .. } => return add_mips(graph, light, input, format, mode),
        Filter::Blur {
            radius,
            sigma,
            kernel,
        } => (radius, sigma, kernel),
    };
    let mut src = input.to_string();
    for (axis, pass) in [(0, "blur_h"), (1, "blur_v")] {
        let out = graph.resource(
            format!("{input}.{pass}"),
            format,
            SizeRule::Reduced {
                of: input.to_string(),
                shift: 0,
            },
            Some(light),
        );
        graph.node(Node {
            name: format!("{input}.{pass}"),
            kernel: "blur".into(),
            inputs: vec![("src".into(), src)],
            outputs: vec![("dst".into(), out.clone())],
            params: bytemuck::bytes_of(&BlurParams::new(axis, radius, sigma, kernel, mode))
                .to_vec(),
            dispatch: Dispatch::Axis {
                of: out.clone(),
                axis,
            },
            light: Some(light),
        });
        src = out;
    }
    src
}

/// Parameters of `kernels/mips.wgsl` (mirrors its `Params`); the executor fills in the sizes
/// of each dispatch's levels, the graph only the mode.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MipParams {
    /// Size of the level read.
    pub src_size: [u32; 2],
    /// Size of the first level written.
    pub a_size: [u32; 2],
    /// Size of the second level written.
    pub b_size: [u32; 2],
    /// 0 linear average, 1 log-sum-exp.
    pub mode: u32,
    /// Padding.
    pub _pad: u32,
}

/// Adds the mip-chain node over `input`: `<input>.mips`, a copy of `input` at level 0 and
/// area-weighted reductions below it, down to 1×1.
fn add_mips(
    graph: &mut Graph,
    light: usize,
    input: &str,
    format: wgpu::TextureFormat,
    mode: BlurMode,
) -> String {
    let out = graph.mip_resource(
        format!("{input}.mips"),
        format,
        SizeRule::Reduced {
            of: input.to_string(),
            shift: 0,
        },
        Some(light),
    );
    let params = MipParams {
        mode: u32::from(mode == BlurMode::LogSumExp),
        ..Default::default()
    };
    graph.node(Node {
        name: format!("{input}.mips"),
        kernel: "mips".into(),
        inputs: vec![("src".into(), input.to_string())],
        outputs: vec![("dst".into(), out.clone())],
        params: bytemuck::bytes_of(&params).to_vec(),
        dispatch: Dispatch::MipChain,
        light: Some(light),
    });
    out
}
