//! Summed-area tables (SAT) of a representation, built on the GPU from work-efficient parallel
//! prefix scans, for box filters of any size at a constant cost per lookup.
//!
//! [`add_sat`] adds five passes to a [`Graph`]; every pass is a plain dispatch and no
//! workgroup ever waits on another (no decoupled look-back, which needs forward-progress
//! guarantees that Vulkan and WebGPU do not give):
//!
//! 1. `sat_rows`: encode each texel and scan each row in blocks of [`SAT_BLOCK`] texels, one
//!    workgroup per block (4 texels per invocation scanned in registers, the invocations'
//!    totals by Blelloch's up-sweep/down-sweep in workgroup memory); block totals to
//!    `.row_sums`.
//! 2. `sat_carry`: the exclusive prefix of each row's block totals (`.row_carry`), one
//!    invocation per row ([`SAT_CARRY_LINES`] per workgroup), serially: a row has at most
//!    ⌈32768 / [`SAT_BLOCK`]⌉ = 32 totals.
//! 3. `sat_cols_reduce`: totals of blocks of [`SAT_BLOCK`] rows of the full row prefix
//!    (`.rows` plus `.row_carry`, added on load) per column (`.col_sums`).
//! 4. `sat_carry`: their exclusive prefix down each column (`.col_carry`).
//! 5. `sat_cols` / `sat_cols_f32`: scan each column block of the full row prefix, add the
//!    column carry, store the inclusive SAT.
//!
//! Traffic: the representation is read once, the block-local row scans are written once and
//! read twice, the table is written once (plus the block totals, 1/[`SAT_BLOCK`] of that).
//!
//! Two codings ([`SatVariant`]): **fixed** point, `e = round(clamp((v − offset)·scale, ±limit))`
//! in wrapping u32 (`rgba32uint`), whose window sums are exact whatever the map size, and
//! **float** (`rgba32float`), `(v − offset)·scale` summed in f32, whose window sums lose
//! precision as the sums at their corners grow (fp32 has 24 significand bits).
//!
//! The scale rule of the fixed variant: a lookup's window of at most `A` texels (see
//! [`lookup_area`]) is exact when its true sum fits an i32, `A · max|e| ≤ 2³¹ − 1`. So every
//! texel is clamped to `|e| ≤ L = ⌊(2³¹ − 1) / A⌋` and
//! `scale = 2^⌊log₂(L / (½·(hi − lo)·(1 + 2⁻²⁰)))⌋` (capped at 2³²), the largest power of two
//! for which no value in `[lo, hi]` reaches the clamp; `offset = ½(lo + hi)`. A power of two
//! makes `(v − offset)·scale` exact in f32. Each value then carries at most `½ / scale` of
//! quantization error (plus 2⁻²⁴·|v − offset| from the subtraction), and so does every mean.

use crate::error::{Error, Result};
use crate::graph::{Dispatch, Graph, Node, SizeRule};

/// Texels per scanned block, one workgroup each (`BLOCK` = `WG_SIZE · ITEMS` in
/// `kernels/shared/sat_scan.wgsl`; a test checks them against each other).
pub const SAT_BLOCK: u32 = 1024;

/// Lines of block totals per `sat_carry` workgroup, one per invocation (its workgroup size).
pub const SAT_CARRY_LINES: u32 = 64;

/// The largest `max_area` the fixed-point coding accepts: one unit per texel must fit an i32.
pub const MAX_FIXED_AREA: u64 = (1 << 31) - 1;

/// How the table stores its sums.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SatVariant {
    /// u32 fixed point with wraparound (`rgba32uint`): exact window sums.
    Fixed,
    /// f32 (`rgba32float`): window sums lose precision with the magnitude of the corners.
    Float,
}

impl SatVariant {
    /// The table's texel format.
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            Self::Fixed => wgpu::TextureFormat::Rgba32Uint,
            Self::Float => wgpu::TextureFormat::Rgba32Float,
        }
    }

    /// The kernel of the last pass (the only one whose output type differs).
    fn last_kernel(self) -> &'static str {
        match self {
            Self::Fixed => "sat_cols",
            Self::Float => "sat_cols_f32",
        }
    }
}

