//! Every bundled scene renders with no NaN, and every covered pixel's visibility matches the
//! f64 references evaluated on the maps the GPU rasterized (read back with `aux`).

#[path = "../common/mod.rs"]
mod common;
use shadowgraph::low_level::cpu::{self, Map, Texels};
use shadowgraph::low_level::render::{DrawnLights, RenderOptions, Renderer, drawn_lights};
use shadowgraph::low_level::scene::Scene;
use shadowgraph::{Error, PcfKernel, Technique};
use std::path::{Path, PathBuf};

mod cascaded;
mod plans;
mod references;
mod techniques;

fn scenes() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut v: Vec<PathBuf> = [root.clone(), root.join("techniques")]
        .iter()
        .flat_map(|d| {
            std::fs::read_dir(d)
                .expect("scenes/")
                .map(|e| e.expect("entry").path())
        })
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 6, "bundled scenes missing: {v:?}");
    // `SHADOWGRAPH_SCENES=point` checks only the scenes whose path contains "point" (for
    // working on one technique; the suite checks them all).
    if let Ok(only) = std::env::var("SHADOWGRAPH_SCENES") {
        v.retain(|p| p.to_string_lossy().contains(&only));
        assert!(!v.is_empty(), "no bundled scene matches {only:?}");
    }
    v
}

