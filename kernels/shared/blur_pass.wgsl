// One pass of a separable blur (import-only module of `blur` and `blur_log`): parameters,
// bindings, and the line an invocation filters. Each invocation writes PER texels of a row or
// `col_per` of a column, in runs of consecutive texels (`blur_line`), reading its taps straight
// from the texture: no workgroup memory, so any radius up to MAX_RADIUS fits (and llvmpipe,
// where a workgroup-memory access costs several texture loads, runs it fast). Rows: a workgroup
// covers WG_SIZE · PER texels of one row; columns:
// WG_SIZE neighbouring columns, `col_per` rows each (the importing kernel's choice), so a
// workgroup's loads lie side by side and its halo of 2r rows is shared by `col_per` outputs. Edges
// clamp (replicate the border texel), so the map edge keeps its shadow instead of fading
// toward zero.
// REDESIGN (`exec::KernelLayout::Redesign`, not yet decided on a GPU): rows as the columns
// turned sideways: workgroup (x, y) covers rows y·WG_SIZE + li, `col_per` texels each from
// x·col_per, so that a SIMD group's lanes load neighbouring rows at one x (a column of a GPU's
// block-linear tiles, which the row pass's lanes PER texels apart touched a sector each) and
// an invocation slides its windows along its row for as many outputs as a column invocation.
// The same sums in the same order per output (runs of the importing kernel's length from a
// multiple of it): the same blur bit for bit (tests/blur_rows.rs).
// Storage: rg32float by default; the executor re-declares `dst` for the bound format.

// Keep in sync with `BlurParams` in src/filter.rs.
struct Params {
    axis: u32,                        // 0 horizontal, 1 vertical
    radius: u32,                      // taps each side, ≤ MAX_RADIUS
    mode: u32,                        // 0 weighted sum; 1 log Σ w exp(v) (the kernel decides)
    _pad: u32,
    weights: array<vec4<f32>, 9>,     // weight of offset i at weights[i / 4][i % 4], i = 0..=32
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;
@group(0) @binding(2) var<uniform> params: Params;

// Keep in sync with `BLUR_PER_INVOCATION` and `BLUR_GROUP` in src/filter.rs.
const PER: u32 = 8u;
const WG_SIZE: u32 = 64u;
const MAX_RADIUS: u32 = 32u;
// The rows' redesign (above); the Rust side dispatches its blocks (`filter::blur_dispatch`).
override REDESIGN: bool = false;

// The texels an invocation writes along line `line` of a map `along` texels long and `across`
// lines wide: `count` of them from `first`, in runs of consecutive texels `step` apart (the
// importing kernel's run length); `r` taps each side. Offsets passed to `tap` and `put` are
// relative to `first`.
struct BlurLine {
    first: i32,
    step: i32,
    line: u32,
    along: i32,
    across: u32,
    r: i32,
    // Outputs the invocation writes: PER along a row, `col_per` down a column (and along a
    // row in the REDESIGN).
    count: i32,
}

// Rows: workgroup (x, y) covers texels [x·WG_SIZE·PER, (x + 1)·WG_SIZE·PER) of row y in runs of
// `run` consecutive texels: invocation li's start at li·run and follow every WG_SIZE·run, so
// that neighbouring invocations' runs lie side by side (run = PER: the PER consecutive texels
// from li·PER, for a kernel that slides one window along them). Columns: workgroup (x, y)
// covers columns x·WG_SIZE + li, rows [y·col_per, (y + 1)·col_per), runs one after another:
// neighbouring invocations are neighbouring columns either way. REDESIGN rows: the columns'
// blocks transposed, workgroup (x, y) on rows y·WG_SIZE + li from x·col_per.
fn blur_line(wg: vec2<u32>, li: u32, run: u32, col_per: u32) -> BlurLine {
    let size = textureDimensions(src);
    var b: BlurLine;
    b.r = i32(min(params.radius, MAX_RADIUS));
    b.count = i32(select(PER, col_per, params.axis == 1u || REDESIGN));
    if params.axis == 1u {
        b.first = i32(wg.y * col_per);
        b.step = i32(run);
        b.line = wg.x * WG_SIZE + li;
        b.along = i32(size.y);
        b.across = size.x;
    } else if REDESIGN {
        b.first = i32(wg.x * col_per);
        b.step = i32(run);
        b.line = wg.y * WG_SIZE + li;
        b.along = i32(size.x);
        b.across = size.y;
    } else {
        b.first = i32(wg.x * WG_SIZE * PER + li * run);
        b.step = i32(WG_SIZE * run);
        b.line = wg.y;
        b.along = i32(size.x);
        b.across = size.y;
    }
    return b;
}

// Whether the invocation has any texel to write.
fn blur_active(b: BlurLine) -> bool {
    return b.line < b.across && b.first < b.along;
}

// The weight of offset d (0 past the radius r ≤ MAX_RADIUS).
fn weight(d: i32, r: i32) -> f32 {
    let i = u32(min(abs(d), r));
    return select(0.0, params.weights[i / 4u][i % 4u], abs(d) <= r);
}

// Texel `first + t` along the line, clamped to the map. `vertical` is the pass's axis
// (params.axis == 1), which every kernel passes as a constant: it tests the axis once and
// calls its loop twice, with `true` and with `false` (see `blur.wgsl`), so that no tap tests
// the axis at run time. llvmpipe did not hoist that uniform test out of the tap loops: the
// blur at r = 4 ran 1.6× faster by the wall clock with it gone (2.1× at r = 32).
fn tap(b: BlurLine, t: i32, vertical: bool) -> vec4<f32> {
    let c = u32(clamp(b.first + t, 0, b.along - 1));
    if vertical {
        return textureLoad(src, vec2<u32>(b.line, c), 0);
    }
    return textureLoad(src, vec2<u32>(c, b.line), 0);
}

// Writes v as output k of the invocation (if inside the map); `vertical` as for `tap`.
fn put(b: BlurLine, k: i32, v: vec4<f32>, vertical: bool) {
    let a = b.first + k;
    if a >= b.along {
        return;
    }
    if vertical {
        textureStore(dst, vec2<u32>(b.line, u32(a)), v);
    } else {
        textureStore(dst, vec2<u32>(u32(a), b.line), v);
    }
}
