// The redesign layout's two-axis blur (import-only module of shared/encode_blur): columns walked
// down a strip (`exec::KernelLayout::Redesign`: GPU_LAYOUT and REDESIGN true; the GPU's and
// a CPU driver's layouts never compile it). FidelityFX Blur's shape (AMD FidelityFX SDK,
// `ffx_blur.h`: a workgroup walks its strip of the image top-down, each row blurred along x
// as it comes in and the vertical blur read from what the rows before left), with the encoding
// fused in front:
//   - each of the WG_SIZE lanes owns one map column, consecutive lanes consecutive columns
//     (a row's loads coalesce); COLUMN_OUTS of them are outputs, TILE_RADIUS columns each side
//     the horizontal pass's halo, and one more each side the depths VSM's encoding reads;
//   - a step takes the strip one row down: each lane loads one depth (a row ahead of the row it
//     encodes, so that the load's latency overlaps a step's work), encodes its texel of the row
//     once, and stores it in workgroup memory; one barrier; then it sums the row's 2r + 1
//     encoded texels around its column (`sum_x`'s order) and pushes the sum into its own
//     vertical window, the CPU strips' `Window` of the last 2·STRIP_RADIUS + 1 horizontal sums,
//     in registers; once the window holds an output's rows it stores that output;
//   - rows and depths alternate between two buffers of workgroup memory, so a step needs one
//     barrier (a row's buffer is written again two steps later, after the barrier between);
//   - a strip's workgroups stack COLUMN_ROWS output rows each along y, each walking its own
//     rows with a halo of r above and below, so that the map fills the GPU.
// Every depth is loaded once a strip (plus the halos), where the tile loaded 8.9 a texel, the
// lanes all busy but the 16 halo columns, in one barrier a row. The sums are the strips': the
// same values as `blur_tile_strips`' within rounding (the pairs past r add exact zeros).
// The clamp-to-edge halo is today's: each lane reads its depths at clamped coordinates, and
// reads its neighbours' depths from the lanes that loaded them at theirs.
// #completed-by-importer

// Output columns of a strip: the WG_SIZE lanes less TILE_RADIUS + 1 each side (240). Keep in
// sync with `ENCODE_BLUR_COLUMNS` in src/filter/encode_blur.rs.
const COLUMN_OUTS: u32 = WG_SIZE - 2u * TILE_RADIUS - 2u;
// Output rows of a workgroup of a strip (its halo, 2r rows, is walked on top). Keep in sync
// with `ENCODE_BLUR_COLUMN_ROWS` in src/filter/encode_blur.rs.
const COLUMN_ROWS: u32 = 64u;
// Workgroup memory (`sh_tile`, reused): two encoded rows of WG_SIZE texels, then, where the
// encoding reads its neighbours (`NEIGHBOURS`), two rows of WG_SIZE linear depths.
const COLUMN_DEPTHS: u32 = 2u * WG_SIZE;
const_assert COLUMN_DEPTHS + select(0u, 2u * WG_SIZE, NEIGHBOURS) <= SH_TEXELS;

// A lane's walk down its column: its map column, the linear depths of the rows above and at
// the row it encodes next, the raw depth of the row below (loaded a step ahead), and the
// non-finite depths of the strip's outputs it met.
struct Column {
    x: i32,
    up: f32,
    z: f32,
    raw_down: f32,
    bad: u32,
}

// The strip of workgroup `wg` (`tile_of`): COLUMN_OUTS × COLUMN_ROWS outputs, the last rows
// clipped to the map.
fn columns_tile(t: ptr<function, Tile>, wg: vec2<u32>) {
    (*t).origin = vec2<i32>(wg * vec2<u32>(COLUMN_OUTS, COLUMN_ROWS));
    (*t).outs = vec2<i32>(i32(COLUMN_OUTS), min(i32(COLUMN_ROWS), (*t).size.y - (*t).origin.y));
    (*t).r = vec2<i32>(i32(min(params.blur.radius, TILE_RADIUS)));
}

