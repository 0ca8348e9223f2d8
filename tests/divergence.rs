//! The reads the shading kernels make in non-uniform control flow (after a receiver was found
//! to face away, to lie outside the map, or to have no blockers; in loops that run to each
//! pixel's own tap count) return the texel asked for on this adapter: `textureLoad` at a
//! per-invocation level inside a branch, after an early return and in a loop of per-invocation
//! length; `textureSampleLevel` inside a branch; a level's size from level 0's
//! (`level_size`). Random texels and levels (seeded); each texel's value encodes its level and
//! coordinates, so the comparison is exact.
//!
//! `textureDimensions(map, level)` at a per-invocation level is the construct llvmpipe gets
//! wrong (it answers with one invocation's level, also with every invocation active); the
//! kernels never use it (`shared/sampling.wgsl`'s `level_size` shifts level 0's size instead),
//! and `dimensions_at_a_varying_level_are_not_used` checks that.

mod common;

use rand::Rng;
use wgpu::util::DeviceExt;

const SIZE: u32 = 64;
const LEVELS: u32 = 7;

fn value(level: u32, x: u32, y: u32) -> f32 {
    (level * 65536 + y * 256 + x) as f32
}

/// Runs `body` per query (`q`: x = active/count, y, z = texel, w = level), `r` the result.
fn run(
    g: &shadowgraph::low_level::gpu::Gpu,
    body: &str,
    sampler: bool,
    queries: &[[u32; 4]],
) -> Vec<f32> {
    let d = &g.device;
    let wgsl = format!(
        "@group(0) @binding(0) var map: texture_2d<f32>;\n\
         @group(0) @binding(1) var<storage, read> queries: array<vec4<u32>>;\n\
         @group(0) @binding(2) var<storage, read_write> results: array<f32>;\n\
         {}\
         @compute @workgroup_size(64)\n\
         fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         let q = queries[id.x];\n    var r = -1.0;\n    {body}\n    results[id.x] = r;\n}}\n",
        if sampler {
            "@group(0) @binding(3) var smp: sampler;\n"
        } else {
            ""
        }
    );
    let kernel =
        shadowgraph::low_level::exec::ComputeKernel::new(d, "divergence", &wgsl).expect("compile");
    let t = d.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: SIZE,
            height: SIZE,
            depth_or_array_layers: 1,
        },
        mip_level_count: LEVELS,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for level in 0..LEVELS {
        let n = SIZE >> level;
        let data: Vec<f32> = (0..n * n).map(|i| value(level, i % n, i / n)).collect();
        shadowgraph::low_level::gpu::write_texture_level(
            &g.queue,
            &t,
            level,
            bytemuck::cast_slice(&data),
        );
    }
    let view = t.create_view(&Default::default());
    let qbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(queries),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: queries.len() as u64 * 4,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let smp = d.create_sampler(&Default::default());
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&view),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: qbuf.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: out.as_entire_binding(),
        },
    ];
    if sampler {
        entries.push(wgpu::BindGroupEntry {
            binding: 3,
            resource: wgpu::BindingResource::Sampler(&smp),
        });
    }
    let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &kernel.layouts[0],
        entries: &entries,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(queries.len() as u32 / 64, 1, 1);
    }
    let raw = shadowgraph::low_level::gpu::submit_and_read(d, &g.queue, enc, &out, "divergence")
        .expect("read");
    bytemuck::cast_slice(&raw).to_vec()
}

fn queries(active: f64, level: Option<u32>, count: u32) -> Vec<[u32; 4]> {
    let mut rng = common::rng(7);
    (0..4096)
        .map(|_| {
            let l = level.unwrap_or_else(|| rng.random_range(0..LEVELS));
            let n = SIZE >> l;
            let a = if rng.random_bool(active) {
                rng.random_range(1..=count)
            } else {
                0
            };
            [a, rng.random_range(0..n), rng.random_range(0..n), l]
        })
        .collect()
}

/// The queries whose result differs from `expect`, as a one-line report (empty: all right).
fn wrong(name: &str, got: &[f32], expect: impl Fn(&[u32; 4]) -> f32, q: &[[u32; 4]]) -> String {
    let bad: Vec<usize> = (0..q.len()).filter(|&i| got[i] != expect(&q[i])).collect();
    match bad.first() {
        None => String::new(),
        Some(&i) => format!(
            "{name}: {} of {} wrong; first {i}: query {:?} got {} want {}",
            bad.len(),
            q.len(),
            q[i],
            got[i],
            expect(&q[i])
        ),
    }
}

