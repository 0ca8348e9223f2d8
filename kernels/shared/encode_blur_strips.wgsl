// A CPU driver's tile blur (import-only module of shared/encode_blur, GPU_LAYOUT false):
// CPU_LANES invocations walk the tile in strips (`blur_tile_strips`), each encoded row along x
// into horizontal sums in workgroup memory, then each column of those sums down into `dst`.
// The redesign's columns (shared/encode_blur_columns) slide the same `Window`.
// #completed-by-importer

// The CPU layout's tile (GPU_LAYOUT false): strips. A window of the 2·STRIP_RADIUS + 1 latest
// texels of a line, centre a7 (a3 … a11, or a0 … a14): the sum of output k, whose centre is
// a7, is w₀·a7 + Σᵢ wᵢ·(a(7−i) + a(7+i)), i = 1 … STRIP_RADIUS, the centre and then the
// symmetric pairs as `sum_x`'s, with wᵢ = 0 past the radius (exact zeros added to the finite
// sum; every texel the window holds is an encoding or a horizontal sum of the map, or 0).
// Named values, not an array (llvmpipe kept arrays indexed in a loop in memory: see `blur`'s
// runs).
//
// STRIP_RADIUS is a constant of each pipeline, set from the node's radius
// (`exec::KernelCache::node_constants`): 4 up to radius 4, else TILE_RADIUS. A window of 9
// texels in place of 15 took the MSM strips 1.27× less CPU time on llvmpipe, VSM's 1.05–1.1×
// (benches/RESULTS.md, 2026-11-28); as a run-time test llvmpipe would run both.
// #override STRIP_RADIUS: select(TILE_RADIUS, 4, params.blur.radius <= 4)
override STRIP_RADIUS: u32 = TILE_RADIUS;
// The window's outer pairs (a0 … a2, a12 … a14): only where STRIP_RADIUS is TILE_RADIUS.
override STRIP_WIDE: bool = STRIP_RADIUS > 4u;

struct Window {
    a0: Texel,
    a1: Texel,
    a2: Texel,
    a3: Texel,
    a4: Texel,
    a5: Texel,
    a6: Texel,
    a7: Texel,
    a8: Texel,
    a9: Texel,
    a10: Texel,
    a11: Texel,
    a12: Texel,
    a13: Texel,
    a14: Texel,
}

// The window's pairs are TILE_RADIUS's, and the horizontal sums of a tile at TILE_RADIUS fit
// workgroup memory.
const_assert TILE_RADIUS == 7u;
const_assert TILE * (TILE + 2u * TILE_RADIUS) <= SH_TEXELS;
const_assert TILE * (CPU_TILE_ROWS + 2u * TILE_RADIUS) <= SH_TEXELS;
// Rows walked in pairs: the strips' encoded rows, CPU_TILE_ROWS + 2r, pair up.
const_assert WALK_ROWS == 1u || (WALK_ROWS == 2u && CPU_TILE_ROWS % 2u == 0u);

fn empty_window() -> Window {
    let z = Texel(0.0);
    return Window(z, z, z, z, z, z, z, z, z, z, z, z, z, z, z);
}

// The window moved on by one texel, v.
fn window_push(w: ptr<function, Window>, v: Texel) {
    if STRIP_WIDE {
        (*w).a0 = (*w).a1;
        (*w).a1 = (*w).a2;
        (*w).a2 = (*w).a3;
    }
    (*w).a3 = (*w).a4;
    (*w).a4 = (*w).a5;
    (*w).a5 = (*w).a6;
    (*w).a6 = (*w).a7;
    (*w).a7 = (*w).a8;
    (*w).a8 = (*w).a9;
    (*w).a9 = (*w).a10;
    (*w).a10 = (*w).a11;
    if STRIP_WIDE {
        (*w).a11 = (*w).a12;
        (*w).a12 = (*w).a13;
        (*w).a13 = (*w).a14;
        (*w).a14 = v;
    } else {
        (*w).a11 = v;
    }
}

// The weights of offsets 0 … 7, 0 past radius r.
struct PairWeights {
    w0: f32,
    w1: f32,
    w2: f32,
    w3: f32,
    w4: f32,
    w5: f32,
    w6: f32,
    w7: f32,
}

