//! The plug-in stage over many frames of a host: a static light is filtered once and costs no
//! dispatch while the host does not record it again, its maps staying those of a fresh filter
//! bit for bit (the same kernels over the same depth: tolerance 0); and timings the host never
//! reads are dropped, not a panic, while the frame it reads at last has its own spans.

mod common;

use std::path::Path;
use std::time::Instant;

use common::host::host_depth;
use glam::{Mat4, Vec3};
use shadowgraph::low_level::gpu::{Gpu, read_texture, submit_and_wait, take_uncaptured};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::low_level::timer::GpuTimer;
use shadowgraph::low_level::wgsl_mirrors::Vertex;
use shadowgraph::{DepthLayer, LightParams, Prefilter, PrefilterConfig};

const SIZE: u32 = 128;
/// Frames a light stays unchanged.
const STILL: usize = 4;

/// `scenes/techniques/vsm.toml` (a sphere over a plane) and a directional light orbiting it:
/// `angle` turns it about the vertical.
fn scene() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/techniques/vsm.toml");
    Scene::load(path).expect("scene")
}

fn orbiting(angle: f32) -> LightParams {
    let eye = Vec3::new(7.0 * angle.cos(), 8.0, 7.0 * angle.sin());
    LightParams::orthographic(Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y), 5.0, 2.0, 20.0)
}

