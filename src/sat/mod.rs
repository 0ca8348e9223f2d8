//! Summed-area tables (SAT) of a representation, built on the GPU in three passes over
//! tiles, for box filters of any size at a constant cost per lookup.
//!
//! [`add_sat`] adds three passes to a [`Graph`] (after Nehab et al. 2011: read twice, write
//! once, and no workgroup ever waits on another, so nothing needs the forward-progress
//! guarantees that Vulkan and WebGPU do not give). The map is cut into tiles of [`SAT_TILE`]²
//! texels, one workgroup each (64 invocations, each a 4×4 sub-block in registers: four times
//! the invocations of 64² tiles of 8×8, which a GPU needs to hide its latency):
//!
//! 1. `sat_tile_sums` / `sat_tile_sums_f32`: read and encode the tile; write the last row and the last column of the
//!    tile's own table (`.col_part`, `width × ⌈height / SAT_TILE⌉`, and `.row_part`,
//!    `⌈width / SAT_TILE⌉ × height`).
//! 2. `sat_carries`: one invocation per column and one per row ([`Dispatch::Lines`]), the
//!    exclusive prefix of those edges along the line: `.col_carry` (the map above the tile
//!    row) and `.row_carry` (the map left of the tile column, every row above included: each
//!    row workgroup first sums the totals of the tiles above its tile row). In
//!    [`crate::exec::KernelLayout::Redesign`] `sat_carries_scan`, a line's tiles shared among
//!    8 lanes and scanned in workgroup memory ([`carries_dispatch`]).
//! 3. `sat_tiles` / `sat_tiles_f32`: read and encode the tile again, scan it, add its column
//!    and row carries, store the inclusive table.
//!
//! Traffic per texel: the representation is read twice and the table written once, plus
//! 8/[`SAT_TILE`] of a table texel for the edges and carries. The table and its intermediates
//! have the representation's channels (1, 2 or 4: [`SatVariant::format`]).
//! [`five_pass`] keeps the first design (five scan passes over 4-channel tables) as the
//! benchmark's baseline. [`layers`] builds several tables whose tile kernels compute their
//! representations from one shared source (CSM's and CSSM's basis from the depth), the same
//! three passes once over all of them.
//!
//! Two codings ([`SatVariant`]): **fixed** point, `e = round(clamp((v − offset)·scale, ±limit))`
//! in wrapping u32, whose window sums are exact whatever the map size, and **float**,
//! `(v − offset)·scale` summed in f32, whose window sums lose
//! precision as the sums at their corners grow (fp32 has 24 significand bits).
//!
//! The scale rule of the fixed variant: a lookup's window of at most `A` texels (see
//! [`lookup_area`]) is exact when its true sum fits an i32, `A · max|e| ≤ 2³¹ − 1`. So every
//! texel is clamped to `|e| ≤ L = ⌊(2³¹ − 1) / A⌋` and
//! `scale = 2^⌊log₂(L / (½·(hi − lo)·(1 + 2⁻²⁰)))⌋` (capped at 2³²), the largest power of two
//! for which no value in `[lo, hi]` reaches the clamp; `offset = ½(lo + hi)`. A power of two
//! makes `(v − offset)·scale` exact in f32. Each value then carries at most `½ / scale` of
//! quantization error (plus 2⁻²⁴·|v − offset| from the subtraction), and so does every mean.

pub mod five_pass;
pub mod layers;
pub mod lookups;

use crate::error::{Error, Result};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::SatVariant;

/// Side of the square tile one workgroup of `sat_tile_sums` and `sat_tiles` owns (`TILE` in
/// `kernels/shared/sat_tile.wgsl`; a test checks them against each other).
pub const SAT_TILE: u32 = 32;

/// Lines per `sat_carries` workgroup, one per invocation (its workgroup size, and that of the
/// tile kernels): a row workgroup covers two tile rows.
pub const SAT_LINES_PER_GROUP: u32 = 64;

/// Lines per workgroup of the carries' redesign (`SCAN_LINES` in `kernels/sat_carries_scan.wgsl`,
/// 8 lanes a line, each holding 8 consecutive tiles of a segment; a test checks them against
/// each other): a row workgroup covers one tile row.
pub const SAT_SCAN_LINES: u32 = 32;

