//! The library functions behind the CLI's subcommands; each returns the text it prints.

use std::fmt::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::graph::cost::fetches::Fetches;
use crate::io::{deinterleave, write_exr, write_png};
use crate::kernels;
use crate::render::{DrawnLights, Frame, RenderOptions, Renderer, drawn_lights, plan_lights};
use crate::technique;
use crate::{model::Light, scene::Scene};

/// `shadowgraph plan`: the plan as text (or Graphviz with `dot`), with each light's traffic
/// per texel and its visibility function's fetches per pixel (no GPU needed).
pub fn plan(scene: &Path, dot: bool) -> Result<String> {
    let scene = Scene::load(scene)?;
    let drawn = drawn_lights(&scene)?;
    let sp = plan_lights(&drawn.lights)?;
    if dot {
        return Ok(sp.plan.to_dot());
    }
    let labels = drawn_labels(&scene, &drawn);
    let fetches = shading_fetches(&drawn.lights)?;
    let per_light = (0..drawn.lights.len())
        .map(|i| {
            let mut s = sp.plan.cost_text(i)?;
            let _ = writeln!(s, "    raster: {}", raster_passes(&sp.plan, i));
            let name = drawn.lights[i].shadow.technique.name();
            let _ = writeln!(s, "    shade: {name} {} fetches/pixel", fetches[i]);
            Ok(s)
        })
        .collect::<Result<Vec<String>>>()?;
    let mut s = warnings(&scene);
    s.push_str(&sp.plan.to_text(&labels, &per_light));
    s.push_str("then: shade (one visibility function per light)\n");
    Ok(s)
}

/// Light `i`'s raster passes: its depth, and the peel pass where the plan reads a second
/// depth ([`technique::second_depth_name`]).
fn raster_passes(plan: &crate::graph::Plan, i: usize) -> String {
    let mut s = format!("light{i}.shadow_raster -> {}", technique::depth_name(i));
    let second = technique::second_depth_name(i);
    if plan.resource(&second).is_some() {
        let _ = write!(
            s,
            ", light{i}.shadow_peel -> {second} (depth peeling: fragments at or in front of {} + {:e} discarded)",
            technique::depth_name(i),
            crate::wgsl_mirrors::PEEL_EPSILON
        );
    }
    s
}

/// One label per drawn light: a cascade names its scene light, its view-distance range and
/// its half-width (the renderer draws cascade 0 in the scene light's place and the others
/// after every scene light).
fn drawn_labels(scene: &Scene, drawn: &DrawnLights) -> Vec<String> {
    let ranges = |i: usize| -> Vec<(f32, f32)> {
        let c = scene.lights[i].shadow.cascades;
        let Ok(camera) = crate::render::cascade_camera(scene) else {
            return Vec::new();
        };
        let fars =
            crate::model::cascades::split_distances(camera.near, camera.far, c.count, c.lambda)
                .unwrap_or_default();
        let nears = std::iter::once(camera.near).chain(fars.iter().copied());
        nears.zip(fars.iter().copied()).collect()
    };
    (0..drawn.lights.len())
        .map(|k| {
            let (i, c) = drawn.owner(k);
            let light = &drawn.lights[k];
            match drawn.groups.iter().find(|g| g.light == i) {
                None => light.label(),
                Some(g) => {
                    let (near, far) = ranges(i).get(c).copied().unwrap_or((0.0, 0.0));
                    let guard = crate::technique::cascade_guard(&scene.lights[i]);
                    let band = if guard == crate::model::cascades::SliceGuard::NONE {
                        String::new()
                    } else {
                        format!(
                            ", guard band {:.3} units + {} texels",
                            guard.world, guard.texels
                        )
                    };
                    format!(
                        "{}, cascade {c} of {} of light {i} (view distances {near:.2}–{far:.2}, half-width {:.3}{band})",
                        light.label(),
                        g.count,
                        0.5 * light.width_at_unit()
                    )
                }
            }
        })
        .collect()
}

/// Per light, the texture fetches per pixel of its visibility function in the shading kernel
/// (the `// #fetches` declarations of `kernels/shared/`, composed as the scene's shading block
/// calls them; see [`crate::graph::cost::fetches`]).
pub fn shading_fetches(lights: &[Light]) -> Result<Vec<f64>> {
    let wgsl = kernels::resolve("shade", Some(&technique::shading_block(lights)))?;
    lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let gpu = crate::wgsl_mirrors::LightGpu::new(l);
            Fetches::new("shade", &wgsl, bytemuck::bytes_of(&gpu))?
                .count(&format!("light{i}_visibility"))
        })
        .collect()
}