/// Parameters of the `sat_*` kernels. Keep in sync with `SatParams` in
/// `kernels/shared/sat_scan.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SatParams {
    /// Subtracted from every value before scaling.
    pub offset: [f32; 4],
    /// Units per value unit (fixed: a power of two; float: 1).
    pub scale: [f32; 4],
    /// `|(v − offset)·scale|` is clamped to this.
    pub limit: [f32; 4],
    /// Channels of the representation used (1–4); the others are stored as 0.
    pub channels: u32,
    /// 1 for the f32 variant, 0 for fixed point.
    pub float_sums: u32,
    /// `sat_carry`: 0 scans along rows, 1 along columns.
    pub axis: u32,
    /// Padding.
    pub _pad: u32,
}

/// How values are coded into a table, per channel: everything a lookup needs to decode it
/// (`sat_mean_fixed` / `sat_mean_float` in `kernels/shared/sat.wgsl` take `offset` and `scale`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SatCoding {
    /// Fixed point or f32.
    pub variant: SatVariant,
    /// Subtracted before scaling: the centre of the value range.
    pub offset: [f32; 4],
    /// Multiplied after the offset.
    pub scale: [f32; 4],
    /// Clamp of the scaled value (fixed: keeps every window of `max_area` texels exact).
    pub limit: [f32; 4],
}

impl SatCoding {
    /// Fixed point for windows of up to `max_area` texels (see [`lookup_area`]) of values in
    /// `[lo[c], hi[c]]` per channel; values outside are clamped (at a slightly wider bound).
    pub fn fixed(max_area: u64, lo: [f32; 4], hi: [f32; 4]) -> Result<Self> {
        let limit = fixed_limit(max_area)?;
        let mut c = Self {
            variant: SatVariant::Fixed,
            offset: [0.0; 4],
            scale: [1.0; 4],
            limit: [limit; 4],
        };
        for i in 0..4 {
            c.offset[i] = centre(lo[i], hi[i])?;
            c.scale[i] = fixed_scale(max_area, lo[i], hi[i])?;
        }
        Ok(c)
    }

    /// f32 sums of values centred on the middle of `[lo[c], hi[c]]` (centring keeps the
    /// corner sums, and so the rounding of window sums, small for maps near a constant).
    pub fn float(lo: [f32; 4], hi: [f32; 4]) -> Result<Self> {
        let mut offset = [0.0; 4];
        for i in 0..4 {
            offset[i] = centre(lo[i], hi[i])?;
        }
        Ok(Self {
            variant: SatVariant::Float,
            offset,
            scale: [1.0; 4],
            limit: [f32::MAX; 4],
        })
    }

    /// The kernels' parameters for a representation with `channels` channels.
    pub fn params(&self, channels: u32, axis: u32) -> SatParams {
        SatParams {
            offset: self.offset,
            scale: self.scale,
            limit: self.limit,
            channels: channels.clamp(1, 4),
            float_sums: u32::from(self.variant == SatVariant::Float),
            axis,
            _pad: 0,
        }
    }
}

/// `½(lo + hi)` for a valid range.
fn centre(lo: f32, hi: f32) -> Result<f32> {
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(Error::Invalid(format!(
            "SAT value range [{lo}, {hi}] must be finite with lo ≤ hi"
        )));
    }
    Ok(lo + 0.5 * (hi - lo))
}

/// `L = ⌊(2³¹ − 1) / max_area⌋` as the largest f32 not above it.
fn fixed_limit(max_area: u64) -> Result<f32> {
    if max_area == 0 || max_area > MAX_FIXED_AREA {
        return Err(Error::Invalid(format!(
            "fixed-point SAT window area {max_area} must be in 1..={MAX_FIXED_AREA}"
        )));
    }
    let l = MAX_FIXED_AREA / max_area;
    // L < 2³¹: clearing the bits below f32's 24-bit significand rounds it down exactly.
    let keep = 64 - l.leading_zeros();
    let l = if keep > 24 {
        l >> (keep - 24) << (keep - 24)
    } else {
        l
    };
    Ok(l as f32)
}

/// The fixed-point scale for windows of up to `max_area` texels of values in `[lo, hi]`:
/// `2^⌊log₂(L / (½·(hi − lo)·(1 + 2⁻²⁰)))⌋` with `L = ⌊(2³¹ − 1) / max_area⌋`, capped at
/// 2³², so that `max_area · max|e| ≤ 2³¹ − 1` (window sums never leave the i32 range, where
/// wrapping u32 differences are exact). Errors for an empty or inverted range or an area
/// outside `1..=2³¹ − 1`.
pub fn fixed_scale(max_area: u64, lo: f32, hi: f32) -> Result<f32> {
    centre(lo, hi)?;
    let limit = f64::from(fixed_limit(max_area)?);
    // The margin covers the f32 rounding of the offset and of v − offset.
    let half = 0.5 * (f64::from(hi) - f64::from(lo)) * (1.0 + 2f64.powi(-20));
    let exponent = if half > 0.0 {
        (limit / half).log2().floor().min(32.0)
    } else {
        32.0
    };
    Ok(2f64.powi(exponent as i32) as f32)
}

