//! One plug-in stage serving several lights of a host: depth maps read in place from the
//! layers of one array texture, one set of pipelines for every light, per-light maps that stay
//! valid until that light is recorded again, and one shader module holding several lights'
//! WGSL blocks.
//!
//! The references are the single-light paths, which `tests/plugin/` checks against the
//! renderer (and so against the f64 references): a layer holds the same depth values as the
//! texture it was copied from, the kernels are the same, so the maps must be equal bit for bit
//! (tolerance 0); the composed module calls the same functions on the same maps as a
//! single-light block, so its visibility must be equal bit for bit too.

mod common;

use std::path::Path;

use common::host::host_depth;
use glam::{Mat4, Vec3};
use rand::Rng;
use shadowgraph::low_level::exec::ComputeKernel;
use shadowgraph::low_level::gpu::{Gpu, read_buffer, read_float_texture, submit_and_wait};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{
    DepthLayer, LightParams, MAX_LIGHTS, Prefilter, PrefilterConfig, PrefilterOutput, StageError,
    Technique, wgsl,
};
use wgpu::util::DeviceExt;

const SIZE: u32 = 128;

/// Two directional lights over `scenes/techniques/vsm.toml` (a sphere over a plane): the
/// scene's, and one from the other side.
fn lights() -> (Scene, [LightParams; 2]) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/vsm.toml");
    let scene = Scene::load(path).expect("scene");
    let first = LightParams::from_light(&scene.lights[0]);
    let view = Mat4::look_at_rh(Vec3::new(6.0, 8.0, -2.0), Vec3::ZERO, Vec3::Y);
    let second = LightParams::orthographic(view, 5.0, 2.0, 20.0);
    (scene, [first, second])
}

/// `layers` copied into the layers of one `Depth32Float` array texture (the test's setup; the
/// stage reads the layers in place).
fn array_of(g: &Gpu, layers: &[&wgpu::Texture]) -> wgpu::Texture {
    let array = g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.depth_array"),
        size: wgpu::Extent3d {
            width: SIZE,
            height: SIZE,
            depth_or_array_layers: layers.len() as u32,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut enc = g.device.create_command_encoder(&Default::default());
    for (k, layer) in layers.iter().enumerate() {
        enc.copy_texture_to_texture(
            layer.as_image_copy(),
            wgpu::TexelCopyTextureInfo {
                texture: &array,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: k as u32,
                },
                aspect: wgpu::TextureAspect::All,
            },
            layer.size(),
        );
    }
    submit_and_wait(&g.device, &g.queue, enc, "array").expect("copy into layers");
    array
}

/// Every map of `out`, read back.
fn maps_of(g: &Gpu, out: &PrefilterOutput) -> Vec<Vec<f32>> {
    out.maps
        .iter()
        .map(|m| {
            read_float_texture(&g.device, &g.queue, &m.texture, 0)
                .expect("readback")
                .1
        })
        .collect()
}

/// Asserts `a` and `b` (maps, or values) are equal bit for bit, reporting how many differ.
fn assert_same(what: &str, a: &[Vec<f32>], b: &[Vec<f32>]) {
    assert_eq!(a.len(), b.len(), "{what}: map count");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(x.len(), y.len(), "{what}: map {k} size");
        let differ: Vec<usize> = (0..x.len())
            .filter(|&i| x[i].to_bits() != y[i].to_bits())
            .collect();
        assert!(
            differ.is_empty(),
            "{what}: map {k}: {} of {} values differ (first at {})",
            differ.len(),
            x.len(),
            differ[0]
        );
    }
}

/// The maps of a fresh single-light stage over a whole texture.
fn single(
    g: &Gpu,
    config: &PrefilterConfig,
    depth: &wgpu::Texture,
    p: &LightParams,
) -> Vec<Vec<f32>> {
    let mut stage = Prefilter::new(&g.device, config).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = stage.record(&g.device, &mut enc, depth, p).expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "single").expect("submit");
    maps_of(g, &out)
}

