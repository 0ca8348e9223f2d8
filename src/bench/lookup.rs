//! The shading pass's lookup cost as the filter widens: PCF against summed-area tables.

use std::fmt::Write;

use super::harness::median;
use super::{GPU_WARMUP_MS, WARMUP};
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::model::SatVariant;
use crate::model::{Filter, Storage, StorageFilter, Technique};

/// The scene the lookup-cost benchmark shades: `scenes/techniques/vsm.toml` (built-in shapes
/// only), embedded so the benchmark runs from anywhere.
const LOOKUP_SCENE: &str = include_str!("../../scenes/techniques/vsm.toml");

/// Default filter widths of [`lookup_cost`]: 3×3 to 65×65 texels.
pub const LOOKUP_WIDTHS: &[u32] = &[3, 5, 9, 17, 33, 65];

/// One filter width of the lookup-cost benchmark: the shading pass's median GPU time with a
/// `width × width` PCF box and with VSM through summed-area tables of the same box.
#[derive(Clone, Debug, PartialEq)]
pub struct LookupRow {
    /// Filter width in texels (odd: PCF's window is `2r + 1`).
    pub width: u32,
    /// Shading pass, PCF box of `width²` taps, ms.
    pub pcf_ms: f64,
    /// Shading pass, VSM through the u32 fixed-point table (16 loads per channel), ms.
    pub sat_fixed_ms: f64,
    /// Shading pass, VSM through the f32 table, ms.
    pub sat_float_ms: f64,
    /// Building the fixed-point table (its passes), ms.
    pub sat_build_ms: f64,
    /// The image it was shaded at, width × height.
    pub image: (u32, u32),
    /// The light's shadow-map size it read, texels a side.
    pub map: u32,
}

/// The shading pass's cost as the filter widens: for each width in `widths`, the median over
/// `repeat` frames (after [`WARMUP`], on a GPU at least [`super::GPU_WARMUP_MS`] of them) of the `shade` pass of the VSM technique scene rendered
/// with a PCF box of that width and with VSM read through summed-area tables of that box.
/// PCF's taps grow with the square of the width; the table's lookups stay at four per channel
/// (sixteen with sub-texel edges) whatever the width.
///
/// `image` shades at that size instead of the scene's 400×300 (a GPU's shading pass at that
/// size is close to its launch floor), and `map` renders the light's shadow map at that size
/// instead of the scene's 512².
pub fn lookup_cost(
    gpu: &Gpu,
    widths: &[u32],
    repeat: u32,
    image: Option<(u32, u32)>,
    map: Option<u32>,
) -> Result<Vec<LookupRow>> {
    if widths.is_empty() || repeat == 0 {
        return Err(Error::Invalid(
            "lookup benchmark needs widths and repeat ≥ 1".into(),
        ));
    }
    if let Some(w) = widths.iter().find(|&&w| w == 0 || w % 2 == 0 || w > 65) {
        return Err(Error::Invalid(format!(
            "lookup benchmark width {w}: widths are odd, 1 to 65 (PCF windows are 2r + 1 wide, r ≤ 32)"
        )));
    }
    if !gpu.can_time() {
        return Err(Error::Invalid(
            "this device cannot time kernels: it lacks TIMESTAMP_QUERY or \
             TIMESTAMP_QUERY_INSIDE_ENCODERS"
                .to_string(),
        ));
    }
    super::check_map(&gpu.device, map, image)?;
    let scene = crate::scene::Scene::parse(
        std::path::Path::new("scenes/techniques/vsm.toml"),
        LOOKUP_SCENE,
    )?;
    let base = super::with_flags(scene, map, image);
    let mut renderer = crate::render::Renderer::new(&gpu.device);
    let mut shade = |technique: Technique| -> Result<(f64, f64)> {
        let mut scene = base.clone();
        scene.lights[0].shadow.technique = technique;
        let by = format!("bench --lookup's `{}` configuration", technique.name());
        scene.locations.set_by("light[0].shadow", by);
        // On a GPU, untimed frames until its clocks have risen; then the WARMUP frames below
        // as on any device.
        renderer.warm_up(&gpu.device, &gpu.queue, &scene)?;
        let frame = renderer.render(
            &gpu.device,
            &gpu.queue,
            &scene,
            crate::render::RenderOptions {
                aux: false,
                repeat: WARMUP + repeat,
                dump: false,
            },
        )?;
        let pass = |frame_timings: &[(String, f64)], f: &dyn Fn(&str) -> bool| -> f64 {
            frame_timings
                .iter()
                .filter(|(name, _)| f(name))
                .map(|(_, ms)| ms)
                .sum()
        };
        let timed = &frame.timings[WARMUP as usize..];
        let mut shade: Vec<f64> = timed.iter().map(|t| pass(t, &|n| n == "shade")).collect();
        let mut table: Vec<f64> = timed
            .iter()
            .map(|t| pass(t, &|n| n.contains(".sat")))
            .collect();
        Ok((median(&mut shade), median(&mut table)))
    };
    let vsm = |variant, width: u32| Technique::Vsm {
        prefilter: StorageFilter {
            storage: Storage::F32,
            filter: Filter::Sat {
                width: width as f32,
                variant,
            },
        },
        bleed: 0.2,
        min_variance: 1e-5,
    };
    let mut rows = Vec::new();
    for &width in widths {
        let (pcf_ms, _) = shade(Technique::Pcf {
            radius: (width - 1) / 2,
            kernel: crate::model::PcfKernel::Box,
        })?;
        let (sat_fixed_ms, sat_build_ms) = shade(vsm(SatVariant::Fixed, width))?;
        let (sat_float_ms, _) = shade(vsm(SatVariant::Float, width))?;
        rows.push(LookupRow {
            width,
            pcf_ms,
            sat_fixed_ms,
            sat_float_ms,
            sat_build_ms,
            image: (base.width, base.height),
            map: base.lights[0].shadow_map,
        });
    }
    Ok(rows)
}

