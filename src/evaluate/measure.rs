//! One configuration's measurement: its render, its errors against the truth (whole, by
//! region, perceptual) and against the PCF truth, its times and memory.

use glam::DVec3;

use super::flip::{Shader, flip_map, flip_stats};
use super::stats::{ErrorStats, Region, Regions, laplacian_rms};
use super::{Config, Measurement, PlanCost, storage_name};
use crate::cpu::Map;
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::render::{FloatMap, Frame, RenderOptions, Renderer, plan_lights};
use crate::truth::Truth;
use crate::truth::pcf::{Receiver, pcf_box};
use crate::wgsl_mirrors::LightGpu;
use crate::{
    model::{Filter, Technique},
    scene::Scene,
};

/// What every configuration is measured against: the truth, its regions and its shading.
pub struct Reference {
    /// The area-light truth.
    pub truth: Truth,
    /// Its visibility in f64.
    truth64: Vec<f64>,
    /// Its penumbra, umbra and lit regions.
    pub regions: Regions,
    /// The masks of [`Region::Penumbra`], [`Region::Umbra`], [`Region::Lit`].
    masks: [Vec<bool>; 3],
    /// The scene's shading.
    shader: Shader,
}

impl Reference {
    /// The reference of `scene` from its `truth`.
    pub fn new(scene: &Scene, truth: Truth) -> Self {
        let regions = Regions::new(
            &truth.visibility,
            &truth.mask,
            truth.width as usize,
            truth.height as usize,
            truth.lights,
        );
        let masks = [Region::Penumbra, Region::Umbra, Region::Lit].map(|r| regions.mask(r));
        Self {
            truth64: truth.visibility.iter().map(|&v| f64::from(v)).collect(),
            truth,
            regions,
            masks,
            shader: Shader::new(scene),
        }
    }

    /// Pixels in the penumbra, umbra and lit regions.
    pub fn region_pixels(&self) -> [usize; 3] {
        self.masks
            .each_ref()
            .map(|m| m.iter().filter(|&&b| b).count())
    }
}

/// One configuration measured: its row, its frame and both shaded images.
pub struct Measured {
    /// The report's row.
    pub row: Measurement,
    /// The last rendered frame.
    pub frame: Frame,
    /// The frame's G-buffer shaded with the frame's visibility (RGB8).
    pub shaded: Vec<u8>,
    /// The same G-buffer shaded with the truth's visibility (RGB8).
    pub truth_shaded: Vec<u8>,
}

/// Renders one frame of a configuration and measures its errors, memory and plan cost; its
/// times are filled later by the time protocol (`timing::fill`).
pub fn measure(
    renderer: &mut Renderer,
    gpu: &Gpu,
    scene: &Scene,
    c: &Config,
    linear: &[FloatMap],
    reference: &Reference,
) -> Result<Measured> {
    let truth = &reference.truth;
    let frame = renderer.render(
        &gpu.device,
        &gpu.queue,
        scene,
        RenderOptions {
            aux: true,
            repeat: 1,
            dump: false,
        },
    )?;
    if frame.visibility.len() != truth.visibility.len() {
        return Err(Error::Invalid("truth and render differ in size".into()));
    }
    let stats = |mask: &[bool]| ErrorStats::new(&frame.visibility, &reference.truth64, mask);
    let soft = stats(&truth.mask);
    let [penumbra, umbra, lit] = reference.masks.each_ref().map(|m| stats(m));
    let (penumbra_hf, _) = laplacian_rms(
        &frame.visibility,
        &reference.truth64,
        &reference.masks[0],
        &truth.mask,
        frame.width as usize,
        frame.height as usize,
        truth.lights,
    );
    let shade = |v: &[f32]| reference.shader.image(&frame.position, &frame.normal, v);
    let (shaded, truth_shaded) = (shade(&frame.visibility), shade(&truth.visibility));
    let flip = flip_stats(&flip_map(&truth_shaded, &shaded, frame.width, frame.height));
    let pcf = match c.box_width {
        Some(w) => Some(pcf_stats(scene, &frame, linear, truth, w)?),
        None => None,
    };
    // The lights the frame drew: a cascaded light's every cascade, each with its own maps.
    let drawn = crate::render::drawn_lights(scene)?;
    let plan = plan_lights(&drawn.lights)?;
    let cost = plan_cost(&plan.plan, &drawn.lights)?;
    // The rasterized maps the plan imports (one depth per drawn light, two where it peels).
    let depth: u64 = plan
        .plan
        .resources
        .iter()
        .filter(|r| r.resource.imported)
        .map(|r| r.bytes)
        .sum();
    let (storage, filter) = match (c.technique.storage(), c.technique.filter()) {
        (Some(storage), Some(filter)) => (storage_name(storage).to_string(), filter_name(filter)),
        _ => (String::new(), String::new()),
    };
    let row = Measurement {
        label: c.label.clone(),
        technique: c.technique.name().to_string(),
        family: super::verdict::Family::of(&c.technique).name().to_string(),
        shadow_map: c.shadow_map,
        storage,
        filter,
        box_width: c.box_width,
        passes: Vec::new(),
        raster_ms: None,
        kernels_ms: None,
        shade_ms: None,
        total_ms: None,
        gbuffer_ms: None,
        wall_ms: None,
        total_spread: None,
        retries: 0,
        clock_off: false,
        check_ratio: None,
        memory_bytes: plan.plan.peak_live_bytes() + depth,
        cost,
        soft,
        penumbra,
        penumbra_hf,
        umbra,
        lit,
        flip,
        pcf,
        temporal: None,
    };
    Ok(Measured {
        row,
        frame,
        shaded,
        truth_shaded,
    })
}