#[test]
fn array_layers_and_light_slots_equal_single_lights() {
    let g = common::gpu();
    let (scene, params) = lights();
    let vertices = scene.vertices();
    let depths: Vec<wgpu::Texture> = params
        .iter()
        .map(|p| host_depth(&g, &vertices, p, 0.0, SIZE))
        .collect();
    let array = array_of(&g, &[&depths[0], &depths[1]]);
    let config = PrefilterConfig::from_light(&scene.lights[0]).with_size(SIZE);
    let expected: Vec<Vec<Vec<f32>>> = (0..2)
        .map(|k| single(&g, &config, &depths[k], &params[k]))
        .collect();
    assert!(
        expected[0][0]
            .iter()
            .zip(&expected[1][0])
            .filter(|(x, y)| x != y)
            .count()
            > 1000,
        "the two lights' maps must differ"
    );

    let mut stage = Prefilter::new(&g.device, &config).expect("stage");
    let pipelines = stage.pipeline_count();
    let mut enc = g.device.create_command_encoder(&Default::default());
    let outs: Vec<PrefilterOutput> = (0..2)
        .map(|k| {
            let depth = DepthLayer::new(&array, k as u32);
            stage
                .record_light(k, &g.device, &mut enc, depth, &params[k])
                .expect("record a layer")
        })
        .collect();
    submit_and_wait(&g.device, &g.queue, enc, "two lights").expect("submit");
    for k in 0..2 {
        assert_same(
            &format!("light {k} from layer {k}"),
            &maps_of(&g, &outs[k]),
            &expected[k],
        );
    }
    assert_eq!(stage.light_count(), 2);
    assert_eq!(
        stage.pipeline_count(),
        pipelines,
        "a second light made pipelines"
    );
    let one_light = {
        let mut s = Prefilter::new(&g.device, &config).expect("stage");
        let mut enc = g.device.create_command_encoder(&Default::default());
        s.record(&g.device, &mut enc, &depths[0], &params[0])
            .expect("record");
        g.queue.submit([enc.finish()]);
        s.texture_count()
    };
    assert_eq!(stage.texture_count(), 2 * one_light, "one pool per light");

    // Light 1 recorded again over light 0's depth: light 0's maps are untouched.
    let mut enc = g.device.create_command_encoder(&Default::default());
    let again = stage
        .record_light(
            1,
            &g.device,
            &mut enc,
            DepthLayer::new(&array, 0),
            &params[0],
        )
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "light 1 again").expect("submit");
    assert_same("light 0 kept", &maps_of(&g, &outs[0]), &expected[0]);
    assert_same("light 1 refiltered", &maps_of(&g, &again), &expected[0]);
    for (a, b) in outs[0].maps.iter().zip(&again.maps) {
        assert_ne!(a.texture, b.texture, "lights share a texture");
    }
}

#[test]
fn bad_layers_and_slots_are_named() {
    let g = common::gpu();
    let (scene, params) = lights();
    let depth = host_depth(&g, &scene.vertices(), &params[0], 0.0, SIZE);
    let array = array_of(&g, &[&depth, &depth]);
    let config = PrefilterConfig::from_light(&scene.lights[0]).with_size(SIZE);
    let mut stage = Prefilter::new(&g.device, &config).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    let e = stage
        .record(&g.device, &mut enc, DepthLayer::new(&array, 2), &params[0])
        .unwrap_err();
    assert!(
        matches!(
            e,
            shadowgraph::Error::Stage(StageError::DepthLayer {
                layer: 2,
                layers: 2
            })
        ),
        "{e}"
    );
    assert!(e.to_string().contains("layer 2"), "{e}");
    let e = stage
        .record_light(MAX_LIGHTS, &g.device, &mut enc, &depth, &params[0])
        .unwrap_err();
    assert!(e.to_string().contains("at most 256 lights"), "{e}");
    assert_eq!(stage.light_count(), 1, "a refused slot allocated nothing");
}