fn pair_weights(r: i32) -> PairWeights {
    return PairWeights(
        run_weight(0, r),
        run_weight(1, r),
        run_weight(2, r),
        run_weight(3, r),
        run_weight(4, r),
        run_weight(5, r),
        run_weight(6, r),
        run_weight(7, r)
    );
}

// The output whose centre is the window's a7.
fn window_sum(w: Window, k: PairWeights) -> Texel {
    var s = k.w0 * w.a7;
    s += k.w1 * (w.a6 + w.a8);
    s += k.w2 * (w.a5 + w.a9);
    s += k.w3 * (w.a4 + w.a10);
    s += k.w4 * (w.a3 + w.a11);
    if STRIP_WIDE {
        s += k.w5 * (w.a2 + w.a12);
        s += k.w6 * (w.a1 + w.a13);
        s += k.w7 * (w.a0 + w.a14);
    }
    return s;
}

// A walk along WALK_ROWS encoded rows, y (and y + 1): the position reached in row y, the linear
// depths before it and the raw depths at it (row y's, then row y + 1's), and the non-finite
// depths of the tile's own outputs met so far. Counted in a register, added to `stats` once an
// invocation (`strip_rows`): an atomic in the walk's step, under a mask, took 7% of the strips'
// instructions on llvmpipe (benches/RESULTS.md, 2026-11-28).
struct Walk {
    p: vec2<i32>,
    before0: f32,
    before1: f32,
    raw0: f32,
    raw1: f32,
    bad: u32,
}

fn walk_start(t: Tile, p: vec2<i32>) -> Walk {
    let q = p + vec2<i32>(0, 1);
    return Walk(
        p,
        depth_direct(t, p - vec2<i32>(1, 0)),
        depth_direct(t, q - vec2<i32>(1, 0)),
        raw_depth(t, p),
        raw_depth(t, q),
        0u
    );
}

// 1 where map texel p is an output of the tile with a non-finite depth (`encode_at`'s count).
fn bad_at(t: Tile, p: vec2<i32>, raw: f32) -> u32 {
    return u32(owns(t, p) && !depth_is_finite(raw));
}

// The encodings at the walk's position in its rows (e1: row y + 1's, where WALK_ROWS is 2).
struct Encoded {
    e0: Texel,
    e1: Texel,
}

// The encodings at the walk's position, the walk moved on by one texel. One row: three depth
// loads (the next texel along the row, and above and below). Two rows: four (the next texel
// along each, above the first and below the second), as each row's texel is the other's
// neighbour below or above; both read their depths at clamped coordinates, so a row's
// neighbour is the other row's texel at the map's edges too.
fn walk_step(t: Tile, w: ptr<function, Walk>) -> Encoded {
    let p = (*w).p;
    let q = p + vec2<i32>(0, 1);
    let dx = vec2<i32>(1, 0);
    let raw0 = (*w).raw0;
    (*w).bad += bad_at(t, p, raw0);
    let z0 = linear_depth(raw0, t.depth);
    let next0 = raw_depth(t, p + dx);
    let up0 = depth_direct(t, p - vec2<i32>(0, 1));
    var e: Encoded;
    // A constant condition: each kernel compiles one of the two.
    if WALK_ROWS == 2u {
        let raw1 = (*w).raw1;
        (*w).bad += bad_at(t, q, raw1);
        let z1 = linear_depth(raw1, t.depth);
        let next1 = raw_depth(t, q + dx);
        e.e0 = texel_of(encode(
            z0,
            (*w).before0,
            linear_depth(next0, t.depth),
            up0,
            z1,
            t.coding
        ));
        e.e1 = texel_of(encode(
            z1,
            (*w).before1,
            linear_depth(next1, t.depth),
            z0,
            depth_direct(t, q + vec2<i32>(0, 1)),
            t.coding
        ));
        (*w).before1 = z1;
        (*w).raw1 = next1;
    } else {
        e.e0 = texel_of(encode(
            z0,
            (*w).before0,
            linear_depth(next0, t.depth),
            up0,
            depth_direct(t, q),
            t.coding
        ));
    }
    (*w).p = p + dx;
    (*w).before0 = z0;
    (*w).raw0 = next0;
    return e;
}

