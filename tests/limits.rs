//! Device limits and memory are checked before anything is created: each error is one line
//! naming the scene file, the key that would fix it and its line (never wgpu's validation text),
//! and nothing was allocated. Errors wgpu raises outside an error scope fail the next submit.

mod common;

use std::path::Path;

use shadowgraph::Error;
use shadowgraph::low_level::render::{RenderOptions, Renderer, plan_lights};
use shadowgraph::low_level::scene::Scene;

const HEADER: &str = "[output]\nwidth = WIDTH\nheight = HEIGHT\n\n[camera]\n\
position = [0.0, 3.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_degrees = 45.0\n";

const OBJECTS: &str = "\n[[object]]\nshape = \"plane\"\nsize = 8.0\n\n[[object]]\nshape = \"box\"\n\
size = 1.0\ntranslate = [0.0, 0.5, 0.0]\n";

/// A directional light with `shadow` as its `[light.shadow]` body.
fn light(map: u32, shadow: &str) -> String {
    format!(
        "\n[[light]]\nkind = \"directional\"\nposition = [-3.0, 6.0, 2.0]\ntarget = [0.0, 0.0, 0.0]\n\
         extent = 4.0\nshadow_map = {map}\n\n[light.shadow]\n{shadow}\n"
    )
}

fn scene(width: u32, height: u32, lights: &[String]) -> (String, Scene) {
    let text = HEADER
        .replace("WIDTH", &width.to_string())
        .replace("HEIGHT", &height.to_string())
        + &lights.concat()
        + OBJECTS;
    let s = Scene::parse(Path::new("limits.toml"), &text).unwrap_or_else(|e| panic!("{e}"));
    (text, s)
}

/// 1-based line of the `n`-th (0-based) line of `text` that starts with `prefix`.
fn nth_line(text: &str, prefix: &str, n: usize) -> usize {
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with(prefix))
        .nth(n)
        .map(|(i, _)| i + 1)
        .unwrap_or_else(|| panic!("no {n}th `{prefix}`"))
}

/// Renders expecting a refusal before anything was created: one line starting with
/// `limits.toml:<line>:` and holding every needle; returns the message.
#[track_caller]
fn refused(
    g: &shadowgraph::low_level::gpu::Gpu,
    s: &Scene,
    opts: RenderOptions,
    line: usize,
    needles: &[&str],
) {
    let mut r = Renderer::new(&g.device);
    let shown = match r.render(&g.device, &g.queue, s, opts) {
        Ok(_) => panic!("rendered; expected a refusal at line {line}"),
        Err(e) => e.to_string(),
    };
    assert!(!shown.contains('\n'), "more than one line: {shown}");
    assert!(
        shown.starts_with(&format!("limits.toml:{line}:")),
        "wrong place: {shown}"
    );
    for n in needles {
        assert!(shown.contains(n), "`{n}` missing from: {shown}");
    }
    assert_eq!(
        (r.executor.kernels.len(), r.executor.texture_count()),
        (0, 0),
        "pipelines or textures were created before the refusal: {shown}"
    );
    shadowgraph::low_level::gpu::take_uncaptured(&g.device).expect("no uncaptured wgpu error");
}

/// A device with WebGPU's default sampled-texture and storage-binding limits (16 and
/// 128 MiB), whatever the adapter offers: a datacenter GPU allows 524288 sampled textures
/// and 2 GiB bindings, so the refusals below would need scenes no test can build.
fn webgpu_limits() -> shadowgraph::low_level::gpu::Gpu {
    let webgpu = wgpu::Limits::default();
    shadowgraph::low_level::gpu::Gpu::with_limits(|l| {
        l.max_sampled_textures_per_shader_stage = webgpu.max_sampled_textures_per_shader_stage;
        l.max_storage_buffer_binding_size = webgpu.max_storage_buffer_binding_size;
    })
    .unwrap_or_else(|e| panic!("GPU tests need an adapter (lavapipe on CI): {e}"))
}

