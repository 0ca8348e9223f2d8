// Pass 1 of 3 of a table of moments computed from the depth (import-only module of the
// `msm_sat_tile_sums`, `vsm_sat_tile_sums`, `evsm_sat_tile_sums` and `esm_sat_tile_sums`
// kernels and their f32 variants; src/sat/layers.rs, technique::add_moment_table: one layer):
// each workgroup computes its tile of the moments from the depth on the fly
// (`moment_sat_source`, shared/sat_tile), rounded as the map's storage would hold them, and
// writes the edges of its tile's own table, as `sat_tile_sums` does for a stored map, the moments
// never written. Counts the non-finite depth texels. The importing kernel declares its source,
// `const SAT_KIND: u32` (SAT_MSM, SAT_VSM, SAT_EVSM or SAT_ESM: a literal, so it compiles only
// its own branch), its variant, `const FLOAT_SUMS: bool`, and its `// #traffic` lines:
// #completed-by-importer
// #import shared/sat_tile_sums
// #import shared/csm_sat_params

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_part: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(2) var row_part: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(3) var<uniform> params: CsmSatParams;
@group(0) @binding(4) var<storage, read_write> stats: array<atomic<u32>>;

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    sat_tile_sums_pass(params.sat, FLOAT_SUMS, moment_sat_source(params, SAT_KIND), wg.xy, li);
    if sat_non_finite > 0u {
        atomicAdd(&stats[0], sat_non_finite);
    }
}
