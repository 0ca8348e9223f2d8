// Tiles of the summed-area-table kernels (import-only module). A workgroup owns a TILE × TILE
// tile of the map; its GRID × GRID invocations each own a SUB × SUB sub-block, swept row by
// row with SUB running column sums in registers, so invocations meet in workgroup memory only
// through their sub-blocks' edge sums (O(SUB) values for SUB² texels). No function returns an
// array: llvmpipe copies such returns through memory, twenty times slower than the sweep.
// SUB = 4 (32² tiles) rather than 8 (64²): a GPU runs four times the invocations at once (a
// 2048² map as 65 536 invocations of 8² texels left an H100 latency bound), while llvmpipe,
// whose invocations are SIMD lanes over the same texels, does the same work. WG_SIZE = 2 · TILE:
// the per-line steps (a tile row or column each) guard `li < TILE`.
// #import shared/sat_params
// #import shared/csm_maps
// #import shared/linear_depth

// Whether pass 3's second sweep loads and encodes its texels again (true: a GPU, from its
// texture cache) or reads the first sweep's encoded texels kept in private memory (false: a CPU
// driver), a pipeline constant the executor sets by device (`exec::KernelLayout`; see
// `sat_enc` in shared/sat_tile_scan). Either way an invocation reads and writes its own SUB ×
// SUB sub-block straight from and to the texture: staging the tile through workgroup memory so
// that neighbouring lanes touch neighbouring texels made the tables 1.3–2.7× slower on an H200
// and 1.5–2.5× on llvmpipe (benches/RESULTS.md, 2026-11-27). The same sums in the same order either way: tables bit for bit the same
// (`tests/sat/layouts.rs` and `tests/csm_sat/tables.rs` compare both).
override GPU_LAYOUT: bool = false;

// Keep in sync with `SAT_TILE` in src/sat/mod.rs.
const SUB: u32 = 4u;
const GRID: u32 = 8u;
const TILE: u32 = 32u; // SUB · GRID
const WG_SIZE: u32 = 64u; // GRID · GRID

// a + b in the variant's arithmetic: wrapping u32, or f32 on the values' bits. The kernels of
// one variant pass `fs` as a constant, so the branch folds away (a uniform branch per add
// costs llvmpipe a quarter of the pass); it is a branch, not a select, so fixed point never
// adds its codes as floats, whose bit patterns may be denormals or NaNs.
fn sat_sum(a: vec4<u32>, b: vec4<u32>, fs: bool) -> vec4<u32> {
    if fs {
        return bitcast<vec4<u32>>(bitcast<vec4<f32>>(a) + bitcast<vec4<f32>>(b));
    }
    return a + b;
}

// The first texel of the sub-block that invocation `li` of tile `tile` owns (invocation li
// is sub-block column li % GRID, row li / GRID).
fn sat_sub_origin(tile: vec2<u32>, li: u32) -> vec2<u32> {
    return tile * TILE + vec2<u32>(li % GRID, li / GRID) * SUB;
}

// Where a tile pass's texels come from: the representation `src` holds (`SAT_STORED`), or the
// layered tables' (src/sat/layers.rs): `src` is the depth buffer and the texel, by `kind`,
// basis map `layer` of the light's sequence at its linear depth (shared/csm_maps), MSM's
// quantized moments of it, VSM's moments (with its four neighbours' depths,
// shared/vsm_moments), EVSM's (shared/evsm_moments) or ESM's exp(c (z − 1)), rounded to f16 or
// 16-bit unorm where the map would be stored so, computed on the fly and never stored.
// `from_depth` and `kind` are literals where each kernel builds its source, so every kernel
// compiles only its own branch. The tile
// kernels of the representation pass the constant `SAT_STORED`, so the branch folds away.
struct SatSource {
    from_depth: bool,    // computed from the depth; false: the texel as stored
    kind: u32,           // SAT_CSM (the sequence's map `layer`), SAT_MSM, SAT_VSM, SAT_EVSM, SAT_ESM
    f16: bool,           // round each basis value to f16
    layer: u32,          // the basis map (CSM's ⌈M/2⌉, then CSM-Z's)
    terms: u32,          // M
    moments: bool,       // the map after CSM's is MSM's moments (CSSM's moment search)
    unorm16: bool,       // round each value to 16-bit unorm
    exp_pos: f32,        // EVSM's c⁺, ESM's c
    exp_neg: f32,        // EVSM's c⁻
    depth: DepthParams,  // the depth buffer's linearization
    band: vec2<u32>,     // this table's carries start at this (tile column, tile row)
}

const SAT_CSM: u32 = 0u;
const SAT_MSM: u32 = 1u;
const SAT_VSM: u32 = 2u;
const SAT_EVSM: u32 = 3u;
const SAT_ESM: u32 = 4u;

const SAT_STORED: SatSource = SatSource(false, SAT_CSM, false, 0u, 0u, false, false, 0.0, 0.0,
    DepthParams(0u, 0.0, 1.0, 0u), vec2<u32>(0u));
