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
    // Outputs the invocation writes: PER along a row, `col_per` down a column.
    count: i32,
    // Rows: where texel `first` lies in the workgroup's staged row (`sh_row`, before padding).
    local: i32,
}

// Rows: workgroup (x, y) covers texels [x·WG_SIZE·PER, (x + 1)·WG_SIZE·PER) of row y in runs of
// `run` consecutive texels: invocation li's start at li·run and follow every WG_SIZE·run, so
// that neighbouring invocations' runs lie side by side (run = PER: the PER consecutive texels
// from li·PER, for a kernel that slides one window along them). Columns: workgroup (x, y)
// covers columns x·WG_SIZE + li, rows [y·col_per, (y + 1)·col_per), runs one after another:
// neighbouring invocations are neighbouring columns either way.
fn blur_line(wg: vec2<u32>, li: u32, run: u32, col_per: u32) -> BlurLine {
    let size = textureDimensions(src);
    var b: BlurLine;
    b.r = i32(min(params.radius, MAX_RADIUS));
    b.count = i32(select(PER, col_per, params.axis == 1u));
    if params.axis == 1u {
        b.first = i32(wg.y * col_per);
        b.step = i32(run);
        b.line = wg.x * WG_SIZE + li;
        b.along = i32(size.y);
        b.across = size.x;
    } else {
        b.first = i32(wg.x * WG_SIZE * PER + li * run);
        b.local = i32(li * run) + b.r;
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
    if !vertical && GPU_LAYOUT {
        return sh_row[row_slot(u32(b.local + t))];
    }
    let c = u32(clamp(b.first + t, 0, b.along - 1));
    if vertical {
        return textureLoad(src, vec2<u32>(b.line, c), 0);
    }
    return textureLoad(src, vec2<u32>(c, b.line), 0);
}

// Writes v as output k of the invocation (if inside the map); under GPU_LAYOUT a row's output
// goes to `row_out` (k a constant after inlining: registers), which `row_unstage` writes.
// `vertical` as for `tap`.
fn put(b: BlurLine, k: i32, v: vec4<f32>, vertical: bool) {
    if !vertical && GPU_LAYOUT {
        row_out[k] = v;
        return;
    }
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

// The memory layout of the row pass, a pipeline constant the executor sets by device
// (`exec::KernelLayout`: true on a GPU). Under it rows are staged through workgroup memory
// (below); without it each invocation reads its run's taps straight from the texture and
// writes its outputs there, as llvmpipe runs fastest: its SIMD lanes gather texel by texel
// anyway, and staging made the horizontal pass 1.2–2.5× slower there (benches/RESULTS.md,
// 2026-11-27, twelfth session). A constant at pipeline creation: each layout compiles alone.
override GPU_LAYOUT: bool = false;

// GPU_LAYOUT: rows are staged through workgroup memory: the workgroup's WG_SIZE · PER texels and the halo
// of r each side are loaded once, neighbouring invocations on neighbouring texels
// (`row_stage`); each invocation sums its run of PER outputs from there as before, keeps them
// in `row_out`, and the workgroup writes them back through the same memory, neighbouring
// invocations on neighbouring texels again (`row_unstage`). Straight from the texture, one
// load or store instruction of a SIMD group touched texels PER apart, a sector each: on the
// H200 the horizontal pass took 3–5× the vertical one, whose neighbouring invocations are
// neighbouring columns (benches/RESULTS.md, 2026-11-27, twelfth session). The sums, their
// order and the edge clamping are unchanged: results bit for bit as before.
// One slot of padding every 8 texels: invocation li's run starts at slot 9·li + …, so the
// eight lanes that a 16-byte access serves at a time (a quarter of a 32-lane SIMD group)
// reading their runs' texels hit distinct banks.
const ROW_STAGE: u32 = WG_SIZE * PER + 2u * MAX_RADIUS;
var<workgroup> sh_row: array<vec4<f32>, ROW_STAGE + ROW_STAGE / 8u>;
var<private> row_out: array<vec4<f32>, PER>;

fn row_slot(j: u32) -> u32 {
    return j + (j >> 3u);
}

// Loads row wg.y's texels [x₀ − r, x₀ + WG_SIZE · PER + r), x₀ = wg.x · WG_SIZE · PER, clamped
// to the map, into `sh_row`. Every invocation of the workgroup calls it (it has a barrier).
fn row_stage(wg: vec2<u32>, li: u32) {
    let size = textureDimensions(src);
    let r = i32(min(params.radius, MAX_RADIUS));
    let x0 = i32(wg.x * WG_SIZE * PER) - r;
    let count = WG_SIZE * PER + 2u * u32(r);
    for (var j = li; j < count; j += WG_SIZE) {
        let x = clamp(x0 + i32(j), 0, i32(size.x) - 1);
        sh_row[row_slot(j)] = textureLoad(src, vec2<u32>(u32(x), min(wg.y, size.y - 1u)), 0);
    }
    workgroupBarrier();
}

// Writes every invocation's `row_out` to row wg.y of `dst` (inside the map). Every invocation
// of the workgroup calls it (it has barriers), after its run.
fn row_unstage(wg: vec2<u32>, li: u32) {
    let size = textureDimensions(src);
    workgroupBarrier();
    for (var k = 0u; k < PER; k++) {
        sh_row[row_slot(li * PER + k)] = row_out[k];
    }
    workgroupBarrier();
    let x0 = wg.x * WG_SIZE * PER;
    for (var j = li; j < WG_SIZE * PER; j += WG_SIZE) {
        if x0 + j < size.x && wg.y < size.y {
            textureStore(dst, vec2<u32>(x0 + j, wg.y), sh_row[row_slot(j)]);
        }
    }
}