/// The dispatch of a table's carries over `of` (`layers` tables stacked, or one): one
/// invocation a column and one a row of `sat_carries` ([`SAT_LINES_PER_GROUP`] a workgroup)
/// in the shipped layouts; in [`crate::exec::KernelLayout::Redesign`], whose `sat_carries`
/// nodes compile `sat_carries_scan` (a line's tiles among 8 lanes, scanned in workgroup
/// memory), [`SAT_SCAN_LINES`] lines a workgroup.
pub fn carries_dispatch(of: &str, layers: Option<u32>) -> Dispatch {
    let lines = |per_group| {
        let d = Dispatch::Lines {
            of: of.to_string(),
            per_group,
        };
        match layers {
            Some(layers) => Dispatch::Layers {
                base: Box::new(d),
                layers,
            },
            None => d,
        }
    };
    Dispatch::Redesigned {
        shipped: Box::new(lines(SAT_LINES_PER_GROUP)),
        redesign: Box::new(lines(SAT_SCAN_LINES)),
    }
}

/// The largest `max_area` the fixed-point coding accepts: one unit per texel must fit an i32.
pub const MAX_FIXED_AREA: u64 = (1 << 31) - 1;

/// The sampler of f32 summed-area tables read with bilinear-filtered fetches (linear
/// filtering, clamped to the edge, level 0; `kernels/shared/sat.wgsl`, `sat_mean_linear`): a
/// plug-in host binds it after the maps where `Prefilter::needs_filtering_sampler` says so (the
/// plug-in re-exports it as `prefilter::SAT_SAMPLER_DESCRIPTOR`); the renderer and
/// [`lookups::lookup_means`] bind the same one.
pub const SAT_SAMPLER_DESCRIPTOR: wgpu::SamplerDescriptor<'static> = wgpu::SamplerDescriptor {
    label: Some("shadowgraph.sat_sampler"),
    address_mode_u: wgpu::AddressMode::ClampToEdge,
    address_mode_v: wgpu::AddressMode::ClampToEdge,
    address_mode_w: wgpu::AddressMode::ClampToEdge,
    mag_filter: wgpu::FilterMode::Linear,
    min_filter: wgpu::FilterMode::Linear,
    mipmap_filter: wgpu::MipmapFilterMode::Nearest,
    lod_min_clamp: 0.0,
    lod_max_clamp: 32.0,
    compare: None,
    anisotropy_clamp: 1,
    border_color: None,
};

/// The kernels of a table's first and last pass in `variant` (one per variant, so the
/// variant's arithmetic is a constant in them).
fn tile_kernels(variant: SatVariant) -> [KernelId; 2] {
    match variant {
        SatVariant::Fixed => [KernelId::SatTileSums, KernelId::SatTiles],
        SatVariant::Float => [KernelId::SatTileSumsF32, KernelId::SatTilesF32],
    }
}

/// Parameters of the `sat_*` kernels. Keep in sync with `SatParams` in
/// `kernels/shared/sat_params.wgsl`.
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
    /// The five-pass baseline's `sat_carry`: 0 scans along rows, 1 along columns (0 elsewhere).
    pub axis: u32,
    /// Tables whose edges `sat_carries` finds stacked in its inputs ([`layers`]; 0 or 1: one).
    pub layers: u32,
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
            layers: 1,
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

