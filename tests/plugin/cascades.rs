//! A cascaded light's maps and visibility through the stage equal the renderer's.

use super::*;

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
    let registered =
        |name| shadowgraph::low_level::technique::named(name, &[]).expect("registered");
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
