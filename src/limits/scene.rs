//! A scene against a device, before anything is created: texture sides, the plan's kernels and
//! dispatches, the shading pass's bindings, buffer sizes, and an estimate of the frame's
//! memory against a budget. Each error is [`Error::SceneLimit`] naming the scene key that
//! would fix it, with its file and line.

use super::MEMORY_BUDGET_ENV;
use crate::error::{Error, Result};
use crate::graph::print::human_bytes;
use crate::graph::{Plan, texel_bytes};
use crate::render::{RenderOptions, ScenePlan};
use crate::scene::Scene;
use crate::{kernels, technique};

/// Bytes of one vertex as uploaded (`scene::Vertex`).
const VERTEX_BYTES: u64 = std::mem::size_of::<crate::wgsl_mirrors::Vertex>() as u64;

/// The estimated memory of one frame (GPU resources, staging buffers and host copies).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Memory {
    /// Everything.
    pub total: u64,
    /// Per light: its depth map, the plan's resources of that light, and their read-backs.
    pub lights: Vec<u64>,
    /// The image: G-buffer, colour, visibility, vertices and their read-backs.
    pub frame: u64,
}

/// Estimates the memory a frame of `scene` takes with `plan` (as the renderer would run it).
/// Pooled textures count once per slot; a read-back counts its staging buffer and its host
/// copies (raw bytes and f32 values).
pub fn render_memory(scene: &Scene, plan: &Plan, opts: &RenderOptions) -> Memory {
    let pixels = u64::from(scene.width) * u64::from(scene.height);
    let count = scene.lights.len() as u64;
    let vertices: u64 = scene
        .objects
        .iter()
        .map(|o| o.mesh.indices.len() as u64)
        .sum();
    // G-buffer (two rgba32f, depth32), colour (rgba8), visibility (f32 per light), vertices.
    let mut frame = pixels * (16 + 16 + 4 + 4 + 4 * count) + vertices * VERTEX_BYTES;
    // Colour and visibility read back: staging buffer and host copy each.
    frame += 2 * pixels * (4 + 4 * count);
    if opts.aux {
        // Position and normal: staging, raw bytes, f32 copy.
        frame += 2 * 3 * pixels * 16;
    }
    // Each light's depth map, and its peeled second depth where its technique reads one.
    let depth: Vec<u64> = scene
        .lights
        .iter()
        .map(|l| {
            let maps = 1 + u64::from(technique::peels(&l.shadow.technique));
            let (w, h) = l.map_dims();
            u64::from(w) * u64::from(h) * 4 * maps
        })
        .collect();
    let n = depth.len();
    let light_of = |r: &crate::graph::PlannedResource| r.resource.light.filter(|&i| i < n);
    // Resources of a light, counted per resource (for naming the largest light); the total
    // counts the texture slots the executor allocates, which resources share.
    let mut own = vec![0u64; n];
    let mut read = vec![0u64; n];
    for r in &plan.resources {
        let Some(i) = light_of(r) else { continue };
        if r.slot.is_some() {
            own[i] += r.bytes;
        }
        let shaded = plan.outputs.contains(&r.resource.name);
        let linear = r.resource.name == technique::linear_name(i);
        if opts.dump || (opts.aux && (shaded || linear)) {
            let texels = r.bytes / texel_bytes(r.resource.format).max(1);
            let channels = u64::from(r.resource.format.components());
            read[i] += 2 * r.bytes + 2 * texels * channels * 4;
        }
    }
    let slots = if opts.dump {
        plan.clone().unaliased().slot_bytes()
    } else {
        plan.slot_bytes()
    };
    let total = frame + depth.iter().sum::<u64>() + slots + read.iter().sum::<u64>();
    let lights = (0..n).map(|i| depth[i] + own[i] + read[i]).collect();
    Memory {
        total,
        lights,
        frame,
    }
}

