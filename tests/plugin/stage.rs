//! The stage's maps and the host shader's visibility equal the renderer's; reuse, resize and
//! timings.

use super::*;

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
/// (tests/common/soft/, which models UV and depth errors of that size), so a pixel counts as
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
                // The renderer draws a cascaded light as one map per cascade (tests/scenes/
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
            // input for: refused by name (tests/plugin_errors/creation.rs).
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
