// Encode and blur fused (import-only module of `vsm_blur`, `evsm_blur`, `msm_blur`): a workgroup
// reads its tile of the rasterized depth once, with a halo of r + 1 texels (the blur's r and one
// more for an encoding that differentiates the depth), linearizes it into workgroup memory,
// encodes every texel of the tile and halo once (the importing kernel's `encode`), runs the
// separable blur along x and then y in workgroup memory, and writes the filtered moments once
// (Peters, HPG 2017: resolve, two Gaussian passes in shared memory, one write).
//
// `params.blur.axis` picks the shape:
//   2: a TILE × TILE tile blurred along both axes (radius ≤ TILE_RADIUS; the tile and its halo of
//      encoded texels fill workgroup memory at TILE_RADIUS with four channels);
//   0: ROW texels of one row blurred along x only (radius ≤ MAX_RADIUS): the fallback for larger
//      radii, followed by `blur`'s vertical pass.
// The sums are those of `blur` (the centre, then the symmetric pairs w₀·v₀ + Σ wᵢ·(v₋ᵢ + vᵢ),
// along x then y), with clamp-to-edge: a halo texel outside the map is the encoding of the border
// texel. Reading the depth at clamped coordinates gives exactly that for `vsm`'s derivatives too:
// a clamped texel's outward difference is 0, as the border texel's is.
// Each workgroup counts the non-finite depths of its own outputs, so each is counted once.
//
// The importing kernel declares `const CHANNELS` (2 or 4), `struct Params` (its encoding's
// fields, then `blur: BlurSpec`), `fn encode(z, left, right, up, down) -> vec4<f32>`, and the
// texel its channels need in workgroup memory: `alias Texel` (vec2<f32> for two channels,
// vec4<f32> for four), `fn texel_of(v: vec4<f32>) -> Texel` and `fn texel_out(t: Texel) ->
// vec4<f32>` (two channels in vec2s halve the workgroup memory and its traffic):
// #completed-by-importer
// Storage: rg32float by default; the executor re-declares `dst` for the bound format.

// #import shared/linear_depth

// Keep in sync with `BlurParams` in src/filter.rs (the same bytes; `axis` 2 means both).
struct BlurSpec {
    axis: u32,                    // 2: both axes in one tile; 0: along x only
    radius: u32,                  // taps each side
    mode: u32,                    // 0 (weighted sum): the only mode fused
    _pad: u32,
    weights: array<vec4<f32>, 9>, // weight of offset i at weights[i / 4][i % 4], i = 0..=32
}

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rg32float, write>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

// Keep in sync with `ENCODE_BLUR_*` in src/filter.rs.
const WG_SIZE: u32 = 256u;
const TILE: u32 = 16u;
const ROW: u32 = 256u;
const TILE_RADIUS: u32 = 7u;
const MAX_RADIUS: u32 = 32u;
// Encoded texels an invocation holds between barriers (`encode_tile`: e0 … e3): at least
// ⌈(TILE + 2·TILE_RADIUS)² / WG_SIZE⌉ of a tile and ⌈(ROW + 2·MAX_RADIUS) / WG_SIZE⌉ of a row.
// Horizontal sums (`blur_tile`: h0, h1): at least ⌈TILE · (TILE + 2·TILE_RADIUS) / WG_SIZE⌉.
// Texels of workgroup memory, a `Texel` each (one access a tap): the depth
// tile ((TILE + 2·TILE_RADIUS + 2)² = 1024, or three rows of ROW + 2·MAX_RADIUS + 2), the
// encoded tile ((TILE + 2·TILE_RADIUS)² = 900, or ROW + 2·MAX_RADIUS) and the horizontal sums
// each fit: 16 KiB with four channels, 8 KiB with two.
const SH_TEXELS: u32 = 1024u;

// The depth tile (in x), then the encoded tile, then the horizontal sums, each over the one
// before.
var<workgroup> sh_tile: array<Texel, SH_TEXELS>;

// A workgroup's outputs and the extents it works over.
struct Tile {
    origin: vec2<i32>, // the first output texel
    outs: vec2<i32>,   // outputs along x and y
    r: vec2<i32>,      // blur radius along x and y (0 along y for a row)
    enc: vec2<i32>,    // encoded extent: outs + 2r
    dep: vec2<i32>,    // depth extent: enc + 2 (the encoding's neighbours)
    size: vec2<i32>,   // the map
}

fn tile_of(wg: vec2<u32>) -> Tile {
    var t: Tile;
    t.size = vec2<i32>(textureDimensions(src));
    if params.blur.axis == 2u {
        let r = i32(min(params.blur.radius, TILE_RADIUS));
        t.origin = vec2<i32>(wg * TILE);
        t.outs = vec2<i32>(i32(TILE));
        t.r = vec2<i32>(r);
    } else {
        t.origin = vec2<i32>(i32(wg.x * ROW), i32(wg.y));
        t.outs = vec2<i32>(i32(ROW), 1);
        t.r = vec2<i32>(i32(min(params.blur.radius, MAX_RADIUS)), 0);
    }
    t.enc = t.outs + 2 * t.r;
    t.dep = t.enc + 2;
    return t;
}