/// Visibility of each light at the points, through a host module holding every light's block.
const PROBE: &str = "
@group(0) @binding(0) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;
@group(0) @binding(2) var<uniform> light_a: sg_Light;
@group(0) @binding(3) var<uniform> light_b: sg_Light;
@group(0) @binding(4) var<uniform> light_c: sg_Light;
// The host's own names, spelt like the library's unprefixed ones, do not collide.
struct Light { unused: f32 }
fn linstep(a: f32) -> f32 { return a; }

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = arrayLength(&points);
    if id.x >= n {
        return;
    }
    let p = points[id.x].xyz;
    let up = vec3<f32>(0.0, 1.0, 0.0);
    out[id.x] = VIS_A;
    out[n + id.x] = VIS_B;
    out[2u * n + id.x] = VIS_C;
}
";

/// Runs `wgsl` (a [`PROBE`] completed) at `points` with `lights` and the maps bound from
/// binding 0 of group 1 in order; `per_light` outputs per point.
fn probe(
    g: &Gpu,
    wgsl: &str,
    points: &[[f32; 4]],
    lights: &[&PrefilterOutput],
    maps: &[&wgpu::TextureView],
    per_light: usize,
) -> Vec<f32> {
    let d = &g.device;
    let kernel = ComputeKernel::new(d, "lights_probe", wgsl).unwrap_or_else(|e| panic!("{e}"));
    let buffer = |bytes: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("probe"),
            contents: bytes,
            usage,
        })
    };
    let pts = buffer(bytemuck::cast_slice(points), wgpu::BufferUsages::STORAGE);
    let out = buffer(
        bytemuck::cast_slice(&vec![-1.0f32; per_light * points.len()]),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let uniforms: Vec<wgpu::Buffer> = lights
        .iter()
        .map(|o| buffer(bytemuck::bytes_of(&o.light), wgpu::BufferUsages::UNIFORM))
        .collect();
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: pts.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: out.as_entire_binding(),
        },
    ];
    for (k, u) in uniforms.iter().enumerate() {
        entries.push(wgpu::BindGroupEntry {
            binding: 2 + k as u32,
            resource: u.as_entire_binding(),
        });
    }
    let bg0 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe"),
        layout: &kernel.layouts[0],
        entries: &entries,
    });
    let map_entries: Vec<wgpu::BindGroupEntry> = maps
        .iter()
        .enumerate()
        .map(|(k, v)| wgpu::BindGroupEntry {
            binding: k as u32,
            resource: wgpu::BindingResource::TextureView(v),
        })
        .collect();
    let bg1 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe.maps"),
        layout: &kernel.layouts[1],
        entries: &map_entries,
    });
    let readback = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe.readback"),
        size: out.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, &bg0, &[]);
        pass.set_bind_group(1, &bg1, &[]);
        pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &readback, 0, out.size());
    submit_and_wait(d, &g.queue, enc, "probe").expect("probe");
    bytemuck::cast_slice(&read_buffer(d, &readback).expect("readback")).to_vec()
}

