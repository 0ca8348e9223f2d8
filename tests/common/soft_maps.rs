//! Random maps, lights and tables for the soft techniques' tests (tests/soft.rs,
//! tests/blocker.rs), and the device's measured sin/cos error.

use std::collections::HashMap;

use glam::Vec3;
use shadowgraph::low_level::cpu::{self, Texels};
use shadowgraph::low_level::gpu::Gpu;
use shadowgraph::low_level::sat::SatCoding;
use shadowgraph::{
    CssmResolve, CssmSearch, Light, LightKind, SatVariant, Shadow, Soft, Storage, Technique,
};

const ULP: f64 = 1.0 / 16_777_216.0; // 2⁻²⁴

/// The device's largest error of CSM's `csm_sin_cos` against f64, measured by running the
/// `csm` kernel (M = 16: every factor the shading can use) over 65 536 depths spread over
/// [−0.25, 1.25] (receiver depths shifted by bias and offset stay inside). The kernel clamps
/// the depth it linearizes to [0, 1], so the sweep runs it with its depth read returning the
/// raw value (the same WGSL otherwise, compiled under the kernel's name). Asserts Vulkan's
/// bound of 2⁻¹¹ on [−π, π]; returns twice the measured error (the sweep samples the
/// functions, the factor covers depths between samples) plus 2⁻²⁴.
pub fn trig_error(g: &Gpu) -> f64 {
    use shadowgraph::low_level::graph::{Dispatch, Graph, Node, SizeRule, plan};
    let (w, h) = (256u32, 256u32);
    let z: Vec<f32> = (0..w * h)
        .map(|i| -0.25 + 1.5 * i as f32 / (w * h - 1) as f32)
        .collect();
    let terms = 16u32;
    let mut graph = Graph::default();
    graph.import("in", wgpu::TextureFormat::R32Float, w, h, Some(0));
    let mut outputs = Vec::new();
    let per = shadowgraph::low_level::wgsl_mirrors::CSM_OUTPUTS;
    for group in 0..(terms / 2).div_ceil(per) {
        let mut slots = Vec::new();
        for j in 0..per.min(terms / 2 - group * per) {
            let out = format!("basis{}", group * per + j);
            graph.resource(
                &out,
                wgpu::TextureFormat::Rgba32Float,
                SizeRule::Reduced {
                    of: "in".into(),
                    shift: 0,
                },
                Some(0),
            );
            slots.push((format!("dst{j}"), out.clone()));
            outputs.push(out);
        }
        graph.node(Node {
            name: format!("basis.{group}"),
            kernel: shadowgraph::low_level::kernels::KernelId::Csm,
            inputs: vec![("src".into(), "in".into())],
            dispatch: Dispatch::Texels(slots[0].1.clone()),
            params: bytemuck::bytes_of(&shadowgraph::low_level::wgsl_mirrors::CsmParams {
                depth: shadowgraph::low_level::wgsl_mirrors::LinearizeParams::ORTHOGRAPHIC,
                first_map: group * per,
                maps: slots.len() as u32,
                terms,
                moments: 0,
            })
            .to_vec(),
            outputs: slots,
            light: Some(0),
        });
    }
    let names: Vec<&str> = outputs.iter().map(String::as_str).collect();
    let p = plan(&graph, &names).expect("plan");
    let input = super::upload(
        &g.device,
        &g.queue,
        "test.trig",
        (w, h),
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(&z),
    );
    let mut exec = shadowgraph::low_level::exec::Executor::new();
    let csm = shadowgraph::low_level::kernels::resolve("csm", None).expect("csm");
    let unclamped = csm.replace("let z = linear_depth(raw, params.depth);", "let z = raw;");
    assert_ne!(csm, unclamped, "csm's depth read changed");
    exec.kernels
        .insert_generated(&g.device, "csm", None, &unclamped)
        .expect("csm probe");
    let imports = HashMap::from([("in".to_string(), input)]);
    let mut enc = g.device.create_command_encoder(&Default::default());
    let out = exec
        .record(&g.device, &mut enc, &p, &imports, None)
        .expect("record");
    shadowgraph::low_level::gpu::submit_and_wait(&g.device, &g.queue, enc, "trig").expect("submit");
    let mut worst: f64 = 0.0;
    for (chunk, name) in outputs.iter().enumerate() {
        let (_, data) = shadowgraph::low_level::gpu::read_float_texture(
            &g.device,
            &g.queue,
            &out.textures[name],
            0,
        )
        .expect("readback");
        for (i, texel) in data.chunks(4).enumerate() {
            let zi = f64::from(z[i]);
            for j in 0..2 {
                let k = 2 * chunk as u32 + 1 + j as u32;
                let c = std::f64::consts::PI * f64::from(2 * k - 1);
                let e_sin = (f64::from(texel[2 * j]) - (c * zi).sin()).abs();
                let e_cos = (f64::from(texel[2 * j + 1]) - (c * zi).cos()).abs();
                worst = worst.max(e_sin).max(e_cos);
            }
        }
    }
    // The depth itself is exact in f32 here; the reference's argument is the f32 value.
    assert!(
        worst <= 2f64.powi(-11),
        "sin/cos error {worst:e} exceeds Vulkan's 2⁻¹¹"
    );
    2.0 * worst + ULP
}

/// Side of the random maps (not a power of two).
pub const MAP: usize = 61;
/// The directional light of the random-map tests.
pub const DIR: LightKind = LightKind::Directional { extent: 5.0 };
/// The spot light of the random-map tests.
pub const SPOT: LightKind = LightKind::Spot { fov_degrees: 60.0 };

