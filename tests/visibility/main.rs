//! The shading kernel's visibility functions against the f64 references, on random blocky
//! depth maps and random receivers (with random normals, so the normal offset is exercised).
//!
//! f32 and f64 may disagree where a receiver sits on a texel boundary or a comparison is a tie:
//! a point is *robust* when the f64 reference does not jump when the receiver's UV and depth
//! are nudged by ±1e-4 texel / ±2e-6 (`common::robust`). At robust points the GPU must match to 1e-5 (the
//! mean of at most a few hundred 0/1 terms in f32); robust points must be ≥ 90% of all.

#[path = "../common/mod.rs"]
mod common;
use glam::{DVec3, Vec3};
use rand::Rng;
use shadowgraph::low_level::cpu::{self, Map};
use shadowgraph::low_level::render::{MapData, Renderer, visibility_at};
use shadowgraph::{Filter, Storage};
use shadowgraph::{Light, LightGpu, LightKind, PcfKernel, Shadow, Technique};

mod direct;
mod prefiltered;

const MAP: usize = 61; // not a power of two

fn light(kind: LightKind, technique: Technique) -> Light {
    let (position, near, far) = match kind {
        LightKind::Directional { .. } => (Vec3::new(-3.0, 10.0, 2.0), 2.0, 20.0),
        LightKind::Spot { .. } | LightKind::Point => (Vec3::new(1.0, 8.0, -1.0), 0.5, 20.0),
    };
    Light {
        kind,
        position,
        target: Vec3::ZERO,
        near,
        far,
        size: 0.6,
        radiance: Vec3::ONE,
        shadow_map: MAP as u32,
        shadow: Shadow {
            technique,
            bias: 0.002,
            slope_bias: 0.0,
            normal_bias: 1.0,
            receiver_plane: 0.0,
            cascades: shadowgraph::Cascades::SINGLE,
        },
    }
}

/// A world point whose light-space UV and linear depth are given, with a normal facing the light.
fn point(l: &Light, rng: &mut impl Rng) -> (Vec3, Vec3) {
    let uv = [rng.random_range(0.08..0.92), rng.random_range(0.08..0.92)];
    let d: f64 = rng.random_range(0.05..0.98);
    point_at(l, uv, d, rng)
}

fn point_at(l: &Light, uv: [f64; 2], d: f64, rng: &mut impl Rng) -> (Vec3, Vec3) {
    let g = LightGpu::new(l);
    let ndc_z = cpu::light::linear_to_ndc(&g, d);
    let inv = (l.projection() * l.view()).as_dmat4().inverse();
    let p = inv.project_point3(DVec3::new(2.0 * uv[0] - 1.0, 1.0 - 2.0 * uv[1], ndc_z));
    let to_light = cpu::light::to_light(&g, p);
    let mut n = DVec3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    n = (n.normalize_or_zero() + 1.5 * to_light).normalize();
    (p.as_vec3(), n.as_vec3())
}

fn reference(l: &LightGpu, map: &Map, s: &cpu::light::LightSample) -> f64 {
    if !s.inside {
        return 1.0;
    }
    match l.technique {
        0 => cpu::vis_hard::vis_hard(map, l, s),
        1 => cpu::vis_pcf::vis_pcf(map, l, s),
        _ => cpu::vis_pcss::vis_pcss(map, l, s),
    }
}

const DIR: LightKind = LightKind::Directional { extent: 5.0 };

const SPOT: LightKind = LightKind::Spot { fov_degrees: 60.0 };
