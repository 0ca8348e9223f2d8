//! The plug-in stage inside a host: from a depth texture the host rasterized itself, the
//! stage's maps equal the renderer's, and the exported WGSL with `PrefilterOutput::light`
//! gives the renderer's visibility; recording every frame keeps memory constant; a size
//! change reallocates; per-kernel timings.

mod common;

use common::host::{host_depth, host_depth_views};

use std::path::{Path, PathBuf};

use shadowgraph::low_level::exec::ComputeKernel;
use shadowgraph::low_level::gpu::{
    Gpu, read_float_texture, read_resource_texture, submit_and_wait,
};
use shadowgraph::low_level::render::{Frame, RenderOptions, Renderer};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::technique::depth_name;
use shadowgraph::{LightParams, Prefilter, PrefilterConfig, StageError};
use wgpu::util::DeviceExt;

/// Records the stage over `depth` in an encoder of the host's, submits, reads map `k` back.
fn run_stage(
    g: &Gpu,
    stage: &mut Prefilter,
    depth: &wgpu::Texture,
    light: &LightParams,
) -> Vec<Vec<f32>> {
    run_stage_channels(g, stage, depth, light)
        .into_iter()
        .map(|(_, d)| d)
        .collect()
}

/// [`run_stage`] with each map's channel count.
fn run_stage_channels(
    g: &Gpu,
    stage: &mut Prefilter,
    depth: &wgpu::Texture,
    light: &LightParams,
) -> Vec<(usize, Vec<f32>)> {
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = stage
        .record(&g.device, &mut enc, depth, light)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "stage").expect("submit");
    out.maps
        .iter()
        .map(|m| {
            // Packed f16 moments (an r32uint texture) unpacked, as the renderer reads its own.
            read_resource_texture(&g.device, &g.queue, &m.texture, 0, m.format).expect("readback")
        })
        .collect()
}

/// The stage's maps as the renderer's `Frame::shade_maps` holds them: summed-area tables
/// decoded to the representation they sum (`render::read_sat_map`, as the renderer reads its
/// own), other maps as they are.
fn stage_maps_as_frame(
    g: &Gpu,
    stage: &mut Prefilter,
    depth: &wgpu::Texture,
    params: &LightParams,
    light: &shadowgraph::Light,
) -> Vec<(usize, Vec<f32>)> {
    let Some(coding) = shadowgraph::low_level::technique::sat_coding(light).expect("coding") else {
        return run_stage_channels(g, stage, depth, params);
    };
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = stage
        .record(&g.device, &mut enc, depth, params)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "stage").expect("submit");
    out.maps
        .iter()
        .zip(shadowgraph::low_level::technique::map_tables(light))
        .map(|(m, n)| {
            let map = shadowgraph::low_level::render::read_sat_map(
                &g.device, &g.queue, "stage", &m.texture, &coding, &n,
            )
            .expect("readback");
            (map.channels, map.data)
        })
        .collect()
}

/// Per pixel of `frame`, the surface's world-space differentials along x and y (two vec4s),
/// as the renderer computes them for its footprints.
fn differentials(frame: &Frame, scene: &Scene) -> Vec<f32> {
    let rays = shadowgraph::low_level::model::CameraRays::new(&scene.camera, frame.width, frame.height);
    let eye = scene.camera.position.as_dvec3();
    let mut diffs = Vec::with_capacity(8 * (frame.width * frame.height) as usize);
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = 4 * (y * frame.width + x) as usize;
            let p = glam::Vec3::from_slice(&frame.position[i..i + 3]).as_dvec3();
            let n = glam::Vec3::from_slice(&frame.normal[i..i + 3]).as_dvec3();
            let n = if n.length() > 0.0 {
                n.normalize()
            } else {
                glam::DVec3::Y
            };
            let (dx, dy) = shadowgraph::low_level::cpu::shade::pixel_differentials(eye, &rays, x, y, p, n);
            for v in [dx, dy] {
                diffs.extend([v.x as f32, v.y as f32, v.z as f32, 0.0]);
            }
        }
    }
    diffs
}