/// The largest integer window a lookup of a `width × height` rectangle (texels, any
/// position) touches: `(⌈width⌉ + 1)·(⌈height⌉ + 1)`, a side thinner than the lookups' minimum
/// extent (2⁻⁸ texel, `SAT_MIN_EXTENT` in `kernels/shared/sat.wgsl`) counting as that; pass it
/// to [`SatCoding::fixed`]. The sides are those the shader sees, `x1 − x0` in f32 (an edge
/// computed as `x0 + w` may round past `w`).
pub fn lookup_area(width: f32, height: f32) -> u64 {
    let side = |v: f32| v.max(1.0 / 256.0).ceil() as u64 + 1;
    side(width) * side(height)
}

/// Channels a representation of `format` uses (its texel components).
pub fn format_channels(format: wgpu::TextureFormat) -> u32 {
    format
        .components_with_aspect(wgpu::TextureAspect::All)
        .clamp(1, 4)
        .into()
}

/// The table's resource name for `input`: `<input>.sat`.
pub fn sat_name(input: &str) -> String {
    format!("{input}.sat")
}

/// Adds the five passes building the inclusive SAT of `input` (a float representation of
/// `light`, 1–4 channels, any size) coded as `coding`; returns the table's resource,
/// `<input>.sat` (`rgba32uint` or `rgba32float`, same size as `input`, always 4 channels).
///
/// Intermediates, all `rgba32uint` (the f32 variant carries f32 bits): `<input>.sat.rows`
/// (block-local row scans, input size), `.row_sums` and `.row_carry`
/// (`⌈width / SAT_BLOCK⌉ × height`), `.col_sums` and `.col_carry`
/// (`width × ⌈height / SAT_BLOCK⌉`), sized by [`SizeRule`]s so the planner follows the input.
pub fn add_sat(graph: &mut Graph, light: usize, input: &str, coding: &SatCoding) -> String {
    let channels = graph.find(input).map_or(4, |r| format_channels(r.format));
    let name = sat_name(input);
    let u32x4 = wgpu::TextureFormat::Rgba32Uint;
    let same = SizeRule::Reduced {
        of: input.to_string(),
        shift: 0,
    };
    let blocks = |x, y| SizeRule::Blocks {
        of: input.to_string(),
        x,
        y,
    };
    let mut res = |suffix: &str, size: SizeRule| {
        graph.resource(format!("{name}.{suffix}"), u32x4, size, Some(light))
    };
    let rows = res("rows", same.clone());
    let row_sums = res("row_sums", blocks(SAT_BLOCK, 1));
    let row_carry = res("row_carry", blocks(SAT_BLOCK, 1));
    let col_sums = res("col_sums", blocks(1, SAT_BLOCK));
    let col_carry = res("col_carry", blocks(1, SAT_BLOCK));
    let out = graph.resource(name.clone(), coding.variant.format(), same, Some(light));

    let names = SatNames {
        input,
        rows: &rows,
        row_sums: &row_sums,
        row_carry: &row_carry,
        col_sums: &col_sums,
        col_carry: &col_carry,
        out: &out,
    };
    for pass in passes(&names, coding.variant) {
        graph.node(Node {
            name: format!("{name}{}", pass.suffix),
            kernel: pass.kernel.into(),
            inputs: named(pass.inputs),
            outputs: named(pass.outputs),
            params: bytemuck::bytes_of(&coding.params(channels, pass.axis)).to_vec(),
            dispatch: Dispatch::Blocks {
                of: pass.blocks_of.to_string(),
                x: pass.block[0],
                y: pass.block[1],
            },
            light: Some(light),
        });
    }
    out
}

