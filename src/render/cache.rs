//! Cached lights: which drawn lights a frame redraws (their raster passes and their plan steps)
//! and which keep last frame's maps. A light is redrawn when its update rate
//! ([`UpdateRate`]) says so, or when anything its maps depend on changed since it was last
//! drawn: the light itself (its position, target, planes, map size, shadow configuration),
//! the casters (every vertex of the scene), the plan (any light's technique or the read-backs
//! asked for: its steps and texture slots) or the renderer's targets (the depth maps). Every
//! light is redrawn when the frame reads every resource back (`dump`).
//!
//! The planner reuses a texture once its resource's last reader ran, so a light's filtered maps
//! could share a texture with another light's intermediate, which would overwrite them while
//! they are kept: when any light may be cached, [`dedicate_outputs`] gives every requested
//! output a texture of its own.

use std::collections::HashMap;

use crate::exec::Outputs;
use crate::graph::{Plan, Slot};
use crate::{
    model::Light,
    scene::{Scene, UpdateRate},
};

use super::cascade::DrawnLights;

/// Whether any light of `scene` may be cached (a rate other than every frame).
pub(super) fn caches(scene: &Scene) -> bool {
    (0..scene.lights.len()).any(|i| scene.update_rate(i) != UpdateRate::EveryFrame)
}

/// `plan` with a texture of its own for every requested output (live to the frame's end and
/// beyond, while cached), the other resources' slots as they were; slots left unused dropped.
pub(super) fn dedicate_outputs(mut plan: Plan) -> Plan {
    let end = plan.steps.len();
    let mut slots: Vec<Slot> = Vec::new();
    let mut renumbered: Vec<Option<usize>> = vec![None; plan.slots.len()];
    for r in &mut plan.resources {
        let Some(old) = r.slot else { continue };
        if r.last_use >= end {
            slots.push(plan.slots[old].clone());
            r.slot = Some(slots.len() - 1);
        } else {
            let new = *renumbered[old].get_or_insert_with(|| {
                slots.push(plan.slots[old].clone());
                slots.len() - 1
            });
            r.slot = Some(new);
        }
    }
    plan.slots = slots;
    plan
}

/// The state of one drawn light's last redraw.
#[derive(Clone, Debug)]
struct Drawn {
    /// The light as drawn ([`light_key`]).
    key: String,
    /// The casters' generation it was drawn with.
    casters: u64,
    /// Frames since (0 on the frame it was drawn).
    since: u64,
}

/// What the renderer remembers of the lights' last redraws, and which the next frame redraws.
#[derive(Default)]
pub(super) struct LightCache {
    /// The plan the kept maps were made by.
    plan: Option<Plan>,
    /// The depth maps they were rasterized into, one per drawn light.
    depths: Vec<wgpu::Texture>,
    /// The scene's vertices as last uploaded, and their generation (bumped on a change).
    vertices: Vec<u8>,
    casters: u64,
    /// Per drawn light, its last redraw (`None`: none to reuse).
    lights: Vec<Option<Drawn>>,
    /// Per drawn light, its rate.
    rates: Vec<UpdateRate>,
    /// Per drawn light, whether its next frame must redraw it whatever its rate.
    changed: Vec<bool>,
    /// Per drawn light, its [`light_key`] this call.
    keys: Vec<String>,
    /// The plan's textures of the last frame, which the kept maps lie in.
    textures: Option<HashMap<String, wgpu::Texture>>,
    /// The plan's storage buffers of the last frame (`exec::Outputs::buffers`).
    buffers: Option<HashMap<String, crate::exec::BufferMap>>,
    /// Whether the scene caches (else every light is drawn every frame and nothing is kept).
    active: bool,
}

/// A light's identity for the cache: every field, as Rust prints them (shortest round-trip
/// floats, so equal text is equal values); `Light` holds floats and compares no other way.
fn light_key(l: &Light) -> String {
    format!("{l:?}")
}

impl LightCache {
    /// Forgets every kept map (after a failed frame, whose passes may have run in part).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Starts a [`super::Renderer::render`] call: notes what changed since the last frame.
    /// `depths` are the drawn lights' depth maps; `all` redraws every light (a dump).
    pub fn begin(
        &mut self,
        scene: &Scene,
        drawn: &DrawnLights,
        plan: &Plan,
        depths: Vec<wgpu::Texture>,
        vertices: &[u8],
        all: bool,
    ) {
        self.active = true;
        let n = drawn.lights.len();
        let same_frame = self.plan.as_ref() == Some(plan) && self.depths == depths;
        if !same_frame || self.lights.len() != n || all {
            self.lights = vec![None; n];
        }
        if self.vertices != vertices {
            self.vertices = vertices.to_vec();
            self.casters += 1;
        }
        self.plan = Some(plan.clone());
        self.depths = depths;
        self.rates = (0..n)
            .map(|k| scene.update_rate(drawn.owner(k).0))
            .collect();
        self.keys = drawn.lights.iter().map(light_key).collect();
        self.changed = self
            .keys
            .iter()
            .zip(&self.lights)
            .map(|(key, d)| {
                d.as_ref()
                    .is_none_or(|d| d.key != *key || d.casters != self.casters)
            })
            .collect();
    }

    /// Which of the `n` drawn lights the next frame redraws; counts the frame.
    pub fn next_frame(&mut self, n: usize) -> Vec<bool> {
        if !self.active {
            return vec![true; n];
        }
        let casters = self.casters;
        let mut redraw = Vec::with_capacity(self.lights.len());
        let each = self
            .lights
            .iter_mut()
            .zip(&self.rates)
            .zip(&mut self.changed);
        for (((d, rate), changed), key) in each.zip(&self.keys) {
            let due = match d {
                Some(d) => *changed || rate.due(d.since + 1),
                None => true,
            };
            match d {
                Some(d) if !due => d.since += 1,
                _ => {
                    *d = Some(Drawn {
                        key: key.clone(),
                        casters,
                        since: 0,
                    })
                }
            }
            *changed = false;
            redraw.push(due);
        }
        redraw
    }

    /// Whether a frame's plan `outputs` lie in the textures of the last frame (where the kept
    /// maps are); remembers them.
    pub fn intact(&mut self, outputs: &Outputs) -> bool {
        if !self.active {
            return true;
        }
        let same = self
            .textures
            .as_ref()
            .is_none_or(|t| *t == outputs.textures)
            && self.buffers.as_ref().is_none_or(|b| *b == outputs.buffers);
        self.textures = Some(outputs.textures.clone());
        self.buffers = Some(outputs.buffers.clone());
        same
    }

    /// Notes that the frame redraws every light after all.
    pub fn redraw_all(&mut self) {
        let casters = self.casters;
        for (d, key) in self.lights.iter_mut().zip(&self.keys) {
            *d = Some(Drawn {
                key: key.clone(),
                casters,
                since: 0,
            });
        }
    }
}