fn filter_name(f: Filter) -> String {
    match f {
        Filter::None => "none",
        Filter::Blur { .. } => "blur",
        Filter::Mips { .. } => "mips",
        Filter::Sat { .. } => "sat",
    }
    .to_string()
}

/// What `shadowgraph plan` prints for the first drawn light: the graph's bytes per texel and
/// dispatches, and the shading's fetches per pixel.
fn plan_cost(plan: &crate::graph::Plan, lights: &[crate::model::Light]) -> Result<PlanCost> {
    use crate::graph::cost;
    let nodes = cost::light_traffic(plan, 0)?;
    let texels = cost::map_texels(plan, 0).max(1.0);
    let fetches = crate::cli::shading_fetches(lights)?;
    Ok(PlanCost {
        bytes_per_texel: nodes.iter().map(|(_, t)| t.bytes()).sum::<f64>() / texels,
        dispatches: nodes.iter().map(|(_, t)| t.dispatches).sum(),
        fetches_per_pixel: fetches.first().copied().unwrap_or(0.0),
    })
}

/// Each light's linear depth map at `size`: the shade map of a `hard` render (the plan's
/// output, so no later kernel reused its texture). Rasterization does not depend on the
/// technique, so this is the map every configuration of that size rasterized.
pub fn linear_maps(
    renderer: &mut Renderer,
    gpu: &Gpu,
    scene: &Scene,
    size: u32,
) -> Result<Vec<FloatMap>> {
    let mut s = scene.clone();
    for l in &mut s.lights {
        l.shadow.technique = Technique::Hard;
        l.shadow_map = size;
    }
    let opts = RenderOptions {
        aux: true,
        repeat: 1,
        dump: false,
    };
    Ok(renderer
        .render(&gpu.device, &gpu.queue, &s, opts)?
        .shade_maps)
}

/// Error against the box-PCF truth over each drawn light's linear map `linear` (1 where the
/// receiver leaves the map, as the shading returns). A cascaded light's reference is each
/// cascade's, picked and blended as the shading does (`cpu::cascade`).
fn pcf_stats(
    scene: &Scene,
    frame: &Frame,
    linear: &[FloatMap],
    truth: &Truth,
    width: f64,
) -> Result<ErrorStats> {
    let lights = scene.lights.len();
    let drawn = crate::render::drawn_lights(scene)?;
    // The linear maps are a `hard` render's: sample each as its drawn light (the same map for
    // every technique but a point light's and a soft technique's cascades, whose guard bands
    // follow the technique; neither has a box width).
    let mut maps = Vec::with_capacity(drawn.lights.len());
    for (k, light) in drawn.lights.iter().enumerate() {
        let Some(linear) = linear.get(k) else {
            return Err(Error::Invalid(format!(
                "drawn light {k} has no linear map to take the PCF truth over"
            )));
        };
        let mut hard = light.clone();
        hard.shadow.technique = Technique::Hard;
        maps.push((LightGpu::new(&hard), linear, f64::from(light.shadow.bias)));
    }
    let mut reference = vec![1.0; frame.visibility.len()];
    for li in 0..lights {
        let group = drawn.groups.iter().find(|g| g.light == li);
        for px in 0..(frame.width * frame.height) as usize {
            let i = px * lights + li;
            if !truth.mask[i] {
                continue;
            }
            let at = |d: &[f32]| {
                DVec3::new(d[4 * px].into(), d[4 * px + 1].into(), d[4 * px + 2].into())
            };
            let (p, n) = (at(&frame.position), at(&frame.normal).normalize_or_zero());
            let pcf = |k: usize| {
                let (g, linear, bias) = &maps[k];
                let s = crate::cpu::light::sample(g, p, n);
                if !s.inside {
                    return 1.0;
                }
                let map = Map {
                    size: linear.width as usize,
                    texels: &linear.data,
                };
                let r = Receiver {
                    uv: s.uv,
                    depth: s.depth,
                };
                pcf_box(&map, &r, width, *bias)
            };
            reference[i] = match group {
                None => pcf(li),
                Some(g) => {
                    // The pick reads cascade 0's cascade fields, which the drawn light holds.
                    let pick = crate::cpu::cascade::pick(&drawn.gpu[li], p);
                    crate::cpu::cascade::blend(&pick, |c| pcf(g.index(c)))
                }
            };
        }
    }
    Ok(ErrorStats::new(&frame.visibility, &reference, &truth.mask))
}