/// A soft technique's table settings for the random maps (search cap 0.25 of 61 texels).
pub fn soft(storage: Storage, sums: SatVariant) -> Soft {
    Soft {
        storage,
        sums,
        max_search: 0.25,
    }
}

/// A light over the random map: search squares of about 10 (directional, 2 units wide) and
/// 30 texels (spot, 0.3 wide), capped at 30.5 texels (`max_search` 0.25 of 61).
pub fn light(kind: LightKind, technique: Technique) -> Light {
    let (position, near, far, size) = match kind {
        LightKind::Directional { .. } => (Vec3::new(-3.0, 10.0, 2.0), 2.0, 20.0, 2.0),
        LightKind::Spot { .. } | LightKind::Point => (Vec3::new(1.0, 8.0, -1.0), 0.5, 20.0, 0.3),
    };
    Light {
        kind,
        position,
        target: Vec3::ZERO,
        near,
        far,
        size,
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

/// A representation's summed-area tables, four channels each, as the GPU would hold them.
pub struct Tables {
    /// Per table, its words (fixed: u32 bit patterns as f32; float: f32 sums).
    pub words: Vec<Vec<f32>>,
    /// The tables' format.
    pub format: wgpu::TextureFormat,
    /// What the tables sum, decoded (the fixed variant's exact quantized values), in the
    /// representation's channel layout: the values the lookups integrate.
    pub decoded: Texels,
}

/// The tables of `rep` (rounded to f32 as a texture stores it) coded by `coding`. A float
/// table is the f64 SAT of the centred values rounded to f32 (the GPU builds its own; what
/// matters here is that the reference integrates what this table holds).
pub fn tables(rep: &Texels, coding: &SatCoding) -> Tables {
    let (w, h) = (rep.width, rep.height);
    let mut words = Vec::new();
    let mut chunks = Vec::new();
    for first in (0..rep.channels).step_by(4) {
        let n = (rep.channels - first).min(4);
        let chunk = Texels {
            width: w,
            height: h,
            channels: n,
            data: rep
                .data
                .chunks(rep.channels)
                .flat_map(|t| t[first..first + n].iter().map(|&v| f64::from(v as f32)))
                .collect(),
        };
        let raw: Vec<u32> = match coding.variant {
            SatVariant::Fixed => cpu::sat::sat_fixed(&chunk, coding)
                .into_iter()
                .flatten()
                .collect(),
            SatVariant::Float => cpu::sat::sat(&cpu::sat::scaled_texels(&chunk, coding))
                .data
                .iter()
                .map(|&v| (v as f32).to_bits())
                .collect(),
        };
        chunks.push((
            n,
            shadowgraph::low_level::sat::decode_table(&raw, w, h, coding, n),
        ));
        words.push(raw.into_iter().map(f32::from_bits).collect());
    }
    let data = (0..w * h)
        .flat_map(|t| {
            chunks
                .iter()
                .flat_map(move |(n, d)| d[t * n..(t + 1) * n].iter().map(|&v| f64::from(v)))
        })
        .collect();
    Tables {
        words,
        format: coding.variant.format(4),
        decoded: Texels {
            width: w,
            height: h,
            channels: rep.channels,
            data,
        },
    }
}

/// f32 rounding of a representation, as a texture stores it.
pub fn rounded(t: Texels) -> Texels {
    Texels {
        data: t.data.iter().map(|&v| f64::from(v as f32)).collect(),
        ..t
    }
}

/// Soft VSM with `sums`, bleed reduction 0.1.
pub fn vssm(sums: SatVariant) -> Technique {
    Technique::Vssm {
        soft: soft(Storage::F32, sums),
        bleed: 0.1,
        min_variance: 1e-5,
    }
}

/// Soft MSM at `storage` with the scene default moment bias.
pub fn msm_soft(storage: Storage, hausdorff: bool) -> Technique {
    Technique::MsmSoft {
        soft: soft(storage, SatVariant::Fixed),
        hausdorff,
        moment_bias: shadowgraph::low_level::model::default_moment_bias(storage),
        bleed: 0.0,
    }
}

/// `t` (a soft technique) with its tables' sums `sums` (f32 ones are read with filtered
/// fetches).
pub fn with_sums(mut t: Technique, sums: SatVariant) -> Technique {
    t.soft_mut().expect("a soft technique").sums = sums;
    t
}

/// CSSM with `terms` terms, offset ½/M, scale 2, the given sharpening and blocker search, and
/// the default two-depth resolve ([`cssm_resolved`]: another).
pub fn cssm(terms: u32, sharpen: f32, sharpen_falloff: f32, search: CssmSearch) -> Technique {
    cssm_resolved(
        terms,
        sharpen,
        sharpen_falloff,
        search,
        CssmResolve::TwoDepth,
    )
}

/// [`cssm`] with the resolve `resolve`.
pub fn cssm_resolved(
    terms: u32,
    sharpen: f32,
    sharpen_falloff: f32,
    search: CssmSearch,
    resolve: CssmResolve,
) -> Technique {
    Technique::Cssm {
        soft: soft(Storage::F32, SatVariant::Fixed),
        terms,
        attenuation: 1.0,
        offset: 0.5 / terms as f32,
        scale: 2.0,
        sharpen,
        sharpen_falloff,
        search,
        resolve,
    }
}