/// Reference visibility of drawn light `k` (a scene light, or one of a cascaded light's
/// cascades) at pixel `px` and its tolerance, if robust (soft techniques: also where the
/// propagated errors could flip the blocker threshold).
fn pixel_reference(
    scene: &Scene,
    frame: &shadowgraph::low_level::render::Frame,
    moments: &[Texels],
    soft: Option<&common::soft::SoftInputs>,
    (drawn, k): (&DrawnLights, usize),
    px: usize,
) -> Option<(f64, f64)> {
    let light = &drawn.lights[k];
    let lg = drawn.gpu[k];
    let p = &frame.position[4 * px..4 * px + 3];
    let n = &frame.normal[4 * px..4 * px + 3];
    let p = glam::DVec3::new(p[0].into(), p[1].into(), p[2].into());
    let n = glam::DVec3::new(n[0].into(), n[1].into(), n[2].into()).normalize();
    // Facing away, the shading reads no map: 0 (`light_faces`). Within 10⁻⁵ of N·L = 0 the f32
    // dot product may take either sign.
    let ndl = cpu::light::facing(&lg, p, n);
    if ndl.abs() < 1e-5 {
        return None;
    }
    if ndl < 0.0 {
        return Some((0.0, 0.0));
    }
    if lg.kind == 2 && point_face_tie(&lg, p, n) {
        return None;
    }
    let mut s = cpu::light::sample(&lg, p, n);
    if lg.max_anisotropy > 0 {
        // The pixel's footprint, as the shading kernel derives it from the camera's rays.
        let rays = shadowgraph::low_level::model::CameraRays::new(
            &scene.camera,
            frame.width,
            frame.height,
        );
        let (x, y) = (px as u32 % frame.width, px as u32 / frame.width);
        let eye = scene.camera.position.as_dvec3();
        let (dx, dy) = cpu::shade::pixel_differentials(eye, &rays, x, y, p, n);
        s.footprint = cpu::light::footprint(&lg, &s, p, n, dx, dy);
        // Where the tap count sits at a ceiling's step, f32 and f64 may take different counts.
        let ratio = cpu::mips::mip_taps(&lg, &s).ratio;
        if (ratio - ratio.round()).abs() < 1e-3 * ratio.max(1.0) {
            return None;
        }
    }
    // The map's width: a point light's atlas is three faces wide.
    let size = lg.map_size[0] as usize;
    let map = Map {
        size,
        texels: &frame.shade_maps[k].data,
    };
    let vis = |t: &cpu::light::LightSample| {
        if let Some(soft) = soft {
            return soft.reference(&lg, t);
        }
        if !t.inside {
            return 1.0;
        }
        match light.shadow.technique {
            Technique::Hard => cpu::vis_hard::vis_hard(&map, &lg, t),
            Technique::Pcf {
                kernel: PcfKernel::Hardware,
                ..
            } => cpu::vis_pcf::vis_pcf_hardware(&map, &lg, t),
            Technique::Pcf { .. } => cpu::vis_pcf::vis_pcf(&map, &lg, t),
            Technique::Pcss { .. } => cpu::vis_pcss::vis_pcss(&map, &lg, t),
            Technique::Smrt { .. } => cpu::vis_smrt::vis_smrt(&map, &lg, t),
            // The map holds the comparison depth (no bias; the far plane where no second
            // surface exists): tests/second_depth.rs checks it against the ray cast and the
            // kernel's reference.
            Technique::Midpoint { radius: 0, .. } | Technique::SecondDepth { radius: 0, .. } => {
                cpu::vis_hard::vis_hard(&map, &lg, t)
            }
            Technique::Midpoint { .. } | Technique::SecondDepth { .. } => {
                cpu::vis_pcf::vis_pcf(&map, &lg, t)
            }
            Technique::Vsm { .. } => cpu::vis_vsm::vis_vsm(moments, &lg, t),
            Technique::Evsm { .. } => cpu::vis_evsm::vis_evsm(moments, &lg, t),
            Technique::Esm { .. } => cpu::vis_esm::vis_esm(moments, &lg, t),
            Technique::Msm { .. } => cpu::vis_msm::vis_msm(moments, &lg, t),
            Technique::Csm { .. } => cpu::vis_csm::vis_csm(moments, &lg, t),
            Technique::Cssm { .. } | Technique::Vssm { .. } | Technique::MsmSoft { .. } => {
                unreachable!("soft techniques use SoftInputs")
            }
        }
    };
    common::robust(&s, size, vis)
        .and_then(|v| match soft {
            Some(soft) => soft.tolerance(&lg, &s, v).map(|t| (v, t)),
            None => Some((v, 0.0)),
        })
        .map(|(v, soft_tolerance)| {
            let tolerance = match light.shadow.technique {
                // Vulkan allows 8-bit bilinear weights: each of four may be off by 2⁻⁸.
                Technique::Pcf {
                    kernel: PcfKernel::Hardware,
                    ..
                } => 1.0 / 64.0,
                Technique::Vsm { .. } => common::vsm_tolerance(moments, &lg, &s),
                Technique::Evsm { .. } => common::evsm_tolerance(moments, &lg, &s),
                Technique::Esm { .. } if lg.filter_width > 0.0 => {
                    common::esm_sat_tolerance(moments, &lg, &s, v)
                }
                Technique::Esm { .. } => common::esm_tolerance(moments, &lg, &s, v),
                Technique::Msm { .. } => common::msm_tolerance(moments, &lg, &s),
                Technique::Csm { .. } => common::csm_tolerance(&lg),
                // Propagated through the chain (tests/common/soft/).
                Technique::Cssm { .. } | Technique::Vssm { .. } | Technique::MsmSoft { .. } => {
                    soft_tolerance
                }
                // Means of 0/1 taps in f32.
                _ => 1e-5,
            };
            // The receiver's UV comes out of f32 projections (a few 2⁻²⁴ each way), which moves the
            // filtered moments' bilinear weights; where neighbouring texels' moments differ by
            // orders of magnitude (EVSM's exp(40 z')), that is visible: add twice the reference's
            // change under ±4·2⁻²⁴ of UV.
            let tolerance = if light.shadow.technique.filter().is_some() {
                let d = 4.0 * 2f64.powi(-24);
                let spread = [[d, 0.0], [-d, 0.0], [0.0, d], [0.0, -d]]
                    .iter()
                    .map(|[du, dv]| {
                        let mut t = s;
                        t.uv = [s.uv[0] + du, s.uv[1] + dv];
                        (vis(&t) - v).abs()
                    })
                    .fold(0.0, f64::max);
                tolerance + 2.0 * spread
            } else {
                tolerance
            };
            // The GPU's footprint is a difference of f32 UVs times the map size: 2⁻²⁴ · 1024 ≈
            // 6·10⁻⁵ texels on an axis of a texel or more, so up to about 10⁻⁴ relative. It moves
            // the taps' level and spacing: add twice the reference's change under a ±2·10⁻⁴ scaling
            // of the footprint, and 8 f32 roundings per tap for the taps' running mean.
            let tolerance = if lg.max_anisotropy > 0 {
                let spread = [1.0 - 2e-4, 1.0 + 2e-4]
                    .iter()
                    .map(|k| {
                        let mut t = s;
                        t.footprint = s.footprint.map(|f| f * k);
                        (vis(&t) - v).abs()
                    })
                    .fold(0.0, f64::max);
                let taps = f64::from(cpu::mips::mip_taps(&lg, &s).count);
                // ESM's running log-sum-exp re-rounds the logarithm (|L| ≤ c) at every tap: 8 ULP
                // of c, relative in the visibility.
                let esm_logs = match light.shadow.technique {
                    Technique::Esm { exponent, .. } => {
                        8.0 * 2f64.powi(-23) * f64::from(exponent) * v
                    }
                    _ => 0.0,
                };
                tolerance + 2.0 * spread + taps * 8.0 * 2f64.powi(-23) * v + esm_logs
            } else {
                tolerance
            };
            (v, tolerance)
        })
}

/// Whether the receiver at `p` (normal `n`, moved by the normal offset) lies within 10⁻⁵
/// (relative) of a tie between a point light's faces, where the f32 shading and the f64
/// reference may pick different faces. Either face reads real geometry there (the guard band):
/// the two lookups differ by resampling, not by a seam; tests/point.rs checks those receivers
/// against the ray cast.
fn point_face_tie(lg: &shadowgraph::LightGpu, p: glam::DVec3, n: glam::DVec3) -> bool {
    let pos = glam::DVec3::new(
        lg.position[0].into(),
        lg.position[1].into(),
        lg.position[2].into(),
    );
    let mut a = (cpu::light::point_moved(lg, p, n) - pos).abs().to_array();
    a.sort_by(f64::total_cmp);
    a[2] - a[1] < 1e-5 * a[2]
}