/// The per-texel values a table holds, decoded: texel `(x, y)` of channel `c` is the 1×1
/// window sum `S(x, y) − S(x − 1, y) − S(x, y − 1) + S(x − 1, y − 1)` (wrapping u32 read as
/// i32 for the fixed variant, exact; f64 differences of the f32 sums for the float variant),
/// divided by the scale, plus the offset. `table` holds the table's raw 32-bit words (4 per
/// texel, row-major); the first `channels` channels are returned. For the fixed variant this is
/// the quantized representation the lookups integrate, exactly.
pub fn decode_table(
    table: &[u32],
    width: usize,
    height: usize,
    coding: &SatCoding,
    channels: usize,
) -> Vec<f32> {
    let at = |x: usize, y: usize, c: usize| table[(y * width + x) * 4 + c];
    let mut out = Vec::with_capacity(width * height * channels);
    for y in 0..height {
        for x in 0..width {
            for c in 0..channels {
                let sum = match coding.variant {
                    SatVariant::Fixed => {
                        let mut v = at(x, y, c);
                        if x > 0 {
                            v = v.wrapping_sub(at(x - 1, y, c));
                        }
                        if y > 0 {
                            v = v.wrapping_sub(at(x, y - 1, c));
                        }
                        if x > 0 && y > 0 {
                            v = v.wrapping_add(at(x - 1, y - 1, c));
                        }
                        f64::from(v as i32)
                    }
                    SatVariant::Float => {
                        let f = |x: usize, y: usize| f64::from(f32::from_bits(at(x, y, c)));
                        let mut v = f(x, y);
                        if x > 0 {
                            v -= f(x - 1, y);
                        }
                        if y > 0 {
                            v -= f(x, y - 1);
                        }
                        if x > 0 && y > 0 {
                            v += f(x - 1, y - 1);
                        }
                        v
                    }
                };
                let value = sum / f64::from(coding.scale[c]) + f64::from(coding.offset[c]);
                out.push(value as f32);
            }
        }
    }
    out
}

/// The resources of one table.
struct SatNames<'a> {
    input: &'a str,
    rows: &'a str,
    row_sums: &'a str,
    row_carry: &'a str,
    col_sums: &'a str,
    col_carry: &'a str,
    out: &'a str,
}

/// One pass of [`add_sat`]: a node named `<table><suffix>` with one workgroup per `block` of
/// `blocks_of`.
struct Pass<'a> {
    suffix: &'a str,
    kernel: &'a str,
    inputs: Vec<(&'a str, &'a str)>,
    outputs: Vec<(&'a str, &'a str)>,
    axis: u32,
    blocks_of: &'a str,
    block: [u32; 2],
}

/// The five passes, in order (see the module documentation).
fn passes<'a>(n: &SatNames<'a>, variant: SatVariant) -> [Pass<'a>; 5] {
    let (b, lines) = (SAT_BLOCK, SAT_CARRY_LINES);
    [
        Pass {
            suffix: ".rows",
            kernel: "sat_rows",
            inputs: vec![("src", n.input)],
            outputs: vec![("dst", n.rows), ("sums", n.row_sums)],
            axis: 0,
            blocks_of: n.input,
            block: [b, 1],
        },
        Pass {
            suffix: ".row_carry",
            kernel: "sat_carry",
            inputs: vec![("src", n.row_sums)],
            outputs: vec![("dst", n.row_carry)],
            axis: 0,
            blocks_of: n.row_sums,
            block: [0, lines],
        },
        Pass {
            suffix: ".col_sums",
            kernel: "sat_cols_reduce",
            inputs: vec![("src", n.rows), ("row_carry", n.row_carry)],
            outputs: vec![("dst", n.col_sums)],
            axis: 1,
            blocks_of: n.input,
            block: [1, b],
        },
        Pass {
            suffix: ".col_carry",
            kernel: "sat_carry",
            inputs: vec![("src", n.col_sums)],
            outputs: vec![("dst", n.col_carry)],
            axis: 1,
            blocks_of: n.col_sums,
            block: [lines, 0],
        },
        Pass {
            suffix: "",
            kernel: variant.last_kernel(),
            inputs: vec![
                ("src", n.rows),
                ("row_carry", n.row_carry),
                ("col_carry", n.col_carry),
            ],
            outputs: vec![("dst", n.out)],
            axis: 1,
            blocks_of: n.input,
            block: [1, b],
        },
    ]
}

