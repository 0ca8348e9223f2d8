//! The stage's planning: the graph of light 0 for a configuration, the maps its shading
//! reads, and the names and views of what a record produced.

use glam::Mat4;

use std::collections::HashMap;

use super::{LightParams, LightSlot, OutputMap, PlanKey, Planned, PrefilterConfig};
use crate::error::{Error, Result};
use crate::graph::{Graph, plan};
use crate::model::Light;
use crate::technique;

/// Node names are `light0.<node>`, like the resource names (`technique::depth_name`): the
/// light's prefix is dropped.
pub(super) fn strip_light(spans: Vec<(String, f64)>) -> Vec<(String, f64)> {
    spans
        .into_iter()
        .map(|(name, ms)| match name.strip_prefix("light0.") {
            Some(n) => (n.to_string(), ms),
            None => (name, ms),
        })
        .collect()
}

/// Parameters to plan with before the first frame: pipelines do not depend on them.
pub(super) fn planning_params() -> LightParams {
    LightParams::orthographic(Mat4::IDENTITY, 1.0, 0.1, 1.0)
}

/// The graph of light 0 with `config`'s technique, planned for the maps the shading reads.
pub(super) fn plan_for(
    config: &PrefilterConfig,
    light: &LightParams,
    size: u32,
) -> Result<Planned> {
    let scene_light = light.scene_light(config, size);
    let mut graph = Graph::default();
    let maps = light_maps(&mut graph, &scene_light);
    let outputs: Vec<&str> = maps.iter().map(|m| m.resource.as_str()).collect();
    let plan = plan(&graph, &outputs)?;
    Ok(Planned {
        key: PlanKey::new(light, size),
        plan,
        maps,
    })
}

/// The maps light 0's technique reads, in binding order. `add_light_nodes` returns one per
/// light today; when it returns a list, this is the one line to change.
pub(super) fn light_maps(graph: &mut Graph, light: &Light) -> Vec<MapInput> {
    let input = technique::add_light_nodes(graph, 0, light);
    input
        .maps
        .into_iter()
        .map(|resource| MapInput {
            format: graph
                .find(&resource)
                .map_or(wgpu::TextureFormat::Depth32Float, |r| r.format),
            resource,
            wgsl_type: input.wgsl_type,
        })
        .collect()
}

/// One map the technique's visibility function reads.
#[derive(Clone, Debug)]
pub(super) struct MapInput {
    /// Graph resource.
    pub(super) resource: String,
    /// WGSL type of its binding.
    pub(super) wgsl_type: &'static str,
    /// Its format in the graph.
    pub(super) format: wgpu::TextureFormat,
}

pub(super) fn depth_aspect_view(t: &wgpu::Texture) -> wgpu::TextureView {
    crate::gpu_objects::view(
        t,
        &wgpu::TextureViewDescriptor {
            aspect: if t.format().is_depth_stencil_format() {
                wgpu::TextureAspect::DepthOnly
            } else {
                wgpu::TextureAspect::All
            },
            ..Default::default()
        },
    )
}

impl LightSlot {
    /// The maps of a record whose plan produced `textures`: the last record's (views
    /// included) while the textures are the same, else made anew.
    pub(super) fn output_maps(
        &mut self,
        textures: &HashMap<String, wgpu::Texture>,
    ) -> Result<Vec<OutputMap>> {
        let texture = |m: &MapInput| {
            textures
                .get(&m.resource)
                .cloned()
                .ok_or_else(|| Error::Invalid(format!("the plan produced no `{}`", m.resource)))
        };
        let same = self.maps.len() == self.planned.maps.len()
            && self.maps.iter().zip(&self.planned.maps).all(|(o, m)| {
                o.resource == m.resource && textures.get(&m.resource) == Some(&o.texture)
            });
        if !same {
            self.maps = self
                .planned
                .maps
                .iter()
                .map(|m| {
                    let texture = texture(m)?;
                    Ok(OutputMap {
                        resource: m.resource.clone(),
                        wgsl_type: m.wgsl_type,
                        format: m.format,
                        view: depth_aspect_view(&texture),
                        texture,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
        }
        Ok(self.maps.clone())
    }
}
