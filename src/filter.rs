//! Filters that work on any prefiltered representation: the separable blur and the mip chain.

use crate::graph::{Dispatch, Graph, LevelView, Node, SizeRule, SubDispatch};
use crate::kernels::KernelId;
use crate::model::{BlurKernel, Filter};

mod encode_blur;

pub use self::encode_blur::{
    ENCODE_BLUR_TILE_RADIUS, EncodeBlur, add_encode_blur, encode_blur_cpu_rows, encode_blur_row,
    encode_blur_row_kernel, encode_blur_tile,
};

/// Taps each side the blur kernel's weight table holds.
pub const MAX_BLUR_RADIUS: u32 = 32;

/// Texels of a line one `blur` or `blur_log` invocation writes (`PER` in
/// `kernels/shared/blur_pass.wgsl`).
pub const BLUR_PER_INVOCATION: u32 = 8;

/// Rows down a column one `blur` invocation writes (`COL_PER` in `kernels/blur.wgsl`; `blur_log`
/// writes [`BLUR_PER_INVOCATION`]): the vertical pass reads its halo of 2r rows once per this
/// many outputs. In the redesign layout a row invocation writes as many along its row.
pub const BLUR_COL_PER: u32 = 32;

/// Invocations of a `blur` or `blur_log` workgroup (`WG_SIZE` in
/// `kernels/shared/blur_pass.wgsl`): along a row, or across neighbouring columns.
pub const BLUR_GROUP: u32 = 64;

/// How the blur combines texels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlurMode {
    /// Weighted sum (moments, basis images).
    Linear,
    /// `log Σ wᵢ exp(vᵢ)`, stably, of texels (logarithms, e.g. ESM's `c·z`) that lie within
    /// [`LOG_BLUR_SPAN`] of each other: `blur_log`.
    LogSumExp,
    /// The same of texels of any spread: `blur_log_wide`, which takes each output's own
    /// maximum where an invocation's texels spread wider (`kernels/shared/blur_log_pass.wgsl`).
    LogSumExpWide,
}

/// The spread of texel values `blur_log` serves without a per-output fallback (its `SPAN`):
/// every exp of a difference within it is a normal f32.
pub const LOG_BLUR_SPAN: f32 = 80.0;

impl BlurMode {
    /// Log-sum-exp of texels that lie in an interval `spread` wide (ESM's `c·z`, z ∈ [0, 1]:
    /// `spread` = c): [`BlurMode::LogSumExp`] within [`LOG_BLUR_SPAN`], else the wide kernel.
    pub fn log_sum_exp(spread: f32) -> Self {
        if spread <= LOG_BLUR_SPAN {
            BlurMode::LogSumExp
        } else {
            BlurMode::LogSumExpWide
        }
    }

    /// Whether the texels are logarithms (either log-sum-exp mode).
    pub fn is_log(self) -> bool {
        self != BlurMode::Linear
    }

    /// `BlurParams::mode`: 0 linear, 1 log-sum-exp, 2 log-sum-exp of any spread.
    fn code(self) -> u32 {
        match self {
            BlurMode::Linear => 0,
            BlurMode::LogSumExp => 1,
            BlurMode::LogSumExpWide => 2,
        }
    }
}

/// Parameters of `kernels/blur.wgsl` (mirrors its `Params`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BlurParams {
    /// 0 horizontal, 1 vertical.
    pub axis: u32,
    /// Taps each side.
    pub radius: u32,
    /// 0 linear, 1 log-sum-exp (`blur_log`), 2 log-sum-exp of any spread (`blur_log_wide`).
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
            mode: mode.code(),
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
        let params = BlurParams::new(axis, radius, sigma, kernel, mode);
        let name = format!("{input}.{pass}");
        src = add_blur_pass(graph, light, [&src, input, &name], format, params);
    }
    src
}