/// 32 lights of mixed techniques sample more textures than a shader stage may: the error
/// names the first light that does not fit, at its `[[light]]` line.
#[test]
fn many_lights_exceed_the_sampled_textures_per_stage() {
    let g = webgpu_limits();
    let limit = g.device.limits().max_sampled_textures_per_shader_stage as usize;
    // CSM with 4 terms binds ⌈4/2⌉ = 2 maps, the others one each; the G-buffer two more.
    let kinds = [
        "technique = \"csm\"\nterms = 4",
        "technique = \"pcf\"",
        "technique = \"vsm\"",
        "technique = \"msm\"",
    ];
    let maps = [2, 1, 1, 1];
    let lights: Vec<String> = (0..32).map(|i| light(64, kinds[i % 4])).collect();
    let (text, s) = scene(64, 48, &lights);
    let mut count = 2;
    let first = (0..32)
        .find(|&i| {
            count += maps[i % 4];
            count > limit
        })
        .expect("the scene must exceed the device's limit");
    let needles = [
        &format!("light[{first}]")[..],
        "max_sampled_textures_per_shader_stage",
    ];
    refused(
        &g,
        &s,
        RenderOptions::default(),
        nth_line(&text, "[[light]]", first),
        &needles,
    );
}

/// The visibility buffer (4 bytes per pixel per light) past the storage-binding limit.
#[test]
fn large_outputs_exceed_the_storage_buffer_binding() {
    let g = webgpu_limits();
    let binding = g.device.limits().max_storage_buffer_binding_size;
    for (w, h, n) in [(8192, 4097, 1), (4096, 4096, 3)] {
        assert!(
            u64::from(w) * u64::from(h) * n * 4 > binding,
            "{w}x{h}x{n} fits"
        );
        let lights: Vec<String> = (0..n).map(|_| light(64, "technique = \"hard\"")).collect();
        let (text, s) = scene(w, h, &lights);
        let line = nth_line(&text, "width", 0);
        refused(
            &g,
            &s,
            RenderOptions::default(),
            line,
            &["output.width", "max_storage_buffer_binding_size"],
        );
    }
}

/// A 16384² map with a summed-area table (4 GiB for the table alone) is past the default
/// memory budget; so is a 16384² PCF map read back with `aux`. Nothing is allocated.
#[test]
fn large_maps_exceed_the_memory_budget() {
    let g = common::gpu();
    if std::env::var_os(shadowgraph::low_level::limits::MEMORY_BUDGET_ENV).is_some() {
        panic!(
            "unset {} to run this test",
            shadowgraph::low_level::limits::MEMORY_BUDGET_ENV
        );
    }
    let max = g.device.limits().max_texture_dimension_2d.min(16384);
    let (text, s) = scene(
        64,
        48,
        &[light(max, "technique = \"msm\"\nfilter = \"sat\"")],
    );
    let line = nth_line(&text, "shadow_map", 0);
    refused(
        &g,
        &s,
        RenderOptions::default(),
        line,
        &["light[0].shadow_map", "memory budget"],
    );
    let (text, s) = scene(64, 48, &[light(max, "technique = \"pcf\"")]);
    let aux = RenderOptions {
        aux: true,
        repeat: 1,
        dump: false,
    };
    refused(
        &g,
        &s,
        aux,
        nth_line(&text, "shadow_map", 0),
        &["light[0].shadow_map", "memory budget"],
    );
}