/// Host shading of given points through the stage's exported WGSL (`shadowgraph_visibility`
/// with `PrefilterOutput::light`), as a compute pass of the host's.
const HOST_PROBE: &str = "
@group(0) @binding(0) var<uniform> light: sg_Light;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> normals: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> visibility: array<f32>;
@group(0) @binding(4) var<storage, read> differentials: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&visibility) {
        return;
    }
    visibility[id.x] = shadowgraph_visibility_footprint(light, positions[id.x].xyz,
        normalize(normals[id.x].xyz), differentials[2u * id.x].xyz, differentials[2u * id.x + 1u].xyz);
}
";

/// Visibility at every pixel of `frame` (its G-buffer) through the host's WGSL, each pixel
/// with its footprint (`cpu::shade::pixel_differentials` of `scene`'s camera, as a fragment
/// shader's dpdx/dpdy would give it).
fn host_visibility(
    g: &Gpu,
    stage: &mut Prefilter,
    depth: &wgpu::Texture,
    light: &LightParams,
    frame: &Frame,
    scene: &Scene,
) -> Vec<f32> {
    let diffs = differentials(frame, scene);
    let d = &g.device;
    let wgsl = format!("{}{HOST_PROBE}", stage.wgsl(1, 0).expect("host WGSL"));
    let kernel = ComputeKernel::new(d, "host_probe", &wgsl).expect("host probe compiles");
    let mut enc = d.create_command_encoder(&Default::default());
    let out = stage.record(d, &mut enc, depth, light).expect("record");
    let storage = |data: &[f32], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host.probe"),
            contents: bytemuck::cast_slice(data),
            usage,
        })
    };
    let n = (frame.width * frame.height) as usize;
    let light_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("host.light"),
        contents: bytemuck::bytes_of(&out.light),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let pos = storage(&frame.position, wgpu::BufferUsages::STORAGE);
    let nor = storage(&frame.normal, wgpu::BufferUsages::STORAGE);
    let dif = storage(&diffs, wgpu::BufferUsages::STORAGE);
    let vis = storage(
        &vec![-1.0; n],
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let bg0 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host.probe"),
        layout: &kernel.layouts[0],
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: light_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: pos.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: nor.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: vis.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: dif.as_entire_binding(),
            },
        ],
    });
    let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        compare: Some(wgpu::CompareFunction::LessEqual),
        ..Default::default()
    });
    let mut entries: Vec<wgpu::BindGroupEntry> = out
        .maps
        .iter()
        .enumerate()
        .map(|(k, m)| wgpu::BindGroupEntry {
            binding: k as u32,
            resource: wgpu::BindingResource::TextureView(&m.view),
        })
        .collect();
    if stage.needs_comparison_sampler().expect("block") {
        entries.push(wgpu::BindGroupEntry {
            binding: out.maps.len() as u32,
            resource: wgpu::BindingResource::Sampler(&sampler),
        });
    }
    let sat_sampler = d.create_sampler(&shadowgraph::SAT_SAMPLER_DESCRIPTOR);
    if stage.needs_filtering_sampler().expect("block") {
        entries.push(wgpu::BindGroupEntry {
            binding: entries.len() as u32,
            resource: wgpu::BindingResource::Sampler(&sat_sampler),
        });
    }
    run_probe(g, &kernel, enc, &bg0, &entries, &vis, n)
}