/// Adds the node of one pass of `blur` or `blur_log` (by `params.mode`) along `params.axis`:
/// `[src, shape, name]` reads `src` and writes `name`, of `format` and the size of `shape`;
/// returns `name`.
fn add_blur_pass(
    graph: &mut Graph,
    light: usize,
    [src, shape, name]: [&str; 3],
    format: wgpu::TextureFormat,
    params: BlurParams,
) -> String {
    let (kernel_id, col_per) = match params.mode {
        0 => (KernelId::Blur, BLUR_COL_PER),
        1 => (KernelId::BlurLog, BLUR_PER_INVOCATION),
        _ => (KernelId::BlurLogWide, BLUR_PER_INVOCATION),
    };
    let size = SizeRule::Reduced {
        of: shape.to_string(),
        shift: 0,
    };
    // The row pass's output is read by the column pass alone: never filtered.
    let out = if params.axis == 0 {
        graph.intermediate(name.to_string(), format, size, Some(light))
    } else {
        graph.resource(name.to_string(), format, size, Some(light))
    };
    let axis = params.axis;
    graph.node(Node {
        name: name.to_string(),
        kernel: kernel_id,
        inputs: vec![("src".into(), src.to_string())],
        outputs: vec![("dst".into(), out.clone())],
        params: bytemuck::bytes_of(&params).to_vec(),
        dispatch: blur_dispatch(&out, axis, col_per),
        light: Some(light),
    });
    out
}

/// The workgroups of a `blur` or `blur_log` pass along `axis` writing `out`, whose column
/// invocations write `col_per` rows each. Columns: a workgroup per [`BLUR_GROUP`] columns ×
/// `col_per` rows. Rows: a workgroup per [`BLUR_GROUP`] · [`BLUR_PER_INVOCATION`] texels of
/// a row; in [`crate::exec::KernelLayout::Redesign`] the columns' blocks turned sideways,
/// `col_per` columns × [`BLUR_GROUP`] rows, an invocation a row (`REDESIGN` in
/// `kernels/shared/blur_pass.wgsl`).
fn blur_dispatch(out: &str, axis: u32, col_per: u32) -> Dispatch {
    let blocks = |x, y| Dispatch::Blocks {
        of: out.to_string(),
        x,
        y,
    };
    if axis != 0 {
        return blocks(BLUR_GROUP, col_per);
    }
    Dispatch::Redesigned {
        shipped: Box::new(blocks(BLUR_GROUP * BLUR_PER_INVOCATION, 1)),
        redesign: Box::new(blocks(col_per, BLUR_GROUP)),
    }
}

/// Parameters of `kernels/mips.wgsl` (mirrors its `Params`): one per dispatch of a mip chain
/// ([`mip_dispatches`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MipParams {
    /// Size of level 0.
    pub base: [u32; 2],
    /// The level a dispatch reads, `s`.
    pub first: u32,
    /// Levels it writes after `s` (0 only for a 1×1 map, whose chain is level 0).
    pub count: u32,
    /// 0 linear average, 1 log-sum-exp (for the record: the kernel, `mips` or `mips_log`,
    /// decides).
    pub mode: u32,
    /// 1: the dispatch also stores the level it reads as level 0 (the first dispatch).
    pub copy: u32,
    /// 1: the level read has an odd side > 1 (a fractional reduction; `count` is 1).
    pub general: u32,
    /// Padding.
    pub _pad: u32,
}

/// Levels one `mips` dispatch writes at most (its `dst1` … `dst6`).
pub const MIP_LEVELS_PER_DISPATCH: u32 = 6;

/// Level-0 texels per axis a `mips` workgroup reduces when the level halves (`TILE` × 2).
pub const MIP_TILE: u32 = 64;