/// Three lights in one module (two VSM lights of one stage, a hard-shadow light of another):
/// the functions of both techniques once, then one block per light; each light's visibility
/// equals its own single-light block's, bit for bit.
#[test]
fn several_lights_compose_in_one_module() {
    let g = common::gpu();
    let (scene, params) = lights();
    let vertices = scene.vertices();
    let depths: Vec<wgpu::Texture> = params
        .iter()
        .map(|p| host_depth(&g, &vertices, p, 0.0, SIZE))
        .collect();
    let array = array_of(&g, &[&depths[0], &depths[1]]);
    let vsm_config = PrefilterConfig::from_light(&scene.lights[0]).with_size(SIZE);
    let hard_config = PrefilterConfig::new(Technique::Hard, SIZE).with_bias(0.002);
    let mut vsm = Prefilter::new(&g.device, &vsm_config).expect("vsm stage");
    let mut hard = Prefilter::new(&g.device, &hard_config).expect("hard stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    let a = vsm
        .record_light(
            0,
            &g.device,
            &mut enc,
            DepthLayer::new(&array, 0),
            &params[0],
        )
        .expect("a");
    let b = vsm
        .record_light(
            1,
            &g.device,
            &mut enc,
            DepthLayer::new(&array, 1),
            &params[1],
        )
        .expect("b");
    let c = hard
        .record(&g.device, &mut enc, DepthLayer::new(&array, 1), &params[1])
        .expect("c");
    submit_and_wait(&g.device, &g.queue, enc, "three lights").expect("submit");

    let mut rng = common::rng(17);
    let points: Vec<[f32; 4]> = (0..2048)
        .map(|_| {
            [
                rng.random_range(-4.0..4.0),
                0.0,
                rng.random_range(-4.0..4.0),
                1.0,
            ]
        })
        .collect();
    let functions =
        wgsl::functions_for(&[vsm_config.technique, hard_config.technique]).expect("functions");
    let composed = format!(
        "{functions}{}{}{}{}",
        vsm.wgsl_light("a", 1, 0).expect("a"),
        vsm.wgsl_light("b", 1, 1).expect("b"),
        hard.wgsl_light("c", 1, 2).expect("c"),
        PROBE
            .replace("VIS_A", "shadowgraph_visibility_a(light_a, p, up)")
            .replace("VIS_B", "shadowgraph_visibility_b(light_b, p, up)")
            .replace("VIS_C", "shadowgraph_visibility_c(light_c, p, up)"),
    );
    let views = [&a.maps[0].view, &b.maps[0].view, &c.maps[0].view];
    let together = probe(&g, &composed, &points, &[&a, &b, &c], &views, 3);
    let n = points.len();
    for (k, (stage, out)) in [(&vsm, &a), (&vsm, &b), (&hard, &c)]
        .into_iter()
        .enumerate()
    {
        let alone = format!(
            "{}{}",
            stage.wgsl(1, 0).expect("block"),
            PROBE
                .replace("VIS_A", "shadowgraph_visibility(light_a, p, up)")
                .replace("out[n + id.x] = VIS_B;", "")
                .replace("out[2u * n + id.x] = VIS_C;", "")
                .replace("var<uniform> light_b: sg_Light;", "")
                .replace("var<uniform> light_c: sg_Light;", "")
                .replace("@group(0) @binding(3)", "")
                .replace("@group(0) @binding(4)", ""),
        );
        let single = probe(&g, &alone, &points, &[out], &[&out.maps[0].view], 1);
        let shared = &together[k * n..(k + 1) * n];
        let differ = single
            .iter()
            .zip(shared)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(differ, 0, "light {k}: composed against alone");
        let shadowed = single.iter().filter(|&&v| v < 0.5).count();
        let lit = single.iter().filter(|&&v| v > 0.5).count();
        assert!(
            shadowed > 20 && lit > 20,
            "light {k}: {shadowed} shadowed, {lit} lit of {n}: the points must see both"
        );
    }
}

/// The memory budget counts every light of a stage: a CSSM (M = 16: eight basis tables and the
/// moments' table) stage planned at 4096² (about 3.2 GiB of textures, under the default 4 GiB)
/// refuses a second light at 4096² before allocating anything for it.
#[test]
fn the_memory_budget_counts_every_light() {
    let g = common::gpu();
    if std::env::var_os(shadowgraph::low_level::limits::MEMORY_BUDGET_ENV).is_some() {
        panic!(
            "unset {} to run this test",
            shadowgraph::low_level::limits::MEMORY_BUDGET_ENV
        );
    }
    let big = 4096;
    let config = PrefilterConfig::cssm(big, 16, 0.5);
    let mut stage = Prefilter::new(&g.device, &config).expect("one light fits the budget");
    let depth = g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.depth"),
        size: wgpu::Extent3d {
            width: big,
            height: big,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let (_, params) = lights();
    let mut enc = g.device.create_command_encoder(&Default::default());
    let e = stage
        .record_light(1, &g.device, &mut enc, &depth, &params[0])
        .unwrap_err();
    assert!(
        matches!(&e, shadowgraph::Error::Limit { what, .. } if what.contains("all its lights")),
        "{e}"
    );
    assert!(e.to_string().contains("memory budget"), "{e}");
    assert_eq!(stage.light_count(), 1, "the refused light holds nothing");
    assert_eq!(stage.texture_count(), 0);
}