/// A cascaded directional light: every pixel's visibility against the f64 pick of its cascade
/// (`cpu::cascade`) and the per-cascade references on the maps the GPU made, blended in f64.
mod cascades {
    use super::*;

    /// The maps a cascade's visibility reads (with the mips filter, the chain rebuilt in f64).
    fn moments(
        frame: &shadowgraph::low_level::render::Frame,
        technique: Technique,
        k: usize,
    ) -> Vec<Texels> {
        let sm = &frame.shade_maps[k];
        let level0 = Texels::from_f32(sm.width as usize, sm.height as usize, sm.channels, &sm.data);
        match technique.filter() {
            Some(shadowgraph::Filter::Mips { .. }) => {
                cpu::mips::mip_chain(&level0, matches!(technique, Technique::Esm { .. }))
            }
            _ => vec![level0],
        }
    }

    /// Checks light `li`'s visibility at every robust covered pixel. Tolerance: each cascade's
    /// own (as for a single map), blended with the pick's weights, plus the f32 error of the
    /// blend weight — the view distance's rounding, 8 · 2⁻²⁴ of the distances involved, over
    /// the band — times the two cascades' difference. Pixels within that rounding of a split
    /// (where f32 may pick the other cascade) are skipped; at least 1% of the checked pixels
    /// lie inside a blend band.
    pub fn check_light(
        scene: &Scene,
        frame: &shadowgraph::low_level::render::Frame,
        drawn: &DrawnLights,
        li: usize,
        e_trig: f64,
    ) {
        let group = drawn
            .groups
            .iter()
            .find(|g| g.light == li)
            .expect("cascaded");
        let technique = scene.lights[li].shadow.technique;
        let maps: Vec<Vec<Texels>> = (0..group.count)
            .map(|c| moments(frame, technique, group.index(c)))
            .collect();
        // A soft technique's inputs per cascade: its own table and `max_search`.
        let softs: Vec<Option<common::soft::SoftInputs>> = (0..group.count)
            .map(|c| {
                common::soft::SoftInputs::new(&drawn.lights[group.index(c)], &maps[c][0], e_trig)
            })
            .collect();
        let lg = drawn.gpu[li];
        let lights = scene.lights.len();
        let (mut gpu_v, mut ref_v, mut tol, mut covered, mut banded) =
            (Vec::new(), Vec::new(), Vec::new(), 0, 0);
        let mut used = vec![0usize; group.count];
        for px in 0..(frame.width * frame.height) as usize {
            if frame.position[4 * px + 3] == 0.0 {
                continue;
            }
            covered += 1;
            let q = &frame.position[4 * px..4 * px + 3];
            let p = glam::DVec3::new(q[0].into(), q[1].into(), q[2].into());
            let pick = cpu::cascade::pick(&lg, p);
            let eye = glam::DVec3::from_array(lg.cascade_eye.map(f64::from));
            let rounding =
                8.0 * 2f64.powi(-24) * (pick.distance.abs() + pick.far + p.length() + eye.length());
            // Within f32's rounding of a split the GPU may pick the neighbour: skipped.
            let split_near = (0..group.count - 1)
                .any(|c| (pick.distance - cpu::cascade::cascade_far_of(&lg, c)).abs() < rounding);
            if split_near {
                continue;
            }
            let reference = |c: usize| {
                let soft = softs[c].as_ref();
                pixel_reference(scene, frame, &maps[c], soft, (drawn, group.index(c)), px)
            };
            let Some((v0, t0)) = reference(pick.index) else {
                continue;
            };
            let in_band = pick.band > 0.0 && pick.distance > pick.far - pick.band - rounding;
            let (v, t) = if in_band {
                let Some((v1, t1)) = reference(pick.index + 1) else {
                    continue;
                };
                banded += 1;
                let dt = rounding / pick.band;
                let w = pick.blend;
                (
                    v0 + (v1 - v0) * w,
                    (1.0 - w) * t0 + w * t1 + (v1 - v0).abs() * dt + 1e-6,
                )
            } else {
                (v0, t0)
            };
            used[pick.index] += 1;
            gpu_v.push(frame.visibility[px * lights + li]);
            ref_v.push(v);
            tol.push(t);
        }
        let what = format!(
            "light {li} ({}) in {} cascades",
            technique.name(),
            group.count
        );
        assert!(
            gpu_v.len() * 10 >= covered * 9,
            "{what}: only {} of {covered} pixels robust",
            gpu_v.len()
        );
        assert!(
            used.iter().all(|&n| n > 0),
            "{what}: a cascade shades no pixel ({used:?})"
        );
        assert!(
            banded * 100 >= gpu_v.len(),
            "{what}: only {banded} of {} pixels in a blend band",
            gpu_v.len()
        );
        let shadowed = ref_v.iter().filter(|&&v| v < 0.5).count();
        assert!(
            shadowed * 200 > ref_v.len(),
            "{what}: casts almost no shadow ({shadowed} pixels)"
        );
        common::assert_within(&what, &gpu_v, &ref_v, &tol);
    }
}