// The weight of offset i ≤ radius.
fn blur_weight(i: i32) -> f32 {
    return params.blur.weights[u32(i) / 4u][u32(i) % 4u];
}

fn sh_get(i: i32) -> Texel {
    return sh_tile[i];
}

// The linear depth at depth-tile index i.
fn sh_depth(i: i32) -> f32 {
    return sh_tile[i].x;
}

// Phase 1: the linear depth of the tile, its halo and one texel more, at clamped coordinates.
fn load_depth(t: Tile, li: u32) {
    let n = t.dep.x * t.dep.y;
    for (var i = i32(li); i < n; i += i32(WG_SIZE)) {
        let p = t.origin - t.r - 1 + vec2<i32>(i % t.dep.x, i / t.dep.x);
        let q = clamp(p, vec2<i32>(0), t.size - 1);
        let raw = textureLoad(src, q, 0).r;
        sh_tile[i] = texel_of(vec4<f32>(linear_depth(raw, params.depth), 0.0, 0.0, 0.0));
        let own = all(p == q) && all(p >= t.origin) && all(p < t.origin + t.outs);
        if own && !depth_is_finite(raw) {
            atomicAdd(&stats[0], 1u);
        }
    }
}

// The encoding of encoded-tile texel i (clamped to the tile: an invocation past its end computes
// a texel it does not store, so none branches).
fn encode_at(t: Tile, i: i32) -> Texel {
    let e = min(i, t.enc.x * t.enc.y - 1);
    let d = (e / t.enc.x + 1) * t.dep.x + e % t.enc.x + 1;
    return texel_of(encode(
        sh_depth(d),
        sh_depth(d - 1),
        sh_depth(d + 1),
        sh_depth(d - t.dep.x),
        sh_depth(d + t.dep.x)
    ));
}

// Stores v at i if i < n.
fn put_below(i: i32, n: i32, v: Texel) {
    if i < n {
        sh_tile[i] = v;
    }
}

// Phase 2: every texel of the tile and its blur halo encoded once, over the depth. The
// ENC_PER values an invocation holds are named, not an array: llvmpipe keeps an array indexed
// in a loop in memory.
fn encode_tile(t: Tile, li: u32) {
    let n = t.enc.x * t.enc.y;
    let i = i32(li);
    let s = i32(WG_SIZE);
    let e0 = encode_at(t, i);
    let e1 = encode_at(t, i + s);
    let e2 = encode_at(t, i + 2 * s);
    let e3 = encode_at(t, i + 3 * s);
    workgroupBarrier();
    put_below(i, n, e0);
    put_below(i + s, n, e1);
    put_below(i + 2 * s, n, e2);
    put_below(i + 3 * s, n, e3);
    workgroupBarrier();
}

// The horizontal sum at output column x of encoded row y.
fn sum_x(t: Tile, x: i32, y: i32) -> Texel {
    let c = y * t.enc.x + x + t.r.x;
    var s = blur_weight(0) * sh_get(c);
    for (var i = 1; i <= t.r.x; i++) {
        s += blur_weight(i) * (sh_get(c - i) + sh_get(c + i));
    }
    return s;
}

fn store(t: Tile, o: vec2<i32>, v: Texel) {
    let p = t.origin + o;
    if all(p < t.size) {
        textureStore(dst, p, texel_out(v));
    }
}

// Phases 3 and 4: along x into workgroup memory (outs.x × enc.y sums, H_PER an invocation),
// then along y into `dst`.
fn blur_tile(t: Tile, li: u32) {
    let n = t.outs.x * t.enc.y;
    let i = i32(li);
    let j = min(i + i32(WG_SIZE), n - 1);
    let h0 = sum_x(t, i % t.outs.x, i / t.outs.x);
    let h1 = sum_x(t, j % t.outs.x, j / t.outs.x);
    workgroupBarrier();
    put_below(i, n, h0);
    put_below(i + i32(WG_SIZE), n, h1);
    workgroupBarrier();
    let o = vec2<i32>(i % t.outs.x, i / t.outs.x);
    let c = (o.y + t.r.y) * t.outs.x + o.x;
    var s = blur_weight(0) * sh_get(c);
    for (var k = 1; k <= t.r.y; k++) {
        s += blur_weight(k) * (sh_get(c - k * t.outs.x) + sh_get(c + k * t.outs.x));
    }
    store(t, o, s);
}

// The importing kernel's `main`: workgroup `wg`, invocation `li`.
fn encode_blur(wg: vec2<u32>, li: u32) {
    let t = tile_of(wg);
    load_depth(t, li);
    workgroupBarrier();
    encode_tile(t, li);
    if params.blur.axis == 2u {
        blur_tile(t, li);
    } else {
        store(t, vec2<i32>(i32(li), 0), sum_x(t, i32(li), 0));
    }
}