/// The host's shadow maps: one `Depth32Float` layer per light.
fn shadow_array(g: &Gpu, layers: u32) -> wgpu::Texture {
    g.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host.shadows"),
        size: wgpu::Extent3d {
            width: SIZE,
            height: SIZE,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// The host's depth pass for `light` into layer `layer` of `array` (drawn into a texture of
/// its own, then copied in); returns the drawn texture.
fn draw_layer(
    g: &Gpu,
    vertices: &[Vertex],
    light: &LightParams,
    array: &wgpu::Texture,
    layer: u32,
) -> wgpu::Texture {
    let depth = host_depth(g, vertices, light, 0.0, SIZE);
    let mut enc = g.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_texture(
        depth.as_image_copy(),
        wgpu::TexelCopyTextureInfo {
            texture: array,
            mip_level: 0,
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: layer,
            },
            aspect: wgpu::TextureAspect::All,
        },
        depth.size(),
    );
    submit_and_wait(&g.device, &g.queue, enc, "host.layer").expect("copy into the layer");
    depth
}

/// The bytes of every map of `maps`.
fn bytes_of(g: &Gpu, maps: &[wgpu::Texture]) -> Vec<Vec<u8>> {
    maps.iter()
        .map(|t| read_texture(&g.device, &g.queue, t, 0).expect("readback"))
        .collect()
}

/// Bytes that differ between two sets of maps (every byte of a map whose size differs).
fn differing(a: &[Vec<u8>], b: &[Vec<u8>]) -> usize {
    assert_eq!(a.len(), b.len(), "map count");
    a.iter()
        .zip(b)
        .map(|(x, y)| match x.len() == y.len() {
            true => x.iter().zip(y).filter(|(p, q)| p != q).count(),
            false => x.len().max(y.len()),
        })
        .sum()
}

/// The maps' bytes of a fresh stage filtering `depth` for `light`, and its dispatches.
fn fresh(
    g: &Gpu,
    config: &PrefilterConfig,
    depth: &wgpu::Texture,
    light: &LightParams,
) -> (Vec<Vec<u8>>, u64) {
    let mut stage = Prefilter::new(&g.device, config).expect("stage");
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = stage
        .record(&g.device, &mut enc, depth, light)
        .expect("record");
    submit_and_wait(&g.device, &g.queue, enc, "fresh").expect("submit");
    let textures: Vec<wgpu::Texture> = out.maps.iter().map(|m| m.texture.clone()).collect();
    (bytes_of(g, &textures), stage.dispatch_count())
}

/// A static light (slot 0, layer 0) beside a moving one (slot 1, layer 1): the host records
/// the static light in the first frame and again only when it changes. Each frame's
/// dispatches are the stage's count across it: the moving light's alone while the static
/// light is unchanged, both when it changed; its maps, kept from the frame it was recorded
/// while the moving light's layer is redrawn and refiltered (and the static light's layer
/// drawn over by the host), are a fresh filter's.
#[test]
fn a_static_light_is_filtered_once_and_kept() {
    let g = common::gpu();
    let scene = scene();
    let vertices = scene.vertices();
    for config in [
        PrefilterConfig::from_light(&scene.lights[0]).with_size(SIZE),
        PrefilterConfig::vssm(SIZE, 0.5),
    ] {
        let what = config.technique.name();
        let array = shadow_array(&g, 2);
        let mut still = orbiting(0.4);
        let mut still_depth = draw_layer(&g, &vertices, &still, &array, 0);
        let (expected, per_light) = fresh(&g, &config, &still_depth, &still);
        assert!(per_light > 0, "{what}: a record dispatches nothing");

        let mut stage = Prefilter::new(&g.device, &config).expect("stage");
        let mut kept = Vec::new();
        for frame in 0..STILL + 2 {
            // The last frame moves the static light: the host says so by recording it.
            let changed = frame == 0 || frame == STILL + 1;
            if frame == STILL + 1 {
                still = orbiting(1.3);
                still_depth = draw_layer(&g, &vertices, &still, &array, 0);
            }
            let moving = orbiting(2.0 + 0.1 * frame as f32);
            draw_layer(&g, &vertices, &moving, &array, 1);
            if !changed {
                // The host draws something else into the static light's layer meanwhile.
                draw_layer(&g, &vertices, &moving, &array, 0);
            }
            let before = stage.dispatch_count();
            let mut enc = g.device.create_command_encoder(&Default::default());
            if changed {
                let out = stage
                    .record_light(0, &g.device, &mut enc, DepthLayer::new(&array, 0), &still)
                    .expect("record the static light");
                kept = out.maps.iter().map(|m| m.texture.clone()).collect();
            }
            stage
                .record_light(1, &g.device, &mut enc, DepthLayer::new(&array, 1), &moving)
                .expect("record the moving light");
            submit_and_wait(&g.device, &g.queue, enc, "frame").expect("submit");
            let lights = if changed { 2 } else { 1 };
            assert_eq!(
                stage.dispatch_count() - before,
                lights * per_light,
                "{what}: frame {frame}'s dispatches ({lights} light(s) recorded)"
            );
            if frame == STILL {
                let off = differing(&bytes_of(&g, &kept), &expected);
                assert_eq!(
                    off, 0,
                    "{what}: the static light's maps after {STILL} frames"
                );
            }
        }
        let (changed, _) = fresh(&g, &config, &still_depth, &still);
        assert!(
            differing(&changed, &expected) > 0,
            "{what}: the change changed nothing"
        );
        let off = differing(&bytes_of(&g, &kept), &changed);
        assert_eq!(off, 0, "{what}: refiltered after the change");
    }
}

/// Ten frames with timing on and the timings never read: no panic or device error, whichever
/// state an unread frame's readback is in when the ring of three comes back to it: its
/// mapping still pending (frame 0's, requested at once, taken back by frame 3 before anything
/// polls the device: frames 1–3 are submitted after it), only its copy recorded (frames 1–3,
/// taken back by frames 4–6: no mapping requested meanwhile), or mapped (frames 4–6, mapped
/// after frame 6 and taken back by frames 7–9). The frame read at last is the
/// last one, with its own spans, each a positive time within the wall clock of its submission.
#[test]
fn unread_timings_are_dropped() {
    let g = common::gpu();
    // A device without timestamps between passes cannot run this test: it fails rather than
    // passing without having checked anything.
    assert!(
        g.can_time(),
        "the device writes no timestamps between passes: this test needs them"
    );
    let work = |size: u64| {
        g.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timed.work"),
            size,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let (from, to) = (work(8 << 20), work(8 << 20));
    let mut timer = GpuTimer::new(&g.device, &g.queue, 2).expect("a timer");
    let frames = 10;
    let mut wall_ms = 0.0;
    let mut held = Vec::new();
    for frame in 0..frames {
        timer.reset();
        let mut enc = g.device.create_command_encoder(&Default::default());
        timer.begin(&mut enc, &format!("frame{frame}.copy"));
        enc.copy_buffer_to_buffer(&from, 0, &to, 0, None);
        timer.begin(&mut enc, &format!("frame{frame}.clear"));
        enc.clear_buffer(&to, 0, None);
        timer.resolve(&mut enc);
        held.push(enc);
        if frame == 1 || frame == 2 {
            continue;
        }
        let start = Instant::now();
        for enc in held.drain(..) {
            submit_and_wait(&g.device, &g.queue, enc, "timed").expect("a frame");
        }
        wall_ms = start.elapsed().as_secs_f64() * 1e3;
        match frame {
            0 => timer.submitted(),
            6..=8 => {
                timer.submitted();
                g.device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .expect("poll");
            }
            _ => {}
        }
    }
    take_uncaptured(&g.device).expect("no device error");
    let spans = timer.read(&g.device).expect("the last frame's timings");
    let last = frames - 1;
    let names: Vec<&str> = spans.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [format!("frame{last}.copy"), format!("frame{last}.clear")]
    );
    let total: f64 = spans.iter().map(|(_, ms)| ms).sum();
    assert!(
        spans.iter().all(|(_, ms)| ms.is_finite() && *ms > 0.0) && total <= wall_ms,
        "{spans:?} in a submission of {wall_ms} ms"
    );
    assert!(
        timer.finish(&g.device).expect("nothing left").is_empty(),
        "frames read twice"
    );
}

/// The stage's own timer through ten frames the host never reads (the failure a host met:
/// a panic at the fourth record), then a read of the last one.
#[test]
fn a_stage_timed_and_never_read_records_on() {
    let g = common::gpu();
    let mut stage = Prefilter::new(&g.device, &PrefilterConfig::vsm(SIZE)).expect("stage");
    if let Err(e) = stage.enable_timing(&g.device, &g.queue) {
        panic!("the stage cannot time on this device, which this test needs: {e}");
    }
    let scene = scene();
    let light = orbiting(0.4);
    let depth = host_depth(&g, &scene.vertices(), &light, 0.0, SIZE);
    for frame in 0..10 {
        let mut enc = g.device.create_command_encoder(&Default::default());
        stage
            .record(&g.device, &mut enc, &depth, &light)
            .unwrap_or_else(|e| panic!("frame {frame}: {e}"));
        submit_and_wait(&g.device, &g.queue, enc, "frame")
            .unwrap_or_else(|e| panic!("frame {frame}: {e}"));
    }
    let timings = stage.timings(&g.device).expect("timings");
    let names: Vec<&str> = timings.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["vsm.blur"]);
    assert!(
        timings[0].1.is_finite() && timings[0].1 > 0.0,
        "{timings:?}"
    );
}
