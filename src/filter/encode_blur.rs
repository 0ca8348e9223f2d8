//! An encoding fused into the separable blur (`kernels/shared/encode_blur.wgsl`): the kernel
//! reads the rasterized depth once, encodes it in workgroup memory and writes the blurred
//! representation once. One dispatch up to [`ENCODE_BLUR_TILE_RADIUS`] taps each side; past it
//! two (the encoding fused into the horizontal pass, then `blur`'s vertical pass), because the
//! tile and its halo no longer fit WebGPU's 16 KiB of workgroup memory.

use super::{BlurMode, BlurParams, add_blur_pass};
use crate::graph::{Dispatch, Graph, Node, SizeRule};
use crate::kernels::KernelId;
use crate::model::Filter;

/// Outputs per side of a two-axis tile (`TILE`, which each fused kernel declares for
/// `kernels/shared/encode_blur.wgsl`): as large as the tile with its halo at
/// [`ENCODE_BLUR_TILE_RADIUS`] lets workgroup memory be, within WebGPU's 16 KiB. Two channels
/// (`vsm_blur`, 8 B a texel) take 24² outputs, 40² depths: 12.5 KiB; four (`evsm_blur`,
/// `msm_blur`) 16², 32² depths: 16 KiB. The 24² tile moves 13% fewer bytes than a 16² one (its
/// halo) and ran 1.12–1.29× faster on llvmpipe (`bench --sizes 1024,2048 --only vsm_blur`,
/// r = 4, alternated with the 16² build; `benches/RESULTS.md`).
pub fn encode_blur_tile(kernel: KernelId) -> u32 {
    match kernel {
        KernelId::VsmBlur | KernelId::VsmBlurRow => 24,
        _ => 16,
    }
}

/// Output rows of a two-axis tile where the kernel compiles in a CPU driver's layout (`const
/// CPU_TILE_ROWS`, which each fused kernel declares): its [`encode_blur_tile`] columns and
/// this many rows ([`Dispatch::Tiles`]). There 8 invocations walk the tile in strips, and a
/// taller tile encodes less halo a texel: VSM's 24 × 40 (its encoded rows, 48 at r = 4, are
/// three pairs for each of the 8 walks) took 0.91× the instructions of its 24², EVSM's and
/// MSM's 16 × 32 0.87× of their 16² (`benches/instructions.sh`; benches/RESULTS.md,
/// 2026-11-28). Their horizontal sums, `TILE × (CPU_TILE_ROWS + 2·TILE_RADIUS)`,
/// fit the workgroup memory the GPU's tile declares.
pub fn encode_blur_cpu_rows(kernel: KernelId) -> u32 {
    match kernel {
        KernelId::VsmBlur | KernelId::VsmBlurRow => 40,
        _ => 32,
    }
}

/// Outputs of a one-row workgroup, the two-pass fallback (`ROW`, which each fused kernel
/// declares for `kernels/shared/encode_blur.wgsl`). Four channels: 256 one an invocation
/// (`evsm_blur`, `msm_blur`), or on maps at least 512 wide 512 in runs of 2 (`evsm_blur_row`,
/// `msm_blur_row`). Two (VSM): 512 in runs of 2 (`vsm_blur`), or on maps at least 1024 wide
/// 1024 in runs of 4 (`vsm_blur_row`, [`encode_blur_row_kernel`]). Every
/// invocation stays busy, each row texel is read 2 + 2r times for a run of outputs instead of
/// 2r + 1 for each, and the halo is loaded once for more outputs.
pub fn encode_blur_row(kernel: KernelId) -> u32 {
    match kernel {
        KernelId::VsmBlurRow => 1024,
        KernelId::VsmBlur | KernelId::EvsmBlurRow | KernelId::MsmBlurRow => 512,
        _ => 256,
    }
}

/// The kernel of `kernel`'s row pass over a map `width` texels wide: the `*_blur_row` kernel
/// where its rows are full — VSM's 1024 texels in runs of 4, EVSM's and MSM's 512 in runs of 2,
/// 1.14–1.29× (VSM) and 1.17–1.19× (MSM) faster
/// at r = 32 on llvmpipe — else the tile kernel's own shorter rows (on a 512² map VSM's longer
/// rows left half the invocations idle: 1.2× slower; `benches/RESULTS.md`, 2026-11-27).
pub fn encode_blur_row_kernel(kernel: KernelId, width: u32) -> KernelId {
    let row = match kernel {
        KernelId::VsmBlur => KernelId::VsmBlurRow,
        KernelId::EvsmBlur => KernelId::EvsmBlurRow,
        KernelId::MsmBlur => KernelId::MsmBlurRow,
        k => return k,
    };
    if width >= encode_blur_row(row) {
        row
    } else {
        kernel
    }
}

/// Output columns of a strip of the redesign layout's tile ([`KernelLayout::Redesign`]:
/// `COLUMN_OUTS` in `kernels/shared/encode_blur_columns.wgsl`): its 256 invocations each own a
/// column of the depth, [`ENCODE_BLUR_TILE_RADIUS`] + 1 of them each side the halo.
///
/// [`KernelLayout::Redesign`]: crate::exec::KernelLayout::Redesign
pub const ENCODE_BLUR_COLUMNS: u32 = 240;