// Lane li's walk at the strip's first encoded row, r above its first output, whose depths
// (where the encoding reads its neighbours) are stored in buffer 0 before the first step.
fn column_start(t: Tile, li: i32) -> Column {
    let x = t.origin.x - i32(TILE_RADIUS) - 1 + li;
    let p = vec2<i32>(x, t.origin.y - t.r.y);
    let raw = raw_depth(t, p);
    let c = Column(
        x,
        depth_direct(t, p - vec2<i32>(0, 1)),
        linear_depth(raw, t.depth),
        raw_depth(t, p + vec2<i32>(0, 1)),
        bad_at(t, p, raw)
    );
    if NEIGHBOURS {
        sh_tile[COLUMN_DEPTHS + u32(li)] = Texel(c.z);
    }
    return c;
}

// Step j: the strip's encoded row j (map row origin.y − r + j) encoded into buffer j % 2, and
// the horizontal sum at the lane's column returned; the lane's walk moved one row down, and
// row j + 1's depths stored in the other buffer. Lanes outside the outputs sum at the nearest
// column that has its taps (and store nothing), so every lane runs the same code.
fn column_step(t: Tile, li: i32, c: ptr<function, Column>, j: i32) -> Texel {
    let w = i32(WG_SIZE);
    let here = (j & 1) * w;
    let y = t.origin.y - t.r.y + j;
    let raw_down = (*c).raw_down;
    (*c).bad += bad_at(t, vec2<i32>((*c).x, y + 1), raw_down);
    let down = linear_depth(raw_down, t.depth);
    (*c).raw_down = raw_depth(t, vec2<i32>((*c).x, y + 2));
    var left = (*c).z;
    var right = (*c).z;
    // A constant condition: each kernel compiles one of the two.
    if NEIGHBOURS {
        let depths = i32(COLUMN_DEPTHS);
        sh_tile[depths + w - here + li] = Texel(down);
        left = sh_tile[depths + here + max(li - 1, 0)].x;
        right = sh_tile[depths + here + min(li + 1, w - 1)].x;
    }
    sh_tile[here + li] = texel_of(encode((*c).z, left, right, (*c).up, down, t.coding));
    workgroupBarrier();
    let r = i32(TILE_RADIUS);
    let at = here + clamp(li, r, w - 1 - r);
    var s = blur_weight(0) * sh_tile[at];
    for (var i = 1; i <= t.r.x; i++) {
        s += blur_weight(i) * (sh_tile[at - i] + sh_tile[at + i]);
    }
    (*c).up = (*c).z;
    (*c).z = down;
    return s;
}

// Output row `row` of the strip at the lane's column, if it is one of the strip's outputs in
// the map.
fn column_store(t: Tile, c: Column, row: i32, v: Texel) {
    let p = vec2<i32>(c.x, t.origin.y + row);
    if owns(t, p) {
        textureStore(dst, p, texel_out(v));
    }
}

// The strip (the redesign layout's tile): enc.y steps, the window's output stored from step
// r + STRIP_RADIUS on (the window's a7 is then the output's centre row), then STRIP_RADIUS − r
// zeros pushed to finish the last outputs, as `strip_columns`' loops; the lane's non-finite
// depths added to `stats` once.
fn blur_columns(t: Tile, li: u32) {
    let k = pair_weights(t.r.y);
    let lead = t.r.y + i32(STRIP_RADIUS);
    var c = column_start(t, i32(li));
    if NEIGHBOURS {
        workgroupBarrier();
    }
    var win = empty_window();
    for (var j = 0; j < t.enc.y; j++) {
        window_push(&win, column_step(t, i32(li), &c, j));
        if j >= lead {
            column_store(t, c, j - lead, window_sum(win, k));
        }
    }
    for (var j = t.enc.y; j < t.enc.y + lead - 2 * t.r.y; j++) {
        window_push(&win, Texel(0.0));
        if j >= lead {
            column_store(t, c, j - lead, window_sum(win, k));
        }
    }
    if c.bad > 0u {
        atomicAdd(&stats[0], c.bad);
    }
}