/// The dispatches of the full mip chain of a `width × height` map: `(first, count)` pairs,
/// each reading level `first` and writing the `count` levels after it. A dispatch writes up to
/// [`MIP_LEVELS_PER_DISPATCH`] levels, each an exact halving (or a side of 1 kept), which a
/// workgroup does from its own texels; a level with an odd side > 1 (a fractional reduction)
/// gets a dispatch of one level. A 1×1 map is one dispatch writing no level after level 0. A
/// 4096² chain is `[(0, 6), (6, 6)]`.
pub fn mip_dispatches(width: u32, height: u32) -> Vec<(u32, u32)> {
    let levels = crate::model::mip_levels(width, height);
    let size = |l: u32| [(width >> l).max(1), (height >> l).max(1)];
    let halves = |l: u32| size(l).iter().all(|&n| n == 1 || n % 2 == 0);
    if levels <= 1 {
        return vec![(0, 0)];
    }
    let mut out = Vec::new();
    let mut first = 0;
    while first + 1 < levels {
        let mut count = 1;
        while halves(first)
            && count < MIP_LEVELS_PER_DISPATCH
            && first + count + 1 < levels
            && halves(first + count)
        {
            count += 1;
        }
        out.push((first, count));
        first += count;
    }
    out
}

/// Workgroups of the mip-chain dispatch that reads level `first` of a `width × height` chain:
/// one per `MIP_TILE / 2` texels of level `first + 1` each way (a workgroup owns a 32 × 32 tile
/// of it; a 1×1 level stays 1×1).
pub fn mip_dispatch_groups(width: u32, height: u32, first: u32) -> [u32; 3] {
    let tile = MIP_TILE / 2;
    let side = |n: u32| (n >> (first + 1)).max(1).div_ceil(tile);
    [side(width), side(height), 1]
}

/// Adds the mip-chain node over `input`: `<input>.mips`, `input` at level 0 and area-weighted
/// reductions below it, down to 1×1, in the dispatches of [`mip_dispatches`].
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
    // An input whose size does not resolve fails the planner (the chain follows its size).
    let (params, dispatches) = graph
        .size(input)
        .map(|(w, h)| mip_chain(w, h, mode))
        .unwrap_or_default();
    graph.node(Node {
        name: format!("{input}.mips"),
        kernel: if mode.is_log() {
            KernelId::MipsLog
        } else {
            KernelId::Mips
        },
        inputs: vec![("src".into(), input.to_string())],
        outputs: vec![("dst".into(), out.clone())],
        params,
        dispatch: Dispatch::Several(dispatches),
        light: Some(light),
    });
    out
}