/// A cascaded light past the budget is named as the scene file's light, with its line and its
/// cascades (`city_street`'s light in eight 4096² `cssm` cascades: 10.7 GiB), not as the drawn
/// cascade that holds the most (`light[7]`, which the file does not have).
#[test]
fn cascades_past_the_memory_budget_name_their_light() {
    let g = common::gpu();
    if std::env::var_os(shadowgraph::low_level::limits::MEMORY_BUDGET_ENV).is_some() {
        panic!(
            "unset {} to run this test",
            shadowgraph::low_level::limits::MEMORY_BUDGET_ENV
        );
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/city_street.toml");
    let text = std::fs::read_to_string(&path)
        .expect("city_street")
        .replace("shadow_map = 512", "shadow_map = 4096")
        .replace("cascades = 4", "cascades = 8")
        .replace("technique = \"pcf\"\nradius = 1", "technique = \"cssm\"");
    let s = Scene::parse(std::path::Path::new("limits.toml"), &text).expect("parses");
    assert_eq!(s.lights[0].shadow.cascades.count, 8);
    refused(
        &g,
        &s,
        RenderOptions::default(),
        nth_line(&text, "shadow_map", 0),
        &[
            "`light[0]`'s 8 cascades of 4096² maps",
            "light[0].shadow_map",
            "memory budget",
        ],
    );
}

/// The memory estimate of a PCF frame, counted by hand: the depth map and the linear map
/// (4 bytes a texel each), the G-buffer (16 + 16 + 4 bytes a pixel), colour (4), visibility
/// (4 per light), the vertices (28 bytes each) and the colour and visibility read-backs
/// (staging buffer and host copy).
#[test]
fn memory_estimate_is_the_sum_of_its_parts() {
    let (_, s) = scene(64, 48, &[light(512, "technique = \"pcf\"")]);
    let sp = plan_lights(&s.lights).unwrap();
    let m = shadowgraph::low_level::limits::render_memory(&s, &sp.plan, &RenderOptions::default());
    let vertices: u64 = s.objects.iter().map(|o| o.mesh.indices.len() as u64).sum();
    let pixels = 64 * 48;
    let frame = pixels * (16 + 16 + 4 + 4 + 4) + 28 * vertices + 2 * pixels * (4 + 4);
    let maps = 2 * 512 * 512 * 4;
    assert_eq!(m.frame, frame);
    assert_eq!(m.lights, vec![maps]);
    assert_eq!(m.total, frame + maps);
}

/// A point light's atlas is three faces wide and two high: its side past the device's largest
/// texture side is named by the face size's key and line (a 1024 face is 3072 texels wide,
/// past a 2048 limit that the face itself fits), and its memory is the atlas's.
#[test]
fn a_point_lights_atlas_is_checked_whole() {
    let point =
        "\n[[light]]\nkind = \"point\"\nposition = [0.0, 3.0, 0.0]\nnear = 0.2\nfar = 20.0\n\
                 shadow_map = 1024\n\n[light.shadow]\ntechnique = \"pcf\"\n"
            .to_string();
    let (text, s) = scene(64, 48, &[point]);
    let sp = plan_lights(&s.lights).unwrap();
    let limits = wgpu::Limits {
        max_texture_dimension_2d: 2048,
        ..wgpu::Limits::default()
    };
    let shown = shadowgraph::low_level::limits::check_scene(
        &s,
        &sp,
        &limits,
        wgpu::Features::empty(),
        &RenderOptions::default(),
        1 << 30,
        &[],
    )
    .expect_err("a 3072-wide atlas on a 2048 device")
    .to_string();
    let line = nth_line(&text, "shadow_map", 0);
    assert!(
        shown.starts_with(&format!("limits.toml:{line}:"))
            && shown.contains("light[0].shadow_map` = 1024")
            && shown.contains("3072 texels wide")
            && shown.contains("max_texture_dimension_2d"),
        "{shown}"
    );
    let m = shadowgraph::low_level::limits::render_memory(&s, &sp.plan, &RenderOptions::default());
    // The atlas's depth and its linear map (PCF reads the linear depth).
    assert_eq!(m.lights, vec![2 * 3072 * 2048 * 4]);
}

/// CSSM's fixed-point tables interleaved in one texture five times as wide as the map
/// (`technique::basis_interleave`, as many as fit in 8192 texels): a device whose largest
/// side is under that is told which texture and the map size's key and line, not wgpu's
/// validation text; the map alone fits it.
#[test]
fn interleaved_tables_past_the_largest_side_name_the_map_size() {
    let cssm = light(1024, "technique = \"cssm\"\nterms = 8")
        .replace("shadow_map", "size = 0.5\nshadow_map");
    let (text, s) = scene(64, 48, &[cssm]);
    let sp = plan_lights(&s.lights).unwrap();
    let check = |max: u32| {
        let limits = wgpu::Limits {
            max_texture_dimension_2d: max,
            ..wgpu::Limits::default()
        };
        shadowgraph::low_level::limits::check_scene(
            &s,
            &sp,
            &limits,
            wgpu::Features::empty(),
            &RenderOptions::default(),
            1 << 30,
            &[],
        )
        .map_err(|e| e.to_string())
    };
    check(8192).expect("5120 texels wide fit 8192");
    let shown = check(4096).expect_err("5120 texels wide on a 4096 device");
    let line = nth_line(&text, "shadow_map", 0);
    assert!(
        shown.starts_with(&format!("limits.toml:{line}:"))
            && shown.contains("light0.csm.sat.layers0")
            && shown.contains("5120")
            && shown.contains("max_texture_dimension_2d")
            && shown.contains("light[0].shadow_map"),
        "{shown}"
    );
}

/// A second-depth light counts its peeled second depth map too: two depth maps and the
/// comparison map, by hand.
#[test]
fn memory_estimate_counts_the_second_depth() {
    for technique in ["midpoint", "second_depth"] {
        let (_, s) = scene(
            64,
            48,
            &[light(512, &format!("technique = \"{technique}\""))],
        );
        let sp = plan_lights(&s.lights).unwrap();
        let m =
            shadowgraph::low_level::limits::render_memory(&s, &sp.plan, &RenderOptions::default());
        assert_eq!(m.lights, vec![3 * 512 * 512 * 4], "{technique}");
    }
}

/// Checks without a device: lowered limits and a small budget name the key and its line.
#[test]
fn lowered_limits_and_budgets_name_the_key() {
    let (text, s) = scene(
        64,
        48,
        // A summed-area table: its tile passes need workgroup memory (the blur needs none).
        &[light(
            2048,
            "technique = \"vsm\"\nfilter = \"sat\"\nfilter_width = 5.0",
        )],
    );
    let sp = plan_lights(&s.lights).unwrap();
    let full = wgpu::Limits::default();
    let check = |l: &wgpu::Limits, f: wgpu::Features, budget: u64| {
        shadowgraph::low_level::limits::check_scene(
            &s,
            &sp,
            l,
            f,
            &RenderOptions::default(),
            budget,
            &[],
        )
        .map_err(|e| e.to_string())
    };
    check(&full, wgpu::Features::empty(), 1 << 30).expect("fits");
    let cases = [
        (
            wgpu::Limits {
                max_texture_dimension_2d: 1024,
                ..full.clone()
            },
            1 << 30,
            "shadow_map",
            "max_texture_dimension_2d",
        ),
        (
            wgpu::Limits {
                max_compute_workgroup_storage_size: 1024,
                ..full.clone()
            },
            1 << 30,
            "technique",
            "max_compute_workgroup_storage_size",
        ),
        (full.clone(), 8 << 20, "shadow_map", "memory budget"),
    ];
    for (limits, budget, key, needle) in cases {
        let shown = check(&limits, wgpu::Features::empty(), budget).expect_err(needle);
        let line = nth_line(&text, key, 0);
        assert!(
            shown.starts_with(&format!("limits.toml:{line}:")) && shown.contains(needle),
            "{needle}: {shown}"
        );
    }
    let (text, s) = scene(
        64,
        48,
        &[light(256, "technique = \"msm\"\nformat = \"unorm16\"")],
    );
    let sp = plan_lights(&s.lights).unwrap();
    let shown = shadowgraph::low_level::limits::check_scene(
        &s,
        &sp,
        &full,
        wgpu::Features::empty(),
        &RenderOptions::default(),
        1 << 30,
        &[],
    )
    .expect_err("unorm16 without the feature")
    .to_string();
    let line = nth_line(&text, "format", 0);
    assert!(
        shown.starts_with(&format!("limits.toml:{line}:"))
            && shown.contains("TEXTURE_FORMAT_16BIT_NORM"),
        "{shown}"
    );
    // A soft technique's f32 tables are read with filtered fetches: without FLOAT32_FILTERABLE
    // the scene is refused at its `sat_sums` line (with the feature, the same scene passes).
    let (text, s) = scene(
        64,
        48,
        &[light(256, "technique = \"vssm\"\nsat_sums = \"float\"")
            .replace("extent = 4.0", "extent = 4.0\nsize = 0.5")],
    );
    let sp = plan_lights(&s.lights).unwrap();
    let check_with = |features| {
        shadowgraph::low_level::limits::check_scene(
            &s,
            &sp,
            &full,
            features,
            &RenderOptions::default(),
            1 << 30,
            &[],
        )
    };
    let shown = check_with(wgpu::Features::empty())
        .expect_err("f32 tables without the feature")
        .to_string();
    let line = nth_line(&text, "sat_sums", 0);
    assert!(
        shown.starts_with(&format!("limits.toml:{line}:")) && shown.contains("FLOAT32_FILTERABLE"),
        "{shown}"
    );
    check_with(wgpu::Features::FLOAT32_FILTERABLE).expect("f32 tables with the feature");
}

/// A wgpu error raised outside any error scope (here a zero-sized texture) used to be logged
/// while the work went on; now the next submit returns it as one error of one line.
#[test]
fn uncaptured_errors_fail_the_next_submit() {
    let g = common::gpu();
    let _bad = g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("zero"),
        size: wgpu::Extent3d {
            width: 0,
            height: 4,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let enc = g.device.create_command_encoder(&Default::default());
    match shadowgraph::low_level::gpu::submit_and_wait(&g.device, &g.queue, enc, "test") {
        Err(e @ Error::Gpu { .. }) => {
            let shown = e.to_string();
            assert!(!shown.contains('\n') && shown.contains("zero"), "{shown}");
        }
        Err(e) => panic!("expected a GPU error, got {e}"),
        Ok(()) => panic!("an uncaptured wgpu error passed as a success"),
    }
    // Reported once: the next submit is clean.
    let enc = g.device.create_command_encoder(&Default::default());
    shadowgraph::low_level::gpu::submit_and_wait(&g.device, &g.queue, enc, "test").expect("clean");
}
