//! The kernels' constants against the Rust side, and a table's plan: its dispatches,
//! what they read and write, its channels.

use super::*;

/// A `const NAME: u32` of a kernel, from naga's IR.
fn wgsl_const(module: &naga::Module, name: &str) -> Option<u32> {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))?;
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => Some(v),
        _ => None,
    }
}

#[test]
fn sat_tile_and_params_match_the_wgsl() {
    // A row workgroup of `sat_carries` covers whole tile rows (`ROWS` of them), one invocation
    // per row; the tile kernels' per-line steps take one invocation a tile row or column.
    assert_eq!(SAT_LINES_PER_GROUP, 2 * SAT_TILE);
    let wgsl = kernels::resolve("sat_carries", None).unwrap();
    let (module, _) = kernels::reflect("sat_carries", &wgsl).unwrap();
    assert_eq!(
        wgsl_const(&module, "ROWS"),
        Some(SAT_LINES_PER_GROUP / SAT_TILE)
    );
    for kernel in [
        "sat_tile_sums",
        "sat_tile_sums_f32",
        "sat_carries",
        "sat_tiles",
        "sat_tiles_f32",
    ] {
        let wgsl = kernels::resolve(kernel, None).unwrap();
        let (module, r) = kernels::reflect(kernel, &wgsl).unwrap();
        assert_eq!(
            wgsl_const(&module, "TILE"),
            Some(SAT_TILE),
            "{kernel}: TILE"
        );
        let wg = r.workgroup_size.unwrap_or_default();
        assert_eq!(wg, [SAT_LINES_PER_GROUP, 1, 1], "{kernel}: workgroup");
        assert_eq!(
            kernels::struct_size(&module, "SatParams"),
            Some(size_of::<SatParams>() as u32),
            "{kernel}: SatParams vs struct SatParams"
        );
    }
    for kernel in [
        "sat_rows",
        "sat_carry",
        "sat_cols_reduce",
        "sat_cols",
        "sat_cols_f32",
    ] {
        let wgsl = kernels::resolve(kernel, None).unwrap();
        let (module, r) = kernels::reflect(kernel, &wgsl).unwrap();
        let block = wgsl_const(&module, "BLOCK");
        let items = wgsl_const(&module, "ITEMS").unwrap_or(0);
        assert_eq!(block, Some(SAT_BLOCK), "{kernel}: BLOCK");
        let wg = r.workgroup_size.unwrap_or_default();
        if kernel == "sat_carry" {
            assert_eq!(wg, [SAT_CARRY_LINES, 1, 1], "{kernel}");
        } else {
            assert_eq!([wg[0] * items, wg[1], wg[2]], [SAT_BLOCK, 1, 1], "{kernel}");
        }
        assert_eq!(
            kernels::struct_size(&module, "SatParams"),
            Some(size_of::<SatParams>() as u32),
            "{kernel}: SatParams vs struct SatParams"
        );
    }
}

/// The structural cost of a table: three dispatches; over them the map is read twice and the
/// table written once, everything else (tile edges and carries, each written once and read
/// once) 8/SAT_TILE of a table texel per texel; the table and its intermediates have the map's
/// channels. Exact, from the plan's resources as the passes bind them.
#[test]
fn sat_reads_the_map_twice_and_writes_the_table_once() {
    for (format, table_bytes) in [
        (wgpu::TextureFormat::R32Float, 4u64),
        (wgpu::TextureFormat::Rg32Float, 8),
        (wgpu::TextureFormat::Rgba32Float, 16),
    ] {
        let n = 4096u32;
        let mut graph = Graph::default();
        graph.import("in", format, n, n, Some(0));
        let coding = SatCoding::fixed(lookup_area(64.0, 64.0), [0.0; 4], [1.0; 4]).unwrap();
        let out = add_sat(&mut graph, 0, "in", &coding);
        let p = plan(&graph, &[&out]).unwrap();
        assert_eq!(p.steps.len(), 3, "{format:?}: dispatches");
        let bytes = |r: &str| p.resource(r).map_or(0, |r| r.bytes);
        let texels = u64::from(n) * u64::from(n);
        let (mut input, mut table, mut other) = (0, 0, 0);
        for step in &p.steps {
            for (_, r) in step.node.inputs.iter().chain(&step.node.outputs) {
                match r.as_str() {
                    "in" => input += bytes(r),
                    r if r == out => table += bytes(r),
                    r => other += bytes(r),
                }
            }
        }
        let input_texel = texel_bytes(format);
        assert_eq!(
            input,
            2 * input_texel * texels,
            "{format:?}: map read twice"
        );
        assert_eq!(
            table,
            table_bytes * texels,
            "{format:?}: table written once"
        );
        assert_eq!(
            other,
            8 * table_bytes * texels / u64::from(SAT_TILE),
            "{format:?}: edges and carries"
        );
        assert_eq!(
            p.resource(&out).unwrap().resource.format,
            SatVariant::Fixed.format(format_channels(format))
        );
    }
}