/// The parameters and dispatches of the mip chain of a `width × height` map
/// ([`mip_dispatches`]): each dispatch reads one level (the `src` slot for the first, which also
/// stores it as level 0 through `dst0`) and writes the `count` levels after it through `dst1` …;
/// the kernel's other `dst` bindings repeat the last level written and are not stored to.
pub fn mip_chain(width: u32, height: u32, mode: BlurMode) -> (Vec<u8>, Vec<SubDispatch>) {
    let size = std::mem::size_of::<MipParams>();
    let odd = |n: u32| n > 1 && n % 2 == 1;
    let level = |binding: String, slot: &str, level: u32| LevelView {
        binding,
        slot: slot.into(),
        level,
    };
    let mut bytes = Vec::new();
    let mut dispatches = Vec::new();
    for (first, count) in mip_dispatches(width, height) {
        let p = MipParams {
            base: [width, height],
            first,
            count,
            mode: u32::from(mode.is_log()),
            copy: u32::from(first == 0),
            general: u32::from(odd((width >> first).max(1)) || odd((height >> first).max(1))),
            _pad: 0,
        };
        let at = bytes.len();
        bytes.extend_from_slice(bytemuck::bytes_of(&p));
        let mut levels = vec![match first {
            0 => level("src".into(), "src", 0),
            l => level("src".into(), "dst", l),
        }];
        if first == 0 {
            levels.push(level("dst0".into(), "dst", 0));
        }
        levels.extend((1..=count).map(|j| level(format!("dst{j}"), "dst", first + j)));
        dispatches.push(SubDispatch {
            params: at..at + size,
            levels,
            groups: mip_dispatch_groups(width, height, first),
        });
    }
    (bytes, dispatches)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mip_dispatches_cover_every_level_once() {
        assert_eq!(mip_dispatches(4096, 4096), [(0, 6), (6, 6)]);
        assert_eq!(mip_dispatches(8192, 8192), [(0, 6), (6, 6), (12, 1)]);
        assert_eq!(mip_dispatches(1, 1), [(0, 0)]);
        // 1000×37 (odd: a dispatch of one level): levels 500×18, 250×9 (odd), 125×4 (odd),
        // 62×2, then 31×1, 15×1, 7×1, 3×1, each odd, down to 1×1.
        assert_eq!(
            mip_dispatches(1000, 37),
            [
                (0, 1),
                (1, 1),
                (2, 1),
                (3, 1),
                (4, 1),
                (5, 1),
                (6, 1),
                (7, 1),
                (8, 1)
            ]
        );
        for (w, h) in [
            (1000, 37),
            (61, 61),
            (1, 57),
            (130, 7),
            (4096, 4096),
            (3, 2100),
        ] {
            let levels = crate::model::mip_levels(w, h);
            let d = mip_dispatches(w, h);
            let mut next = 0;
            for &(first, count) in &d {
                assert_eq!(first, next, "{w}x{h}: {d:?}");
                assert!((1..=MIP_LEVELS_PER_DISPATCH).contains(&count));
                // A dispatch only halves (or keeps a side of 1), but for a one-level one.
                for l in (first..first + count).skip(usize::from(count == 1)) {
                    let n = [(w >> l).max(1), (h >> l).max(1)];
                    assert!(n.iter().all(|&n| n == 1 || n % 2 == 0), "{w}x{h} level {l}");
                }
                next = first + count;
            }
            assert_eq!(next + 1, levels, "{w}x{h}: {d:?}");
        }
    }

    /// The chain as data: each dispatch's parameters are its slice of the node's bytes, it
    /// reads the last level written and names the levels it writes (4096²: levels 0–6, then
    /// 6–12; 1000×37: level 1 is 500×18, even, level 2 is 250×9, odd, a fractional step).
    #[test]
    fn mip_chain_dispatches_are_data() {
        let (bytes, d) = mip_chain(4096, 4096, BlurMode::LogSumExp);
        assert_eq!(d.len(), 2);
        assert_eq!(bytes.len(), 2 * std::mem::size_of::<MipParams>());
        let params =
            |k: usize| -> MipParams { bytemuck::pod_read_unaligned(&bytes[d[k].params.clone()]) };
        let want = MipParams {
            base: [4096, 4096],
            first: 6,
            count: 6,
            mode: 1,
            copy: 0,
            general: 0,
            _pad: 0,
        };
        assert_eq!(params(1), want);
        assert_eq!(
            params(0),
            MipParams {
                first: 0,
                copy: 1,
                ..want
            }
        );
        let names = |k: usize| -> Vec<(String, String, u32)> {
            d[k].levels
                .iter()
                .map(|v| (v.binding.clone(), v.slot.clone(), v.level))
                .collect()
        };
        let dst = |j: u32, l: u32| (format!("dst{j}"), "dst".to_string(), l);
        let mut first = vec![("src".to_string(), "src".to_string(), 0), dst(0, 0)];
        first.extend((1..=6).map(|j| dst(j, j)));
        assert_eq!(names(0), first);
        let mut second = vec![("src".to_string(), "dst".to_string(), 6)];
        second.extend((1..=6).map(|j| dst(j, 6 + j)));
        assert_eq!(names(1), second);
        // A workgroup per 32² tile of the level after the one read.
        assert_eq!(d[0].groups, [64, 64, 1]);
        assert_eq!(d[1].groups, [1, 1, 1]);
        let (bytes, d) = mip_chain(1000, 37, BlurMode::Linear);
        let general: Vec<u32> = d
            .iter()
            .map(|d| bytemuck::pod_read_unaligned::<MipParams>(&bytes[d.params.clone()]).general)
            .collect();
        assert_eq!(general, [1, 0, 1, 1, 0, 1, 1, 1, 1]);
        assert_eq!(d[0].groups, [16, 1, 1]);
    }
}
