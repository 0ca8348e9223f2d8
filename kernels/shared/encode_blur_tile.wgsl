// The GPU layout's tile blur (import-only module of shared/encode_blur, GPU_LAYOUT true): with
// the tile and its halo encoded into workgroup memory (`encode_tile`), WG_SIZE invocations blur
// it along x into workgroup memory, then along y into `dst`, in runs of RUN outputs an
// invocation (`blur_tile_runs`) or one output at a time (`blur_tile_single`); `sum_x` is also
// the row path's sum of one output.
// #completed-by-importer

// Runs (RUN = 4): an invocation sums RUN consecutive outputs along a line of the tile (a row,
// then a column): each of the RUN + 2r texels the run covers is read once from workgroup memory
// into RUN running sums, RUN + 2r reads for RUN outputs where one output at a time reads 2r + 1
// (3 against 9 an output at r = 4). The tile's side is a multiple of RUN and its runs fit one
// an invocation: (TILE / RUN) · (TILE + 2·TILE_RADIUS) ≤ WG_SIZE (228 at TILE = 24).
// Which kernels run them, measured (benches/RESULTS.md, 2026-11-27): the two-channel tile (24²)
// keeps 144 of 256 invocations busy in its vertical pass and ran 6% faster on an H200 (1.29–
// 1.33× on llvmpipe); a four-channel tile (16²) keeps 64 busy and ran 17–20% slower on the H200
// (1.07–1.12× faster on llvmpipe), and so does the row path (ROW / RUN = 64 of 256: 12% slower
// there, 1.13–1.19× faster on llvmpipe). The GPU decides: four channels and the row path sum one
// output an invocation (`blur_tile_single`, `sum_x`). RUN is a constant, so each kernel
// compiles one of the two.

// The weight of offset d, 0 past the radius r.
fn run_weight(d: i32, r: i32) -> f32 {
    return select(0.0, blur_weight(min(abs(d), r)), abs(d) <= r);
}

// The RUN sums of a run: texel `first + k·step` of workgroup memory is output k's centre, its
// taps at `first + (k + i)·step`, |i| ≤ r. Tap j of the loop, at offset j − r from output 0's
// centre, carries weight w(j − r − k) in output k: a shift register of RUN weights.
struct Run {
    s0: Texel,
    s1: Texel,
    s2: Texel,
    s3: Texel,
}

fn run_sums(first: i32, step: i32, r: i32) -> Run {
    var o: Run;
    o.s0 = Texel(0.0);
    o.s1 = Texel(0.0);
    o.s2 = Texel(0.0);
    o.s3 = Texel(0.0);
    var w0 = run_weight(-r, r);
    var w1 = run_weight(-r - 1, r);
    var w2 = run_weight(-r - 2, r);
    var w3 = run_weight(-r - 3, r);
    for (var j = 0; j < i32(RUN) + 2 * r; j++) {
        let v = sh_get(first + (j - r) * step);
        o.s0 += w0 * v;
        o.s1 += w1 * v;
        o.s2 += w2 * v;
        o.s3 += w3 * v;
        w3 = w2;
        w2 = w1;
        w1 = w0;
        w0 = run_weight(j + 1 - r, r);
    }
    return o;
}

// Phases 2 and 3 in runs (RUN = 4): along x into workgroup memory (outs.x × enc.y sums, a run an
// invocation), then along y into `dst` (outs.x × outs.y outputs, a run down a column an
// invocation). Invocations past the last run idle through the barriers.
fn blur_tile_runs(t: Tile, li: u32) {
    let i = i32(li);
    let runs_x = t.outs.x / i32(RUN);
    let rx = div_mod(i, runs_x);
    let row = rx.x;
    let x0 = rx.y * i32(RUN);
    let along_x = row < t.enc.y;
    var h: Run;
    if along_x {
        h = run_sums(row * t.enc.x + x0 + t.r.x, 1, t.r.x);
    }
    workgroupBarrier();
    if along_x {
        let c = row * t.outs.x + x0;
        sh_tile[c] = h.s0;
        sh_tile[c + 1] = h.s1;
        sh_tile[c + 2] = h.s2;
        sh_tile[c + 3] = h.s3;
    }
    workgroupBarrier();
    let runs_y = t.outs.y / i32(RUN);
    let yc = div_mod(i, t.outs.x);
    let col = yc.y;
    let y0 = yc.x * i32(RUN);
    if i < t.outs.x * runs_y {
        let v = run_sums((y0 + t.r.y) * t.outs.x + col, t.outs.x, t.r.y);
        store(t, vec2<i32>(col, y0), v.s0);
        store(t, vec2<i32>(col, y0 + 1), v.s1);
        store(t, vec2<i32>(col, y0 + 2), v.s2);
        store(t, vec2<i32>(col, y0 + 3), v.s3);
    }
}

// The horizontal sum at output column x of encoded row y, alone.
fn sum_x(t: Tile, x: i32, y: i32) -> Texel {
    let c = y * t.enc.x + x + t.r.x;
    var s = blur_weight(0) * sh_get(c);
    for (var i = 1; i <= t.r.x; i++) {
        s += blur_weight(i) * (sh_get(c - i) + sh_get(c + i));
    }
    return s;
}

// The vertical sum of output q of the tile, alone, stored.
fn sum_y(t: Tile, q: i32) {
    let o = div_mod(q, t.outs.x).yx;
    let c = (o.y + t.r.y) * t.outs.x + o.x;
    var v = blur_weight(0) * sh_get(c);
    for (var k = 1; k <= t.r.y; k++) {
        v += blur_weight(k) * (sh_get(c - k * t.outs.x) + sh_get(c + k * t.outs.x));
    }
    store(t, o, v);
}

// Phases 2 and 3 one output an invocation (RUN = 1): along x into workgroup memory (outs.x ×
// enc.y sums, in up to four blocks of WG_SIZE), then along y into `dst` (WG_SIZE at a time).
fn blur_tile_single(t: Tile, li: u32) {
    let n = t.outs.x * t.enc.y;
    let i = i32(li);
    let w = i32(WG_SIZE);
    let j1 = min(i + w, n - 1);
    let a0 = div_mod(i, t.outs.x);
    let a1 = div_mod(j1, t.outs.x);
    let h0 = sum_x(t, a0.y, a0.x);
    let h1 = sum_x(t, a1.y, a1.x);
    var h2 = h1;
    var h3 = h1;
    if H_MAX > 2u * WG_SIZE && 2 * w < n {
        let j2 = min(i + 2 * w, n - 1);
        let j3 = min(i + 3 * w, n - 1);
        let a2 = div_mod(j2, t.outs.x);
        let a3 = div_mod(j3, t.outs.x);
        h2 = sum_x(t, a2.y, a2.x);
        h3 = sum_x(t, a3.y, a3.x);
    }
    workgroupBarrier();
    put_below(i, n, h0);
    put_below(i + w, n, h1);
    if H_MAX > 2u * WG_SIZE && 2 * w < n {
        put_below(i + 2 * w, n, h2);
        put_below(i + 3 * w, n, h3);
    }
    workgroupBarrier();
    sum_y(t, i);
    if TILE * TILE > WG_SIZE {
        for (var q = i + w; q < t.outs.x * t.outs.y; q += w) {
            sum_y(t, q);
        }
    }
}