/// A host probe's last steps: its maps' bind group from `entries`, one invocation a pixel,
/// `vis` read back.
fn run_probe(
    g: &Gpu,
    kernel: &ComputeKernel,
    mut enc: wgpu::CommandEncoder,
    bg0: &wgpu::BindGroup,
    entries: &[wgpu::BindGroupEntry],
    vis: &wgpu::Buffer,
    n: usize,
) -> Vec<f32> {
    let d = &g.device;
    let bg1 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host.probe.maps"),
        layout: &kernel.layouts[1],
        entries,
    });
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&kernel.pipeline);
        pass.set_bind_group(0, bg0, &[]);
        pass.set_bind_group(1, &bg1, &[]);
        pass.dispatch_workgroups((n as u32).div_ceil(64), 1, 1);
    }
    let readback = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("host.probe.readback"),
        size: vis.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_buffer_to_buffer(vis, 0, &readback, 0, vis.size());
    submit_and_wait(d, &g.queue, enc, "host probe").expect("submit");
    let raw = shadowgraph::low_level::gpu::read_buffer(d, &readback).expect("readback");
    bytemuck::cast_slice(&raw).to_vec()
}

/// A host's probe of a cascaded light through the exported WGSL: `shadowgraph_visibility_
/// cascaded_sun` (`Prefilter::wgsl_cascades`) at the renderer's G-buffer points, with every
/// cascade's maps bound and cascade 0's `sg_Light` holding the pick fields.
const HOST_CASCADE_PROBE: &str = "
@group(0) @binding(0) var<uniform> lights: array<sg_Light, 4>;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> normals: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> visibility: array<f32>;
@group(0) @binding(4) var<storage, read> differentials: array<vec4<f32>>;

// Per pixel: the plain function's visibility, then the one with the pixel's footprint.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if 2u * id.x >= arrayLength(&visibility) {
        return;
    }
    let p = positions[id.x].xyz;
    let n = normalize(normals[id.x].xyz);
    visibility[2u * id.x] = shadowgraph_visibility_cascaded_sun(lights, p, n);
    visibility[2u * id.x + 1u] = shadowgraph_visibility_footprint_cascaded_sun(lights, p, n,
        differentials[2u * id.x].xyz, differentials[2u * id.x + 1u].xyz);
}
";

/// [`HOST_CASCADE_PROBE`]: four light slots of `stage` recorded from `depths` with
/// `cascades`' lights, the pick fields filled, the probe run over `frame`'s pixels: per pixel
/// the plain function's visibility and the footprint's.
fn host_cascaded_visibility(
    g: &Gpu,
    stage: &mut Prefilter,
    depths: &[wgpu::Texture],
    cascades: &[shadowgraph::cascades::Cascade],
    camera: &shadowgraph::cascades::CascadeCamera,
    frame: &Frame,
    scene: &Scene,
) -> Vec<f32> {
    assert_eq!(cascades.len(), 4, "the probe's array holds four cascades");
    let d = &g.device;
    let wgsl = format!(
        "{}{}{HOST_CASCADE_PROBE}",
        stage.wgsl_functions().expect("functions"),
        stage.wgsl_cascades("sun", 1, 0).expect("cascades block")
    );
    let kernel = ComputeKernel::new(d, "host_cascade_probe", &wgsl).expect("probe compiles");
    let mut enc = d.create_command_encoder(&Default::default());
    let mut outs: Vec<_> = cascades
        .iter()
        .zip(depths)
        .enumerate()
        .map(|(k, (c, depth))| {
            stage
                .record_light(k, d, &mut enc, depth, &c.light)
                .expect("record")
        })
        .collect();
    let blend = stage.config().cascades.blend;
    shadowgraph::cascades::pick_fields(&mut outs[0].light, camera, cascades, blend)
        .expect("pick fields");
    let lights: Vec<u8> = outs
        .iter()
        .flat_map(|o| bytemuck::bytes_of(&o.light).to_vec())
        .collect();
    let buffer = |data: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host.cascade_probe"),
            contents: data,
            usage,
        })
    };
    let n = (frame.width * frame.height) as usize;
    let light_buf = buffer(&lights, wgpu::BufferUsages::UNIFORM);
    let pos = buffer(
        bytemuck::cast_slice(&frame.position),
        wgpu::BufferUsages::STORAGE,
    );
    let nor = buffer(
        bytemuck::cast_slice(&frame.normal),
        wgpu::BufferUsages::STORAGE,
    );
    let vis = buffer(
        bytemuck::cast_slice(&vec![-1.0f32; 2 * n]),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let dif = buffer(
        bytemuck::cast_slice(&differentials(frame, scene)),
        wgpu::BufferUsages::STORAGE,
    );
    let bg0 = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host.cascade_probe"),
        layout: &kernel.layouts[0],
        entries: &[&light_buf, &pos, &nor, &vis, &dif]
            .iter()
            .enumerate()
            .map(|(b, buf)| wgpu::BindGroupEntry {
                binding: b as u32,
                resource: buf.as_entire_binding(),
            })
            .collect::<Vec<_>>(),
    });
    let cmp_sampler = d.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        compare: Some(wgpu::CompareFunction::LessEqual),
        ..Default::default()
    });
    let sat_sampler = d.create_sampler(&shadowgraph::SAT_SAMPLER_DESCRIPTOR);
    let per_light = stage
        .layout_entries(0, wgpu::ShaderStages::COMPUTE)
        .expect("entries")
        .len() as u32;
    let samplers = [
        (
            stage.needs_comparison_sampler().expect("block"),
            &cmp_sampler,
        ),
        (
            stage.needs_filtering_sampler().expect("block"),
            &sat_sampler,
        ),
    ];
    let mut entries = Vec::new();
    for (k, out) in outs.iter().enumerate() {
        let first = k as u32 * per_light;
        let views = out
            .maps
            .iter()
            .map(|m| wgpu::BindingResource::TextureView(&m.view));
        let used = samplers.iter().filter(|s| s.0);
        let resources = views.chain(used.map(|s| wgpu::BindingResource::Sampler(s.1)));
        entries.extend(
            resources
                .enumerate()
                .map(|(j, resource)| wgpu::BindGroupEntry {
                    binding: first + j as u32,
                    resource,
                }),
        );
    }
    run_probe(g, &kernel, enc, &bg0, &entries, &vis, n)
}