fn named(pairs: Vec<(&str, &str)>) -> Vec<(String, String)> {
    pairs
        .into_iter()
        .map(|(b, r)| (b.to_string(), r.to_string()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_scale_keeps_the_largest_window_in_i32() {
        for (area, lo, hi) in [
            (1u64, 0.0f32, 1.0f32),
            (9, 0.0, 1.0),
            (33 * 33, 0.2, 0.7),
            (1024 * 1024, 0.0, 1.0),
            (8192 * 8192, -3.0, 5.0),
            (MAX_FIXED_AREA, 0.0, 1.0),
        ] {
            let s = f64::from(fixed_scale(area, lo, hi).unwrap());
            assert_eq!(s.log2().fract(), 0.0, "{area}: {s} is a power of two");
            let half = 0.5 * f64::from(hi - lo);
            let limit = f64::from(fixed_limit(area).unwrap());
            // Values in [lo, hi] stay inside the clamp, and a window of clamped values fits.
            assert!(half * s <= limit, "{area}: {s}");
            assert!(area as f64 * limit <= MAX_FIXED_AREA as f64, "{area}");
            // The largest such power of two: twice the scale would cross the clamp.
            assert!(
                2.0 * half * s * (1.0 + 2f64.powi(-20)) > limit,
                "{area}: {s}"
            );
        }
        assert_eq!(fixed_scale(4, 0.5, 0.5).unwrap(), 2f32.powi(32));
        assert!(fixed_scale(0, 0.0, 1.0).is_err());
        assert!(fixed_scale(MAX_FIXED_AREA + 1, 0.0, 1.0).is_err());
        assert!(fixed_scale(4, 1.0, 0.0).is_err());
        assert!(fixed_scale(4, f32::NAN, 1.0).is_err());
    }

    #[test]
    fn limit_is_an_exact_f32_not_above_the_bound() {
        for area in [1, 2, 3, 1000, 1 << 20, MAX_FIXED_AREA] {
            let l = fixed_limit(area).unwrap();
            assert!(f64::from(l) <= (MAX_FIXED_AREA / area) as f64, "{area}");
            assert_eq!(l.fract(), 0.0);
        }
    }

    #[test]
    fn lookup_area_covers_any_placement() {
        assert_eq!(lookup_area(1.0, 1.0), 4);
        assert_eq!(lookup_area(0.25, 3.5), 2 * 5);
        assert_eq!(lookup_area(0.0, 0.0), 4);
        // The nodes of an edge pair x0, x1 = x0 + w are ⌊x0⌋ ..= ⌊x1⌋ + 1, as in `sat_nodes`.
        for i in 0..2000u32 {
            let x0 = (i as f32 * 0.618_034).fract() * 50.0;
            let w = (i as f32 * 0.414_213_6).fract() * 9.0;
            let x1 = x0 + w.max(1.0 / 256.0);
            let span = (x1.floor() - x0.floor()) as u64 + 1;
            assert!(span * span <= lookup_area(w, w), "x0 {x0} w {w}");
        }
    }

    #[test]
    fn sat_plans_five_passes_sized_by_blocks() {
        let mut g = Graph::default();
        g.import("in", wgpu::TextureFormat::Rg32Float, 3000, 37, Some(0));
        let coding = SatCoding::fixed(64, [0.0; 4], [1.0; 4]).unwrap();
        let out = add_sat(&mut g, 0, "in", &coding);
        assert_eq!(out, "in.sat");
        let p = crate::graph::plan(&g, &[&out]).unwrap();
        let kernels: Vec<&str> = p.steps.iter().map(|s| s.node.kernel.as_str()).collect();
        assert_eq!(
            kernels,
            [
                "sat_rows",
                "sat_carry",
                "sat_cols_reduce",
                "sat_carry",
                "sat_cols"
            ]
        );
        let size = |n: &str| {
            let r = p.resource(n).unwrap();
            (r.width, r.height, r.resource.format)
        };
        let u = wgpu::TextureFormat::Rgba32Uint;
        assert_eq!(size("in.sat"), (3000, 37, u));
        assert_eq!(size("in.sat.rows"), (3000, 37, u));
        assert_eq!(size("in.sat.row_carry"), (3, 37, u));
        assert_eq!(size("in.sat.col_carry"), (3000, 1, u));
        let params: &SatParams = bytemuck::from_bytes(&p.steps[0].node.params);
        assert_eq!((params.channels, params.float_sums), (2, 0));

        let mut g = Graph::default();
        g.import("in", wgpu::TextureFormat::R32Float, 5, 5, Some(0));
        let out = add_sat(
            &mut g,
            0,
            "in",
            &SatCoding::float([0.0; 4], [1.0; 4]).unwrap(),
        );
        let p = crate::graph::plan(&g, &[&out]).unwrap();
        assert_eq!(p.steps[4].node.kernel, "sat_cols_f32");
        assert_eq!(
            p.resource(&out).unwrap().resource.format,
            wgpu::TextureFormat::Rgba32Float
        );
    }
}