/// `shadowgraph render`: renders, writes the PNG (and EXRs with `aux`), returns a summary.
pub fn render(
    gpu: &Gpu,
    scene_path: &Path,
    output: &Path,
    aux: Option<&Path>,
    timings: bool,
    repeat: u32,
) -> Result<String> {
    let scene = Scene::load(scene_path)?;
    // What would fail after the frames is refused before them.
    let png = output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        return Err(Error::Invalid(format!(
            "-o {}: render writes a PNG; name a `.png` file",
            output.display()
        )));
    }
    if let Some(dir) = aux {
        crate::io::make_dir(dir)?;
    }
    let mut renderer = Renderer::new(&gpu.device);
    // Timings on a GPU: untimed frames first until its clocks have risen.
    if timings {
        renderer.warm_up(&gpu.device, &gpu.queue, &scene)?;
    }
    let frame = renderer.render(
        &gpu.device,
        &gpu.queue,
        &scene,
        RenderOptions {
            aux: aux.is_some(),
            repeat,
            dump: false,
        },
    )?;
    let bad = frame.visibility.iter().filter(|v| !v.is_finite()).count();
    if bad > 0 {
        return Err(Error::Gpu {
            stage: "shade".into(),
            message: format!("{bad} non-finite visibility values"),
        });
    }
    write_png(output, frame.width, frame.height, &frame.rgba)?;
    let mut s = format!(
        "wrote {} ({}x{})\n",
        output.display(),
        frame.width,
        frame.height
    );
    for (step, n) in &frame.sanitized {
        let _ = writeln!(s, "warning: {step} replaced {n} non-finite depth texel(s)");
    }
    if let Some(dir) = aux {
        write_aux(dir, &scene, &frame)?;
        let _ = writeln!(
            s,
            "wrote position.exr, normal.exr, visibility.exr to {}",
            dir.display()
        );
    }
    if timings {
        s.push_str(&timing_table(gpu, &frame));
    }
    Ok(s)
}

/// The scene's validation warnings, one `warning:` line each.
fn warnings(scene: &Scene) -> String {
    scene
        .warnings
        .iter()
        .map(|w| format!("warning: {w}\n"))
        .collect()
}

fn write_aux(dir: &Path, scene: &Scene, frame: &Frame) -> Result<()> {
    crate::io::make_dir(dir)?;
    let (w, h) = (frame.width, frame.height);
    write_exr(
        &dir.join("position.exr"),
        w,
        h,
        deinterleave(&frame.position, 4, &["X", "Y", "Z", "coverage"]),
    )?;
    write_exr(
        &dir.join("normal.exr"),
        w,
        h,
        deinterleave(&frame.normal, 4, &["X", "Y", "Z", "material"]),
    )?;
    let names: Vec<String> = (0..scene.lights.len())
        .map(|i| format!("light{i}"))
        .collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    write_exr(
        &dir.join("visibility.exr"),
        w,
        h,
        deinterleave(&frame.visibility, scene.lights.len(), &refs),
    )
}

/// Median of each pass's time over the frames, as a table, with the frames' wall time.
pub fn timing_table(gpu: &Gpu, frame: &Frame) -> String {
    let mut s = String::new();
    if !gpu.can_time() {
        s.push_str(
            "timings: this device lacks TIMESTAMP_QUERY or TIMESTAMP_QUERY_INSIDE_ENCODERS, so \
             GPU passes cannot be timed\n",
        );
        return s;
    }
    let Some(first) = frame.timings.first() else {
        return s;
    };
    let _ = writeln!(
        s,
        "GPU time per pass (timestamps between passes), median of {} frame(s){}, on {}:",
        frame.timings.len(),
        if crate::timer::is_gpu(&gpu.device) {
            format!(" after {} ms of untimed ones", crate::timer::GPU_WARMUP_MS)
        } else {
            String::new()
        },
        gpu.describe()
    );
    let mut total = 0.0;
    for (i, (label, _)) in first.iter().enumerate() {
        let mut v: Vec<f64> = frame
            .timings
            .iter()
            .filter_map(|t| t.get(i).map(|x| x.1))
            .collect();
        let med = median(&mut v);
        total += med;
        let _ = writeln!(s, "  {label:<28} {med:>10.3} ms");
    }
    let _ = writeln!(s, "  {:<28} {total:>10.3} ms", "total");
    let mut wall = frame.wall_ms.clone();
    let _ = writeln!(
        s,
        "  {:<28} {:>10.3} ms  (submit to completion, median)",
        "wall",
        median(&mut wall)
    );
    s
}

/// The median of `v` (the upper middle value for an even count); NaN when empty.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