/// Output rows a workgroup of the redesign layout's strip walks (`COLUMN_ROWS`): with its halo
/// of 2r rows, 64 + 2r steps; a 4096² map is then 18 × 64 workgroups.
pub const ENCODE_BLUR_COLUMN_ROWS: u32 = 64;

/// The largest radius the one-dispatch tile takes (`TILE_RADIUS`): the tile's depths with
/// their halo, (TILE + 2·8)² texels of workgroup memory, fit 16 KiB ([`encode_blur_tile`]).
pub const ENCODE_BLUR_TILE_RADIUS: u32 = 7;

/// `BlurParams::axis` of the one-dispatch tile: both axes.
const BOTH_AXES: u32 = 2;

/// An encoding to fuse into a blur.
pub struct EncodeBlur<'a> {
    /// The fused kernel (a `*_blur` kernel importing `shared/encode_blur`).
    pub kernel: KernelId,
    /// The rasterized depth it reads.
    pub depth: &'a str,
    /// The unfiltered encoding's resource name: the outputs are `<encoded>.blur` (and
    /// `<encoded>.blur_h` for two passes).
    pub encoded: &'a str,
    /// The representation's format.
    pub format: wgpu::TextureFormat,
    /// The encoding's parameters (the kernel's `Params` before its `blur` member).
    pub params: &'a [u8],
    /// The depth's width in texels (which row kernel: [`encode_blur_row_kernel`]).
    pub width: u32,
}

/// Adds the nodes of `e` fused into `filter`'s blur, writing `<encoded>.blur` (the depth's
/// size): the node `<encoded>.blur`, or past [`ENCODE_BLUR_TILE_RADIUS`] the nodes
/// `<encoded>.blur_h` (the fused kernel, along x) and `<encoded>.blur` (`blur`, along y).
/// Returns the filtered resource, or `None` when `filter` is no blur.
pub fn add_encode_blur(
    graph: &mut Graph,
    light: usize,
    e: &EncodeBlur,
    filter: &Filter,
) -> Option<String> {
    let Filter::Blur {
        radius,
        sigma,
        kernel,
    } = *filter
    else {
        return None;
    };
    let both = BlurParams::new(BOTH_AXES, radius, sigma, kernel, BlurMode::Linear);
    let out = format!("{}.blur", e.encoded);
    if both.radius <= ENCODE_BLUR_TILE_RADIUS {
        fused_node(
            graph,
            light,
            e,
            &out,
            both,
            Some(encode_blur_tile(e.kernel)),
        );
        return Some(out);
    }
    let h = format!("{}.blur_h", e.encoded);
    let row = EncodeBlur {
        kernel: encode_blur_row_kernel(e.kernel, e.width),
        ..*e
    };
    fused_node(graph, light, &row, &h, BlurParams { axis: 0, ..both }, None);
    let v = BlurParams { axis: 1, ..both };
    Some(add_blur_pass(
        graph,
        light,
        [&h, e.depth, &out],
        e.format,
        v,
    ))
}

/// The node `name` of `e`'s fused kernel with `blur`: a workgroup per `tile`² outputs (per
/// `tile` × [`encode_blur_cpu_rows`] on a CPU driver, per [`ENCODE_BLUR_COLUMNS`] ×
/// [`ENCODE_BLUR_COLUMN_ROWS`] in the redesign layout), or per [`encode_blur_row`] texels of a
/// row when `tile` is `None`.
fn fused_node(
    graph: &mut Graph,
    light: usize,
    e: &EncodeBlur,
    name: &str,
    blur: BlurParams,
    tile: Option<u32>,
) {
    let size = SizeRule::Reduced {
        of: e.depth.to_string(),
        shift: 0,
    };
    // The row pass of the two-pass fallback is read by its column pass alone.
    let out = if tile.is_none() {
        graph.intermediate(name.to_string(), e.format, size, Some(light))
    } else {
        graph.resource(name.to_string(), e.format, size, Some(light))
    };
    let dispatch = match tile {
        None => Dispatch::Blocks {
            of: out.clone(),
            x: encode_blur_row(e.kernel),
            y: 1,
        },
        Some(t) => Dispatch::Redesigned {
            shipped: Box::new(Dispatch::Tiles {
                of: out.clone(),
                x: t,
                y: t,
                cpu_y: encode_blur_cpu_rows(e.kernel),
            }),
            redesign: Box::new(Dispatch::Blocks {
                of: out.clone(),
                x: ENCODE_BLUR_COLUMNS,
                y: ENCODE_BLUR_COLUMN_ROWS,
            }),
        },
    };
    graph.node(Node {
        name: name.to_string(),
        kernel: e.kernel,
        inputs: vec![("src".into(), e.depth.to_string())],
        outputs: vec![("dst".into(), out.clone())],
        params: [e.params, bytemuck::bytes_of(&blur)].concat(),
        dispatch,
        light: Some(light),
    });
}