fn scenes() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut v: Vec<PathBuf> = [root.clone(), root.join("techniques")]
        .iter()
        .flat_map(|d| {
            std::fs::read_dir(d)
                .expect("scenes/")
                .map(|e| e.expect("entry").path())
        })
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    v
}

/// Count of values that differ bit for bit, and the largest difference.
fn differences(a: &[f32], b: &[f32]) -> (usize, f32) {
    assert_eq!(a.len(), b.len(), "lengths");
    a.iter().zip(b).fold((0, 0.0f32), |(n, worst), (x, y)| {
        if x.to_bits() == y.to_bits() {
            (n, worst)
        } else {
            (n + 1, worst.max((x - y).abs()))
        }
    })
}

/// For every light of every bundled scene: the host's depth equals the renderer's raster,
/// so the stage's maps must equal the renderer's bit for bit (the same kernels on the same
/// inputs; tolerance 0). Visibility through the exported WGSL and `PrefilterOutput::light`:
/// that light's position, direction and map width come from inverting the host's matrices
/// rather than from the scene, an ulp-level change that can flip a comparison exactly at a
/// texel edge; so |Δ| ≤ 1e-5 at ≥ 99.9% of covered pixels and ≤ 1e-3 summed over all. The
/// soft techniques' f32 chains (blocker estimate → width → lookup) amplify such changes where
/// they are ill-conditioned (soft MSM's reconstruction, measured: |Δ| up to 1e-3 at 0.55% of
/// pixels): there each run may stand as far from the f64 reference as its propagated tolerance
/// (tests/common/soft.rs, which models UV and depth errors of that size), so a pixel counts as
/// off where |Δ| exceeds 1e-5 and twice that tolerance; pixels where the reference jumps or the
/// blocker threshold could flip are not counted.
#[test]
fn stage_outputs_equal_the_renderers() {
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    for path in scenes() {
        let scene = Scene::load(&path).expect("scene loads");
        let name = path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        let frame = renderer
            .render(
                &g.device,
                &g.queue,
                &scene,
                RenderOptions {
                    aux: true,
                    repeat: 1,
                    dump: true,
                },
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let vertices = scene.vertices();
        let lights = scene.lights.len();
        for (li, light) in scene.lights.iter().enumerate() {
            if light.shadow.cascades.count > 1 {
                // The renderer draws a cascaded light as one map per cascade (tests/scenes.rs
                // checks them per pixel); a host fits its own (`prefilter::cascades`).
                continue;
            }
            let what = format!("{name} light {li} ({})", light.shadow.technique.name());
            let params = LightParams::from_light(light);
            let config = PrefilterConfig::from_light(light);
            // A point light's atlas, drawn face by face with the stage's views.
            let (w, h) = light.map_dims();
            let depth = if params.point {
                let stage = Prefilter::new(&g.device, &config).expect("stage");
                let views: Vec<(glam::Mat4, [u32; 4])> = stage
                    .point_views(&params, light.shadow_map)
                    .expect("point views")
                    .iter()
                    .map(|v| (v.view_proj, v.viewport))
                    .collect();
                host_depth_views(&g, &vertices, &views, light.shadow.slope_bias, (w, h))
            } else {
                host_depth(
                    &g,
                    &vertices,
                    &params,
                    light.shadow.slope_bias,
                    light.shadow_map,
                )
            };
            let renderer_depth = frame
                .resources
                .iter()
                .find(|r| r.levels[0].resource == depth_name(li))
                .expect("dump holds the raster");
            let host = read_float_texture(&g.device, &g.queue, &depth, 0)
                .expect("readback")
                .1;
            let (n, worst) = differences(&host, &renderer_depth.levels[0].data);
            assert_eq!(
                n, 0,
                "{what}: host depth differs from the renderer's at {n} texels (worst {worst:e})"
            );

            // The second-depth techniques read a peeled second depth the stage takes no
            // input for: refused by name (tests/plugin_errors.rs).
            if shadowgraph::low_level::technique::peels(&light.shadow.technique) {
                continue;
            }
            let mut stage =
                Prefilter::new(&g.device, &config).unwrap_or_else(|e| panic!("{what}: {e}"));
            // The renderer's map holds every map's channels side by side (CSM: 2M channels).
            let maps = stage_maps_as_frame(&g, &mut stage, &depth, &params, light);
            let texels = (w * h) as usize;
            let concat: Vec<f32> = (0..texels)
                .flat_map(|t| {
                    maps.iter()
                        .flat_map(move |(c, d)| d[t * c..(t + 1) * c].iter().copied())
                })
                .collect();
            let (n, worst) = differences(&concat, &frame.shade_maps[li].data);
            assert_eq!(
                n, 0,
                "{what}: stage map differs at {n} values (worst {worst:e})"
            );

            let vis = host_visibility(&g, &mut stage, &depth, &params, &frame, &scene);
            let soft = soft_inputs(&g, &frame, light, li);
            let (mut covered, mut off, mut total) = (0, 0, 0.0f64);
            for (px, v) in vis.iter().enumerate() {
                if frame.position[4 * px + 3] == 0.0 {
                    continue;
                }
                covered += 1;
                let diff = f64::from((v - frame.visibility[px * lights + li]).abs());
                total += diff;
                // Every allowance is at least 1e-5: the f64 reference only where it can matter.
                if diff <= 1e-5 {
                    continue;
                }
                let allowed = match &soft {
                    Some(soft) => soft_allowance(soft, light, &frame, px),
                    None => Some(1e-5),
                };
                if allowed.is_some_and(|a| diff > a) {
                    off += 1;
                }
            }
            assert!(
                off * 1000 <= covered && total <= 1e-3 * covered as f64,
                "{what}: {off} of {covered} pixels off by > 1e-5, mean |Δ| {:e}",
                total / covered as f64
            );
        }
    }
}

/// Recording every frame reuses the pool and the pipelines; a size change reallocates (to
/// what a fresh stage holds at that size) and gives what a fresh stage gives.
#[test]
fn every_frame_reuses_textures_and_a_resize_reallocates() {
    let g = common::gpu();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/vsm.toml");
    let scene = Scene::load(path).expect("scene");
    let light = &scene.lights[0];
    let params = LightParams::from_light(light);
    let vertices = scene.vertices();
    let depth = |size| host_depth(&g, &vertices, &params, light.shadow.slope_bias, size);
    let (small, large) = (depth(96), depth(160));
    let config = PrefilterConfig::from_light(light);
    let mut stage = Prefilter::new(&g.device, &config.with_size(96)).expect("stage");
    let pipelines = stage.pipeline_count();
    let first = run_stage(&g, &mut stage, &small, &params);
    let textures = stage.texture_count();
    assert!(textures > 0);
    for frame in 0..200 {
        let mut enc = g.device.create_command_encoder(&Default::default());
        let out = stage
            .record(&g.device, &mut enc, &small, &params)
            .expect("record");
        assert_eq!(out.maps[0].texture.width(), 96);
        g.queue.submit([enc.finish()]);
        assert_eq!(stage.texture_count(), textures, "frame {frame}: pool grew");
        assert_eq!(
            stage.pipeline_count(),
            pipelines,
            "frame {frame}: pipelines made again"
        );
    }
    g.device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");

    let resized = run_stage(&g, &mut stage, &large, &params);
    let mut fresh = Prefilter::new(&g.device, &config.with_size(160)).expect("stage");
    let expected = run_stage(&g, &mut fresh, &large, &params);
    assert_eq!(stage.size(), 160);
    assert_eq!(
        stage.texture_count(),
        fresh.texture_count(),
        "old-size textures kept"
    );
    assert_eq!(
        stage.pipeline_count(),
        pipelines,
        "a resize keeps pipelines"
    );
    assert_eq!(
        differences(&resized[0], &expected[0]).0,
        0,
        "resized output"
    );
    assert_eq!(resized[0].len(), 160 * 160 * 2);

    let back = run_stage(&g, &mut stage, &small, &params);
    assert_eq!(stage.texture_count(), textures);
    assert_eq!(
        differences(&back[0], &first[0]).0,
        0,
        "back to the first size"
    );
}

/// Per-kernel timings, named by node, when the device has timestamps; otherwise asking is
/// the named missing-feature error.
#[test]
fn kernels_are_timed_when_the_device_can() {
    let g = common::gpu();
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(128)).expect("stage");
    match stage.enable_timing(&g.device, &g.queue) {
        Err(shadowgraph::Error::Stage(StageError::MissingFeature { feature, .. })) => {
            let missing = shadowgraph::TIMER_FEATURES.difference(g.device.features());
            assert!(!missing.is_empty());
            assert_eq!(feature, missing);
            return;
        }
        Err(e) => panic!("{e}"),
        Ok(()) => {}
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/vsm.toml");
    let scene = Scene::load(path).expect("scene");
    let params = LightParams::from_light(&scene.lights[0]);
    let depth = host_depth(&g, &scene.vertices(), &params, 1.0, 128);
    let _ = run_stage(&g, &mut stage, &depth, &params);
    let timings = stage.timings(&g.device).expect("timings");
    let names: Vec<&str> = timings.iter().map(|(n, _)| n.as_str()).collect();
    // The encoding linearizes the depth itself and is fused into the blur: one step.
    assert_eq!(names, ["vsm.blur"]);
    assert!(
        timings.iter().all(|(_, ms)| ms.is_finite() && *ms >= 0.0),
        "{timings:?}"
    );
}

/// A soft light's f64 inputs from the renderer's shade map (`None` for other techniques).
fn soft_inputs(
    g: &Gpu,
    frame: &Frame,
    light: &shadowgraph::Light,
    li: usize,
) -> Option<common::soft::SoftInputs> {
    light.shadow.technique.soft()?;
    let sm = &frame.shade_maps[li];
    let level0 = shadowgraph::low_level::cpu::Texels::from_f32(
        sm.width as usize,
        sm.height as usize,
        sm.channels,
        &sm.data,
    );
    common::soft::SoftInputs::new(light, &level0, common::soft_maps::trig_error(g))
}

/// How far two runs of a soft light may differ at pixel `px`: 1e-5 or twice the propagated
/// tolerance of the f64 reference, `None` where it jumps or the blocker threshold could flip.
fn soft_allowance(
    soft: &common::soft::SoftInputs,
    light: &shadowgraph::Light,
    frame: &Frame,
    px: usize,
) -> Option<f64> {
    let lg = shadowgraph::LightGpu::new(light);
    let p = &frame.position[4 * px..4 * px + 3];
    let n = &frame.normal[4 * px..4 * px + 3];
    let s = shadowgraph::low_level::cpu::light::sample(
        &lg,
        glam::DVec3::new(p[0].into(), p[1].into(), p[2].into()),
        glam::DVec3::new(n[0].into(), n[1].into(), n[2].into()).normalize(),
    );
    let v = common::robust(&s, light.shadow_map as usize, |t| soft.reference(&lg, t))?;
    soft.tolerance(&lg, &s, v).map(|t| (2.0 * t).max(1e-5))
}

/// PCSS and the soft techniques in a host's cascades, and ESM with anisotropic mips:
/// `Prefilter::fit_light_cascades` on `city_street`'s sun (four 512² cascades) gives each
/// cascade the renderer's light (planes exact; matrices to 1e-5 of their largest element, as
/// the host's light is rebuilt from inverted matrices; for PCSS and the soft techniques its
/// own `max_search` to 1e-6 and PCSS's capped filter). Drawn by the host with those matrices,
/// filtered by the stage, all four bound and shaded through the exported
/// `shadowgraph_visibility_cascaded_sun` and its footprint variant (`wgsl_cascades`: the pick
/// and the blend in WGSL), every covered pixel's visibility is the renderer's by the rule of
/// `stage_outputs_equal_the_renderers` (the host's rasters differ from the renderer's by those
/// ulps too), the soft allowance taken from the cascades the pixel reads (the f64 pick); the
/// plain function's for every technique but the anisotropic one, whose lookups follow the
/// footprint, the footprint variant's for all.
#[test]
fn stage_cascades_equal_the_renderers() {
    use shadowgraph::cascades::pick_fields;
    use shadowgraph::low_level::cpu::cascade::pick;
    use shadowgraph::low_level::render::{cascade_camera, drawn_lights};
    use shadowgraph::{Filter, Technique};
    let g = common::gpu();
    let mut renderer = Renderer::new(&g.device);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let mut scene = Scene::load(&path).expect("city_street loads");
    let vertices = scene.vertices();
    let registered = |name| shadowgraph::low_level::technique::named(name, &[]).expect("registered");
    let anisotropic = Technique::Esm {
        filter: Filter::Mips {
            width: 2.0,
            max_anisotropy: 8,
        },
        exponent: 40.0,
    };
    let techniques = [
        registered("pcss"),
        registered("vssm"),
        registered("msm_soft"),
        registered("cssm"),
        anisotropic,
    ];
    for technique in techniques {
        let name = technique.name();
        scene.lights[0].shadow.technique = technique;
        let frame = renderer
            .render(
                &g.device,
                &g.queue,
                &scene,
                RenderOptions {
                    aux: true,
                    repeat: 1,
                    dump: false,
                },
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let drawn = drawn_lights(&scene).expect("drawn lights");
        let light = &scene.lights[0];
        let config = PrefilterConfig::from_light(light);
        let mut stage = Prefilter::new(&g.device, &config).expect("stage");
        let camera = cascade_camera(&scene).expect("camera");
        let cascades = stage
            .fit_light_cascades(&camera, &LightParams::from_light(light))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(cascades.len(), 4, "{name}");
        let mut first = cascades[0].light.light_gpu(&config, config.size);
        pick_fields(&mut first, &camera, &cascades, config.cascades.blend).expect("pick");
        let index = |k: usize| {
            if k == 0 {
                0
            } else {
                drawn.groups[0].first + k - 1
            }
        };
        let mut depths = Vec::new();
        let mut soft = Vec::new();
        for (k, c) in cascades.iter().enumerate() {
            let what = format!("{name} cascade {k}");
            let theirs = &drawn.lights[index(k)];
            let r = LightParams::from_light(theirs);
            for (a, b) in [(c.light.view, r.view), (c.light.projection, r.projection)] {
                let scale = b.to_cols_array().iter().fold(1f32, |m, x| m.max(x.abs()));
                let worst = (a - b)
                    .to_cols_array()
                    .iter()
                    .fold(0f32, |m, x| m.max(x.abs()));
                assert!(worst <= 1e-5 * scale, "{what}: matrix off by {worst}");
            }
            assert_eq!(
                (c.light.near, c.light.far),
                (r.near, r.far),
                "{what}: planes"
            );
            let (ours, rg) = (c.light.light_gpu(&config, config.size), drawn.gpu[index(k)]);
            match theirs.shadow.technique.max_search() {
                Some(m) => {
                    assert!(
                        (c.light.max_search.expect("own cap") - m).abs() <= 1e-6 * m,
                        "{what}: max_search"
                    );
                    assert!(
                        (ours.max_search - rg.max_search).abs() <= 1e-6 * m,
                        "{what}"
                    );
                    assert_eq!((ours.capped_filter, rg.capped_filter), (1, 1), "{what}");
                }
                None => assert_eq!(c.light.max_search, None, "{what}: no band, no cap"),
            }
            let depth = host_depth(
                &g,
                &vertices,
                &c.light,
                light.shadow.slope_bias,
                config.size,
            );
            depths.push(depth);
            soft.push(soft_inputs(&g, &frame, theirs, index(k)));
        }
        let vis =
            host_cascaded_visibility(&g, &mut stage, &depths, &cascades, &camera, &frame, &scene);
        let lights = scene.lights.len();
        // The plain function (not for lookups that follow the footprint), then the footprint's.
        // Anisotropic lookups weight their taps by a level of detail from the footprint's
        // projection, which the host's ulp-level matrices move: 1e-4 there (measured: 668
        // pixels between 1e-5 and 1e-4, none above).
        let follows_footprint = technique == anisotropic;
        let floor = if follows_footprint { 1e-4 } else { 1e-5 };
        for (variant, offset) in [("plain", 0), ("footprint", 1)] {
            if follows_footprint && offset == 0 {
                continue;
            }
            let (mut covered, mut off, mut total) = (0, 0, 0.0f64);
            for (px, p) in frame.position.chunks_exact(4).enumerate() {
                if p[3] == 0.0 {
                    continue;
                }
                covered += 1;
                let diff = f64::from((vis[2 * px + offset] - frame.visibility[px * lights]).abs());
                total += diff;
                if diff <= floor {
                    continue;
                }
                // The allowance (an f64 reference and its tolerance) only where it is needed,
                // from the cascades the f64 pick says the pixel reads.
                let pk = pick(&first, glam::Vec3::from_slice(&p[..3]).as_dvec3());
                let read = [pk.index, (pk.index + 1).min(3)];
                let allowed = read.iter().try_fold(floor, |a, &c| match &soft[c] {
                    Some(s) => {
                        soft_allowance(s, &drawn.lights[index(c)], &frame, px).map(|t| a.max(t))
                    }
                    None => Some(a),
                });
                if allowed.is_some_and(|a| diff > a) {
                    off += 1;
                }
            }
            assert!(
                off * 1000 <= covered && total <= 1e-3 * covered as f64,
                "{name} ({variant}): {off} of {covered} pixels off, mean |Δ| {:e}",
                total / covered as f64
            );
            eprintln!(
                "{name} ({variant}): {off} of {covered} pixels off, mean |Δ| {:e}",
                total / covered as f64
            );
        }
    }
}