/// Adds the three passes building the inclusive SAT of `input` (a float representation of
/// `light`, 1–4 channels, any size) coded as `coding`; returns the table's resource,
/// `<input>.sat`, the size of `input`, in [`SatVariant::format`] for the input's channels.
///
/// Intermediates, in the table's channels as u32 (the f32 variant carries f32 bits):
/// `<input>.sat.col_part` and `.col_carry` (`width × ⌈height / SAT_TILE⌉`), `.row_part` and
/// `.row_carry` (`⌈width / SAT_TILE⌉ × height`), sized by [`SizeRule::Blocks`] so the planner
/// follows the input.
pub fn add_sat(graph: &mut Graph, light: usize, input: &str, coding: &SatCoding) -> String {
    let channels = graph.find(input).map_or(4, |r| format_channels(r.format));
    let name = sat_name(input);
    let words = SatVariant::Fixed.format(channels);
    let blocks = |x, y| SizeRule::Blocks {
        of: input.to_string(),
        x,
        y,
    };
    let mut res = |suffix: &str, size: SizeRule| {
        // Read by the table's own passes alone, with `textureLoad`.
        graph.intermediate(format!("{name}.{suffix}"), words, size, Some(light))
    };
    let col_part = res("col_part", blocks(1, SAT_TILE));
    let row_part = res("row_part", blocks(SAT_TILE, 1));
    let col_carry = res("col_carry", blocks(1, SAT_TILE));
    let row_carry = res("row_carry", blocks(SAT_TILE, 1));
    let same = SizeRule::Reduced {
        of: input.to_string(),
        shift: 0,
    };
    // A fixed-point table is only loaded, never filtered (its lookups' `textureLoad`).
    let out = if coding.variant == SatVariant::Fixed {
        graph.intermediate(
            name.clone(),
            coding.variant.format(channels),
            same,
            Some(light),
        )
    } else {
        graph.resource(
            name.clone(),
            coding.variant.format(channels),
            same,
            Some(light),
        )
    };
    let tiles = Dispatch::Blocks {
        of: input.to_string(),
        x: SAT_TILE,
        y: SAT_TILE,
    };
    let params = bytemuck::bytes_of(&coding.params(channels, 0)).to_vec();
    let passes = [
        (
            ".tile_sums",
            tile_kernels(coding.variant)[0],
            vec![("src", input)],
            vec![("col_part", col_part.as_str()), ("row_part", &row_part)],
            tiles.clone(),
        ),
        (
            ".carries",
            KernelId::SatCarries,
            vec![("col_part", col_part.as_str()), ("row_part", &row_part)],
            vec![("col_carry", col_carry.as_str()), ("row_carry", &row_carry)],
            carries_dispatch(input, None),
        ),
        (
            "",
            tile_kernels(coding.variant)[1],
            vec![
                ("src", input),
                ("col_carry", &col_carry),
                ("row_carry", &row_carry),
            ],
            vec![("dst", out.as_str())],
            tiles,
        ),
    ];
    for (suffix, kernel, inputs, outputs, dispatch) in passes {
        graph.node(Node {
            name: format!("{name}{suffix}"),
            kernel,
            inputs: named(inputs),
            outputs: named(outputs),
            params: params.clone(),
            dispatch,
            light: Some(light),
        });
    }
    out
}

fn named(pairs: Vec<(&str, &str)>) -> Vec<(String, String)> {
    pairs
        .into_iter()
        .map(|(b, r)| (b.to_string(), r.to_string()))
        .collect()
}