/// [`lookup_cost`]'s report: one line per width, times and each over the narrowest width's
/// (on a CPU adapter only those ratios mean anything).
pub fn format_lookup_table(device: &str, cpu: bool, repeat: u32, rows: &[LookupRow]) -> String {
    let mut s = String::new();
    let ((w, h), map) = rows.first().map_or(((0, 0), 0), |r| (r.image, r.map));
    let _ = writeln!(s, "shading-pass lookup cost on {device}");
    let _ = writeln!(
        s,
        "scenes/techniques/vsm.toml ({w}×{h}, {map}² map); GPU timestamps of the shade pass, median \
         of {repeat} frame(s) after {WARMUP} warm-up frame(s) (on a GPU, at least {GPU_WARMUP_MS} ms); (×) = over the first width's time."
    );
    if cpu {
        let _ = writeln!(
            s,
            "NOTE: this adapter is a CPU device (software Vulkan): only the ratios mean anything."
        );
    }
    let _ = writeln!(
        s,
        "{:>7}  {:>10} {:>7}  {:>12} {:>7}  {:>12} {:>7}  {:>13}",
        "width", "pcf ms", "(×)", "sat u32 ms", "(×)", "sat f32 ms", "(×)", "table build ms"
    );
    let first = rows.first();
    for r in rows {
        let ratio = |v: f64, f: fn(&LookupRow) -> f64| first.map_or(f64::NAN, |r0| v / f(r0));
        let _ = writeln!(
            s,
            "{:>4}²   {:>10.3} {:>7.2}  {:>12.3} {:>7.2}  {:>12.3} {:>7.2}  {:>13.3}",
            r.width,
            r.pcf_ms,
            ratio(r.pcf_ms, |r| r.pcf_ms),
            r.sat_fixed_ms,
            ratio(r.sat_fixed_ms, |r| r.sat_fixed_ms),
            r.sat_float_ms,
            ratio(r.sat_float_ms, |r| r.sat_float_ms),
            r.sat_build_ms,
        );
    }
    s
}