// The walk's texels pushed into the windows of its rows.
fn push_rows(w0: ptr<function, Window>, w1: ptr<function, Window>, e: Encoded) {
    window_push(w0, e.e0);
    if WALK_ROWS == 2u {
        window_push(w1, e.e1);
    }
}

// The rows' sums stored at i in workgroup memory (row y + 1's at i + outs.x).
fn store_rows(t: Tile, i: i32, w0: Window, w1: Window, k: PairWeights) {
    sh_tile[i] = window_sum(w0, k);
    if WALK_ROWS == 2u {
        sh_tile[i + t.outs.x] = window_sum(w1, k);
    }
}

// Strips along x: invocation li walks encoded rows WALK_ROWS at a time, rows WALK_ROWS·li,
// WALK_ROWS·(li + LANES), … (enc.y rows: the tile's with its halo) from the halo's left end,
// and stores each row's outs.x horizontal sums in workgroup memory (row-major, outs.x a row).
// With R = STRIP_RADIUS, output k's sum is complete when the walk has pushed texel k + r + R:
// the window's a7 is then texel k + r, its centre. Three loops, so that no step tests which
// part of the walk it is in (llvmpipe would run both sides): the first r + R texels fill the
// window, the rest of the row sums as it goes, and R − r zeros finish the last outputs past the
// row's end.
fn strip_rows(t: Tile, li: u32, k: PairWeights) {
    let r = t.r.x;
    let rr = i32(STRIP_RADIUS);
    let rows = i32(WALK_ROWS);
    var bad = 0u;
    for (var row = rows * i32(li); row < t.enc.y; row += rows * i32(LANES)) {
        var walk = walk_start(t, t.origin - t.r + vec2<i32>(0, row));
        var win0 = empty_window();
        var win1 = empty_window();
        var j = 0;
        for (; j < r + rr; j++) {
            push_rows(&win0, &win1, walk_step(t, &walk));
        }
        let at = row * t.outs.x - r - rr;
        for (; j < t.enc.x; j++) {
            push_rows(&win0, &win1, walk_step(t, &walk));
            store_rows(t, at + j, win0, win1, k);
        }
        let zeros = Encoded(Texel(0.0), Texel(0.0));
        for (; j < t.enc.x + rr - r; j++) {
            push_rows(&win0, &win1, zeros);
            store_rows(t, at + j, win0, win1, k);
        }
        bad += walk.bad;
    }
    if bad > 0u {
        atomicAdd(&stats[0], bad);
    }
}

// Strips along y: invocation li walks columns li, li + LANES, … of the horizontal sums down,
// in `strip_rows`' three loops, and stores each output.
fn strip_columns(t: Tile, li: u32, k: PairWeights) {
    let r = t.r.y;
    let rr = i32(STRIP_RADIUS);
    for (var c = i32(li); c < t.outs.x; c += i32(LANES)) {
        var win = empty_window();
        var j = 0;
        for (; j < r + rr; j++) {
            window_push(&win, sh_get(j * t.outs.x + c));
        }
        for (; j < t.enc.y; j++) {
            window_push(&win, sh_get(j * t.outs.x + c));
            store(t, vec2<i32>(c, j - r - rr), window_sum(win, k));
        }
        for (; j < t.enc.y + rr - r; j++) {
            window_push(&win, Texel(0.0));
            store(t, vec2<i32>(c, j - r - rr), window_sum(win, k));
        }
    }
}

// The tile in strips (the CPU layout): along x into workgroup memory (outs.x × enc.y sums),
// one barrier, then along y into `dst`. Each pass reads its own weights: llvmpipe keeps what
// lives across a barrier in its coroutine's frame, and the weights held across it took 10% of
// the VSM strips' instructions (benches/instructions.sh; benches/RESULTS.md, 2026-11-28).
fn blur_tile_strips(t: Tile, li: u32) {
    strip_rows(t, li, pair_weights(t.r.x));
    workgroupBarrier();
    strip_columns(t, li, pair_weights(t.r.y));
}