/// Checks `scene` rendered with `opts` against a device's `limits` and `features` and the
/// memory `budget`; `sp` is the scene's plan. `owner` maps each light of `scene` to the light of
/// the scene file that errors name: a cascaded light is checked as the lights it draws (its
/// cascades after the file's lights, `render::DrawnLights::owner`); empty: each its own.
pub fn check_scene(
    scene: &Scene,
    sp: &ScenePlan,
    limits: &wgpu::Limits,
    features: wgpu::Features,
    opts: &RenderOptions,
    budget: u64,
    owner: &[usize],
) -> Result<()> {
    let c = Checker {
        scene,
        limits,
        owner,
    };
    c.sides()?;
    c.features(features)?;
    c.plan(&sp.plan)?;
    c.shading(sp)?;
    c.buffers(opts, &sp.plan)?;
    c.memory(&render_memory(scene, &sp.plan, opts), budget)
}

struct Checker<'a> {
    scene: &'a Scene,
    limits: &'a wgpu::Limits,
    owner: &'a [usize],
}

impl Checker<'_> {
    /// The scene file's light of checked light `i` (a cascade's: its scene light).
    fn file_light(&self, i: usize) -> usize {
        self.owner.get(i).copied().unwrap_or(i)
    }

    fn err(&self, key: &str, message: String) -> Error {
        Error::SceneLimit {
            path: self.scene.path.clone(),
            location: self.scene.locations.get(key),
            message,
        }
    }

    fn sides(&self) -> Result<()> {
        let max = self.limits.max_texture_dimension_2d;
        let s = self.scene;
        // (key, texels, what the texels are when they are not the key's value)
        let mut sides: Vec<(String, u32, Option<String>)> = vec![
            ("output.width".to_string(), s.width, None),
            ("output.height".into(), s.height, None),
        ];
        for (i, l) in s.lights.iter().enumerate() {
            let (w, _) = l.map_dims();
            // A point light's atlas is three faces wide.
            let what = (w != l.shadow_map)
                .then(|| format!("a point light's atlas of three faces is {w} texels wide, which"));
            sides.push((format!("light[{i}].shadow_map"), w, what));
        }
        match sides.into_iter().find(|(_, v, _)| *v > max) {
            Some((key, v, what)) => {
                let shown = match what {
                    Some(what) => format!("`{key}` = {}: {what}", v / 3),
                    None => format!("`{key}` = {v}"),
                };
                Err(self.err(
                    &key,
                    format!(
                        "{shown} is past this device's largest texture side, {max} \
                         (max_texture_dimension_2d)"
                    ),
                ))
            }
            None => Ok(()),
        }
    }

    fn features(&self, features: wgpu::Features) -> Result<()> {
        use crate::model::Storage;
        for (i, l) in self.scene.lights.iter().enumerate() {
            // Only MSM's tables accept unorm16 (`technique::params::MSM_FORMAT`).
            if l.shadow.technique.storage() == Some(Storage::Unorm16)
                && !features.contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM)
            {
                let key = format!("light[{i}].shadow.format");
                return Err(Error::MissingFeature {
                    what: format!(
                        "{}{}: `{key}` = \"unorm16\"",
                        self.scene.path.display(),
                        self.scene.locations.get(&key)
                    ),
                    feature: "TEXTURE_FORMAT_16BIT_NORM",
                });
            }
            // A soft technique's f32 tables are read with filtered fetches (`sat_mean_linear`).
            if l.shadow.technique.sat_filtered()
                && !features.contains(wgpu::Features::FLOAT32_FILTERABLE)
            {
                let key = format!("light[{i}].shadow.sat_sums");
                return Err(Error::MissingFeature {
                    what: format!(
                        "{}{}: `{key}` = \"float\" (the soft filter's filtered table lookups)",
                        self.scene.path.display(),
                        self.scene.locations.get(&key)
                    ),
                    feature: "FLOAT32_FILTERABLE",
                });
            }
        }
        Ok(())
    }

    fn plan(&self, plan: &Plan) -> Result<()> {
        let Some(over) = super::plan_over(plan, self.limits)? else {
            return Ok(());
        };
        let drawn = over.light.unwrap_or(0);
        let l = self.scene.lights.get(drawn);
        let i = self.file_light(drawn);
        let (key, fix) = if over.dispatch {
            (format!("light[{i}].shadow_map"), "lower it".to_string())
        } else {
            let name = l.map_or("", |l| l.shadow.technique.name());
            (
                format!("light[{i}].shadow.technique"),
                format!("\"{name}\" cannot run on this device; choose another technique or filter"),
            )
        };
        Err(self.err(
            &key,
            format!(
                "{} is {}, more than this device's {}: `{key}`: {fix}",
                over.what, over.requested, over.limit
            ),
        ))
    }

    /// The generated shading kernel's bindings and dispatch.
    fn shading(&self, sp: &ScenePlan) -> Result<()> {
        let s = self.scene;
        let wgsl = kernels::resolve("shade", Some(&technique::shading_block(&s.lights)))?;
        if let Some(n) = super::kernel_over("shade", &wgsl, self.limits)? {
            if n.limit_name == "max_sampled_textures_per_shader_stage" {
                return Err(self.too_many_maps(&n, sp));
            }
            return Err(self.err(
                "light[0]",
                format!(
                    "the shading pass of {} light(s) needs {} {}, more than this device's {}",
                    s.lights.len(),
                    n.requested,
                    n.describe(),
                    n.limit
                ),
            ));
        }
        let max = self.limits.max_compute_workgroups_per_dimension;
        // The shading kernel's workgroups are 8×8 (kernels/shade.wgsl).
        for (key, side) in [("output.width", s.width), ("output.height", s.height)] {
            if side.div_ceil(8) > max {
                return Err(self.err(
                    key,
                    format!(
                        "`{key}` = {side} needs {} workgroups of the shading pass, more than this \
                         device's {max} (max_compute_workgroups_per_dimension)",
                        side.div_ceil(8)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Sampled textures of the shading pass: blame the first light past the limit.
    fn too_many_maps(&self, n: &super::Need, sp: &ScenePlan) -> Error {
        let base = n.requested
            - sp.shade_inputs
                .iter()
                .map(|i| i.maps.len() as u64)
                .sum::<u64>();
        let mut count = base;
        let mut first = 0;
        for (i, input) in sp.shade_inputs.iter().enumerate() {
            count += input.maps.len() as u64;
            if count > n.limit {
                first = self.file_light(i);
                break;
            }
        }
        self.err(
            &format!("light[{first}]"),
            format!(
                "the shading pass would sample {} textures ({base} for the G-buffer and one or \
                 more maps per light for {} lights), more than this device's {} ({}): \
                 `light[{first}]` and the lights after it do not fit; use fewer `[[light]]` \
                 tables or techniques with fewer maps",
                n.requested,
                self.scene.lights.len(),
                n.limit,
                n.limit_name
            ),
        )
    }

    fn buffers(&self, opts: &RenderOptions, plan: &Plan) -> Result<()> {
        let s = self.scene;
        let l = self.limits;
        let pixels = u64::from(s.width) * u64::from(s.height);
        let lights = s.lights.len().max(1) as u64;
        let binding = l.max_storage_buffer_binding_size.min(l.max_buffer_size);
        let visibility = pixels * lights * 4;
        if visibility > binding {
            return Err(self.err(
                "output.width",
                format!(
                    "the visibility buffer of {}×{} pixels × {lights} light(s) is {visibility} \
                     bytes, more than this device binds, {binding} \
                     (max_storage_buffer_binding_size): lower `output.width` and \
                     `output.height`, or use fewer lights",
                    s.width, s.height
                ),
            ));
        }
        let per_light = std::mem::size_of::<crate::wgsl_mirrors::LightGpu>() as u64;
        if lights * per_light > binding || s.objects.len() as u64 * 16 > binding {
            return Err(self.err(
                "light[0]",
                "too many lights or objects for one storage buffer".into(),
            ));
        }
        let vertices: u64 = s.objects.iter().map(|o| o.mesh.indices.len() as u64).sum();
        if vertices * VERTEX_BYTES > l.max_buffer_size {
            let (i, _) = s
                .objects
                .iter()
                .enumerate()
                .max_by_key(|(_, o)| o.mesh.indices.len())
                .unwrap_or((0, &s.objects[0]));
            return Err(self.err(
                &format!("object[{i}]"),
                format!(
                    "the vertex buffer would be {} bytes, more than this device's {} \
                     (max_buffer_size); `object[{i}]` is the largest",
                    vertices * VERTEX_BYTES,
                    l.max_buffer_size
                ),
            ));
        }
        self.read_backs(opts, plan)
    }

    /// Every texture read back goes through one buffer of its padded rows.
    fn read_backs(&self, opts: &RenderOptions, plan: &Plan) -> Result<()> {
        let s = self.scene;
        let max = self.limits.max_buffer_size;
        let padded = |w: u32, bpp: u64| {
            (u64::from(w) * bpp).div_ceil(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT))
                * u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        };
        let image_bpp = if opts.aux { 16 } else { 4 };
        let image = padded(s.width, image_bpp) * u64::from(s.height);
        if image > max {
            return Err(self.err(
                "output.width",
                format!(
                    "reading the {}×{} image back needs a buffer of {image} bytes, more than this \
                     device's {max} (max_buffer_size): lower `output.width` and `output.height`",
                    s.width, s.height
                ),
            ));
        }
        if !(opts.aux || opts.dump) {
            return Ok(());
        }
        for r in &plan.resources {
            let Some(i) = r.resource.light else { continue };
            let bytes = padded(r.width, texel_bytes(r.resource.format)) * u64::from(r.height);
            let read = opts.dump || plan.outputs.contains(&r.resource.name);
            if read && bytes > max {
                let key = format!("light[{}].shadow_map", self.file_light(i));
                return Err(self.err(
                    &key,
                    format!(
                        "reading `{}` back needs a buffer of {bytes} bytes, more than this \
                         device's {max} (max_buffer_size): lower `{key}`",
                        r.resource.name
                    ),
                ));
            }
        }
        Ok(())
    }

    fn memory(&self, m: &Memory, budget: u64) -> Result<()> {
        if m.total <= budget {
            return Ok(());
        }
        // Per light of the scene file: a cascaded light's bytes are its cascades'.
        let mut per_file = vec![(0u64, 0usize); m.lights.len()];
        for (k, &b) in m.lights.iter().enumerate() {
            let i = self.file_light(k).min(per_file.len() - 1);
            per_file[i].0 += b;
            per_file[i].1 += 1;
        }
        let (i, (most, drawn)) = per_file
            .iter()
            .copied()
            .enumerate()
            .max_by_key(|&(_, (b, _))| b)
            .unwrap_or((0, (0, 1)));
        // Counted per resource, a light's bytes may pass the total, whose pooled slots its
        // resources share: shown as at most the total.
        let most = most.min(m.total);
        let (key, part) = if most >= m.frame {
            let maps = match self.scene.lights.get(i) {
                Some(l) if l.kind == crate::model::LightKind::Point => {
                    format!("six {}² faces", l.shadow_map)
                }
                l if drawn > 1 => format!(
                    "{drawn} cascades of {}² maps",
                    l.map_or(0, |l| l.shadow_map)
                ),
                l => format!("{}² maps", l.map_or(0, |l| l.shadow_map)),
            };
            (
                format!("light[{i}].shadow_map"),
                format!("`light[{i}]`'s {maps}: {}", human_bytes(most)),
            )
        } else {
            (
                "output.width".to_string(),
                format!(
                    "the {}×{} image: {}",
                    self.scene.width,
                    self.scene.height,
                    human_bytes(m.frame)
                ),
            )
        };
        Err(self.err(
            &key,
            format!(
                "this frame needs an estimated {} ({part}), more than the memory budget of {} \
                 ({MEMORY_BUDGET_ENV}): lower `{key}` or raise the budget",
                human_bytes(m.total),
                human_bytes(budget)
            ),
        ))
    }
}