/// The depth of the f32 table's summation tree for a `width × height` map: every f32 table
/// texel is a sum of the scaled values over its rectangle in which no value passes through
/// more than this many roundings, so it is within `d·2⁻²⁴·Σ|x|` of the exact sum. Per pass
/// (see the kernels; 4×4 sub-blocks, 8×8 of them a tile): the tile edges 20 (a sub-block's
/// row sums 3, prefixed 3, across the sub-blocks 7, the sub-rows above 7); a column carry
/// that many plus one per tile above, a row carry one more per tile above (the tiles' totals)
/// and one per tile to the left; in the last pass the sub-block's table 6, the sums left of
/// it 12 and above it 20 (its columns' 12 plus the whole sub-blocks above-left, 19), each
/// added to its carry, and both sides added:
/// `32 + tiles_x + tiles_y` bounds them all. The redesign layout's tile passes
/// (`kernels/shared/sat_strip.wgsl`) stay within it: a tile's own table at most 20 deep (a
/// column's running sum in chunks of 8 rows, 8; the upper half-tile's sums, 1; the row scan, 5
/// with 32-lane subgroups, at most 10 with narrower ones), as the shipped edges.
pub fn float_sum_depth(width: u32, height: u32) -> u32 {
    32 + width.div_ceil(SAT_TILE) + height.div_ceil(SAT_TILE)
}
/// The per-texel values a table holds, decoded: texel `(x, y)` of channel `c` is the 1×1
/// window sum `S(x, y) − S(x − 1, y) − S(x, y − 1) + S(x − 1, y − 1)` (wrapping u32 read as
/// i32 for the fixed variant, exact; f64 differences of the f32 sums for the float variant),
/// divided by the scale, plus the offset. `table` holds the table's raw 32-bit words,
/// row-major, as many per texel as its format has channels (`table.len() / (width·height)`);
/// the first `channels` channels are returned. For the fixed variant this is
/// the quantized representation the lookups integrate, exactly.
pub fn decode_table(
    table: &[u32],
    width: usize,
    height: usize,
    coding: &SatCoding,
    channels: usize,
) -> Vec<f32> {
    let stride = table.len() / (width * height).max(1);
    let at = |x: usize, y: usize, c: usize| table[(y * width + x) * stride + c];
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

    /// A `const NAME: u32` of `kernel`'s resolved WGSL, and its workgroup's width.
    fn wgsl_consts(kernel: &str, names: &[&str]) -> (Vec<Option<u32>>, u32) {
        let wgsl = crate::kernels::resolve(kernel, None).unwrap();
        let (module, r) = crate::kernels::reflect(kernel, &wgsl).unwrap();
        let value = |name: &str| {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))?;
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => Some(v),
                _ => None,
            }
        };
        let wg = r.workgroup_size.unwrap_or_default()[0];
        (names.iter().map(|n| value(n)).collect(), wg)
    }

    #[test]
    fn carries_scan_constants_match_the_wgsl() {
        let names = [
            "SCAN_LINES",
            "SCAN_PARTS",
            "SCAN_BATCH",
            "SCAN_SPAN",
            "SCAN_QUARTERS",
            "TILE",
        ];
        let (c, wg) = wgsl_consts("sat_carries_scan", &names);
        let [lines, parts, batch, span, quarters, tile] = [0, 1, 2, 3, 4, 5].map(|i| c[i].unwrap());
        // A row workgroup is one tile row; its lanes cover a segment's tiles QUARTERS times.
        assert_eq!((lines, tile), (SAT_SCAN_LINES, SAT_TILE));
        assert_eq!(lines, tile);
        assert_eq!(wg, lines * parts);
        assert_eq!(span, parts * batch);
        assert_eq!(quarters * span, wg);
    }

    #[test]
    fn sat_plans_three_passes_sized_by_tiles() {
        let mut g = Graph::default();
        g.import("in", wgpu::TextureFormat::Rg32Float, 3000, 37, Some(0));
        let coding = SatCoding::fixed(64, [0.0; 4], [1.0; 4]).unwrap();
        let out = add_sat(&mut g, 0, "in", &coding);
        assert_eq!(out, "in.sat");
        let p = crate::graph::plan(&g, &[&out]).unwrap();
        let kernels: Vec<&str> = p.steps.iter().map(|s| s.node.kernel.as_str()).collect();
        assert_eq!(kernels, ["sat_tile_sums", "sat_carries", "sat_tiles"]);
        let size = |n: &str| {
            let r = p.resource(n).unwrap();
            (r.width, r.height, r.resource.format)
        };
        let u = wgpu::TextureFormat::Rg32Uint;
        assert_eq!(size("in.sat"), (3000, 37, u));
        assert_eq!(size("in.sat.col_part"), (3000, 2, u));
        assert_eq!(size("in.sat.row_carry"), (94, 37, u));
        let params: &SatParams = bytemuck::from_bytes(&p.steps[0].node.params);
        assert_eq!((params.channels, params.float_sums), (2, 0));
        let size = |r: &str| p.resource(r).map(|p| (p.width, p.height));
        assert_eq!(
            p.steps[0].node.dispatch.groups(size, [64, 1, 1]),
            Some([94, 2, 1])
        );
        assert_eq!(
            p.steps[1].node.dispatch.groups(size, [64, 1, 1]),
            Some([47, 2, 1])
        );
        // The redesign's carries: 32 lines a workgroup; a shipped layout keeps 64.
        for (gpu, redesign, groups) in [(true, true, 94), (true, false, 47), (false, false, 47)] {
            let d = &p.steps[1].node.dispatch;
            assert_eq!(
                d.groups_in(size, [256, 1, 1], gpu, redesign),
                Some([groups, 2, 1])
            );
        }

        for (format, channels, table) in [
            (
                wgpu::TextureFormat::R32Float,
                1,
                wgpu::TextureFormat::R32Float,
            ),
            (
                wgpu::TextureFormat::Rgba16Float,
                4,
                wgpu::TextureFormat::Rgba32Float,
            ),
        ] {
            let mut g = Graph::default();
            g.import("in", format, 5, 5, Some(0));
            let coding = SatCoding::float([0.0; 4], [1.0; 4]).unwrap();
            let out = add_sat(&mut g, 0, "in", &coding);
            let p = crate::graph::plan(&g, &[&out]).unwrap();
            assert_eq!(p.steps[2].node.kernel, "sat_tiles_f32");
            assert_eq!(p.resource(&out).unwrap().resource.format, table);
            let params: &SatParams = bytemuck::from_bytes(&p.steps[2].node.params);
            assert_eq!((params.channels, params.float_sums), (channels, 1));
        }
    }
}
