// Pass 3 of 3 of a table of moments computed from the depth, fixed-point variant (import-only
// module of the `msm_sat_tiles`, `vsm_sat_tiles`, `evsm_sat_tiles` and `esm_sat_tiles` kernels;
// src/sat/layers.rs, technique::add_moment_table: one layer): each workgroup computes its tile of
// the moments from the depth again (`moment_sat_source`, shared/sat_tile), scans it as
// `sat_tiles` does, adds the carries (pass 2, `sat_carries`) and stores the table. The executor
// re-declares `dst0` for the table's channels. The importing kernel declares its source, `const
// SAT_KIND: u32` (a literal, as shared/moment_sat_sums), and its `// #traffic` lines:
// #completed-by-importer
// #import shared/sat_tile_scan
// #import shared/csm_sat_params

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var col_carry: texture_2d<u32>;
@group(0) @binding(2) var row_carry: texture_2d<u32>;
@group(0) @binding(3) var dst0: texture_storage_2d<rgba32uint, write>;
@group(0) @binding(4) var<uniform> params: CsmSatParams;

const FLOAT_SUMS: bool = false;

// Table texel q (shared/sat_tile_scan; one table, `slot` unused).
fn sat_store(slot: u32, q: vec2<u32>, v: vec4<u32>) {
    textureStore(dst0, q, v);
}

@compute @workgroup_size(WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    sat_tile_table(params.sat, FLOAT_SUMS, moment_sat_source(params, SAT_KIND), wg.xy, li, 0u);
}