/// Asserts that no case reported a wrong result.
fn assert_all_right(reports: Vec<String>) {
    let bad: Vec<String> = reports.into_iter().filter(|r| !r.is_empty()).collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

const FETCH: &str = "textureLoad(map, vec2<u32>(q.y, q.z), i32(q.w)).r";

/// The texel's value for an active query, −1 (untouched) for an inactive one.
fn texel(q: &[u32; 4]) -> f32 {
    if q[0] == 0 {
        -1.0
    } else {
        value(q[3], q[1], q[2])
    }
}

#[test]
fn loads_at_varying_levels_in_branches_are_exact() {
    let g = common::gpu();
    let mut reports = Vec::new();
    for (name, active, level, body) in [
        ("all active", 1.0, None, format!("r = {FETCH};")),
        (
            "in a branch, half active",
            0.5,
            None,
            format!("if q.x != 0u {{ r = {FETCH}; }}"),
        ),
        (
            "in a branch, 90% active",
            0.9,
            None,
            format!("if q.x != 0u {{ r = {FETCH}; }}"),
        ),
        (
            "in a branch, 10% active",
            0.1,
            None,
            format!("if q.x != 0u {{ r = {FETCH}; }}"),
        ),
        (
            "level 0 in a branch",
            0.5,
            Some(0),
            format!("if q.x != 0u {{ r = {FETCH}; }}"),
        ),
        (
            "after an early return",
            0.5,
            None,
            format!("if q.x == 0u {{ results[id.x] = -1.0; return; }} r = {FETCH};"),
        ),
    ] {
        let q = queries(active, level, 1);
        reports.push(wrong(name, &run(&g, &body, false, &q), texel, &q));
    }
    let uv = "(vec2<f32>(vec2<u32>(q.y, q.z)) + 0.5) / vec2<f32>(f32(64u >> q.w))";
    let body = format!("if q.x != 0u {{ r = textureSampleLevel(map, smp, {uv}, f32(q.w)).r; }}");
    let q = queries(0.5, None, 1);
    reports.push(wrong(
        "sampleLevel in a branch",
        &run(&g, &body, true, &q),
        texel,
        &q,
    ));
    assert_all_right(reports);
}

/// A loop that runs to each invocation's own count (`sample_map`'s taps, the soft techniques'
/// second pass) reads every trip's texel.
#[test]
fn loops_of_varying_length_read_every_trip() {
    let g = common::gpu();
    let sum = |q: &[u32; 4]| {
        if q[0] == 0 {
            -1.0
        } else {
            q[0] as f32 * value(q[3], q[1], q[2])
        }
    };
    let body =
        format!("if q.x != 0u {{ r = 0.0; }} for (var k = 0u; k < q.x; k++) {{ r += {FETCH}; }}");
    let mut reports = Vec::new();
    for (name, level) in [
        ("varying level", None),
        ("level 0", Some(0)),
        ("level 3", Some(3)),
    ] {
        let q = queries(0.8, level, 8);
        reports.push(wrong(name, &run(&g, &body, false, &q), sum, &q));
    }
    assert_all_right(reports);
}

/// `level_size`'s way (level 0's size shifted) is right under divergence.
#[test]
fn level_sizes_from_level_zero_are_exact() {
    let g = common::gpu();
    let dims = |q: &[u32; 4]| {
        if q[0] == 0 {
            -1.0
        } else {
            (SIZE >> q[3]) as f32
        }
    };
    let body = "if q.x != 0u { r = f32(max(textureDimensions(map).x >> q.w, 1u)); }";
    let q = queries(0.5, None, 1);
    assert_all_right(vec![wrong(
        "level_size",
        &run(&g, body, false, &q),
        dims,
        &q,
    )]);
}

/// No kernel asks `textureDimensions` for a level (the construct llvmpipe answers with one
/// invocation's level): every call names only the texture.
#[test]
fn dimensions_at_a_varying_level_are_not_used() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("kernels");
    let mut found = Vec::new();
    let mut dirs = vec![root];
    while let Some(dir) = dirs.pop() {
        for e in std::fs::read_dir(&dir).expect("kernels") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "wgsl") {
                let text = std::fs::read_to_string(&p).expect("kernel");
                for (n, line) in text.lines().enumerate() {
                    let code = line.split("//").next().unwrap_or("");
                    if let Some(at) = code.find("textureDimensions(") {
                        let args = &code[at + "textureDimensions(".len()..];
                        let call = args.split(')').next().unwrap_or("");
                        if call.contains(',') {
                            found.push(format!("{}:{}: {}", p.display(), n + 1, line.trim()));
                        }
                    }
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "textureDimensions at a level:\n{}",
        found.join("\n")
    );
}
