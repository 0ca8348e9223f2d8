//! Case 4: exponential warps at and past the storage limits (`scene::exponent_limit`: 42 for
//! fp32, 5.54 for fp16, from ln(FLT_MAX) = 88.7 and ln(65504) = 11.09 halved for the squared
//! moment). EVSM4 at both limits and ESM far past them (c = 200 and 10⁴, the validator's
//! largest) run on a depth map with blocks of exactly 0 and 1 (the extreme moments) through
//! the scene graph with a blur and with mips, every stage compared with the f64 stage
//! (`stages`), then the encoded map goes through `add_sat` with a coding chosen from its
//! value range ([`sat_coding_for`]). Past the limits the validator must clamp (EVSM) or
//! refuse (beyond its range) the exponent; what the clamp prevents is shown by encoding with
//! an unclamped exponent.
//!
//! The rows above apply `add_sat` to the encoded map directly; [`scene_sat_rows`] runs the
//! scene path too: `filter = "sat"` scenes whose exponents the validator clamps to the table's
//! limit (`scene::sat_exponent_limit`), rendered, their tables decoded texel by texel against
//! the f64 encoding of the GPU's linear map within the coding's step, and their visibility.

use std::collections::HashMap;
use std::path::Path;

use super::StabilityRow;
use super::check::{Check, Rng, U};
use super::harness::{DIRECTIONAL, Poison, light, mips, registered, run_graph};
use super::stages::{Stages, run_stages};
use crate::cpu::{self, Texels};
use crate::error::{Error, Result};
use crate::exec::Executor;
use crate::gpu::{Gpu, read_texture};
use crate::graph::Graph;
use crate::model::ParamValue;
use crate::technique::{Encoding, encoding};
use crate::{
    model::SatVariant,
    sat::{SatCoding, add_sat, float_sum_depth},
};
use crate::{
    model::{BlurKernel, Filter, Storage, Technique, exponent_limit},
    scene::Scene,
};

const MAP: u32 = 64;

/// The coding of a summed-area table for values in `[lo[c], hi[c]]` on a map of `map_area`
/// texels, looked up in windows of up to `max_window` texels: f32 sums (centred on the range)
/// when no prefix sum can overflow, i.e. `map_area · max ½(hi − lo)` stays below `FLT_MAX / 2`
/// (a factor 2 above any rounding growth); otherwise fixed point, which cannot overflow (codes
/// are clamped and the sums wrap) and keeps every window of up to `max_window` texels exact,
/// at a quantization of `½/scale` per texel that grows with the range. Errors for an invalid
/// range or window area.
pub fn sat_coding_for(
    lo: [f32; 4],
    hi: [f32; 4],
    map_area: u64,
    max_window: u64,
) -> Result<SatCoding> {
    let half = (0..4)
        .map(|c| 0.5 * (f64::from(hi[c]) - f64::from(lo[c])))
        .fold(0.0, f64::max);
    if map_area as f64 * half <= f64::from(f32::MAX) / 2.0 {
        SatCoding::float(lo, hi)
    } else {
        SatCoding::fixed(max_window, lo, hi)
    }
}

/// The depth map: a smooth random field with steps, a block of exactly 0, a block of exactly 1
/// and single texels of 0 and 1.
fn depth_map(rng: &mut Rng) -> Vec<f32> {
    let n = MAP as usize;
    let (a, b) = (rng.range(-0.3, 0.3), rng.range(-0.3, 0.3));
    (0..n * n)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            if (4..14).contains(&x) && (4..14).contains(&y) {
                return 0.0;
            }
            if (40..60).contains(&x) && (30..50).contains(&y) {
                return 1.0;
            }
            if rng.below(50) == 0 {
                return [0.0, 1.0][rng.below(2)];
            }
            let (u, v) = (x as f64 / n as f64, y as f64 / n as f64);
            let step = if rng.below(20) == 0 { -0.3 } else { 0.0 };
            (0.5 + a * u + b * v + step + rng.range(0.0, 0.01)).clamp(0.0, 1.0) as f32
        })
        .collect()
}

fn filters() -> [Filter; 2] {
    [
        Filter::Blur {
            radius: 3.0,
            sigma: 1.5,
            kernel: BlurKernel::Gaussian,
        },
        mips(4.0),
    ]
}

fn evsm4(storage: Storage, filter: Filter, c: f32) -> Technique {
    let c = ParamValue::Float(c);
    registered(
        "evsm4",
        Some(storage),
        filter,
        &[("exponent_pos", c), ("exponent_neg", c)],
    )
}

fn esm(filter: Filter, c: f32) -> Technique {
    registered("esm", None, filter, &[("exponent", ParamValue::Float(c))])
}

/// Rows of one configuration: encode, blur, mips (stages), then the SAT of the encoded map.
fn configuration(
    gpu: &Gpu,
    exec: &mut Executor,
    raw: &[f32],
    name: &str,
    storage: &str,
    technique: impl Fn(Filter) -> Technique,
) -> Result<Vec<StabilityRow>> {
    let mut rows = Vec::new();
    let mut sat = Vec::new();
    for (i, filter) in filters().into_iter().enumerate() {
        let l = light(DIRECTIONAL, technique(filter), MAP, 0.002);
        let Some(Stages {
            encode,
            mut filter,
            filter_name,
            nonfinite,
            ran,
            encoded,
            ..
        }) = run_stages(gpu, exec, &l, raw)?
        else {
            return Err(Error::Invalid(format!("{name} has no prefiltered map")));
        };
        if nonfinite > 0 {
            filter.problem(format!(
                "{nonfinite} NaN/Inf texels in the graph's resources"
            ));
        }
        if i == 0 {
            rows.push(encode.row(4, "encode vs f64", name, storage));
        }
        rows.push(filter.row(4, &format!("{filter_name} vs f64"), name, storage));
        if i == 0 {
            let (resource, _, texels) = &encoded[0];
            let texture = ran.outputs.textures[resource].clone();
            sat = sat_rows(gpu, &texture, texels, name, storage)?;
        }
    }
    rows.extend(sat);
    Ok(rows)
}

/// Per-channel `[min, max]` of `t` (unused channels `[0, 0]`).
pub(crate) fn range(t: &Texels) -> ([f32; 4], [f32; 4]) {
    let (mut lo, mut hi) = ([0.0f32; 4], [0.0f32; 4]);
    for c in 0..t.channels.min(4) {
        let v = t.data.iter().skip(c).step_by(t.channels).map(|&v| v as f32);
        lo[c] = v.clone().fold(f32::INFINITY, f32::min);
        hi[c] = v.fold(f32::NEG_INFINITY, f32::max);
    }
    (lo, hi)
}

/// `add_sat` over the GPU's encoded map with the coding [`sat_coding_for`] picks for its range
/// (whole-map windows), checked; the other coding reported beside it.
fn sat_rows(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    texels: &Texels,
    name: &str,
    storage: &str,
) -> Result<Vec<StabilityRow>> {
    let (lo, hi) = range(texels);
    let area = (texels.width * texels.height) as u64;
    let chosen = sat_coding_for(lo, hi, area, area)?;
    let other = match chosen.variant {
        SatVariant::Float => SatCoding::fixed(area, lo, hi)?,
        SatVariant::Fixed => SatCoding::float(lo, hi)?,
    };
    let mut rows = Vec::new();
    for (coding, is_chosen) in [(chosen, true), (other, false)] {
        let (check, nonfinite) = sat_check(gpu, texture, texels, &coding, (lo, hi))?;
        let variant = match coding.variant {
            SatVariant::Fixed => "sat fixed u32",
            SatVariant::Float => "sat f32",
        };
        let what = "SAT window means / range vs f64";
        if is_chosen {
            let mut row = check.row(4, &format!("{what} (chosen coding)"), name, storage);
            row.storage = format!("{storage} → {variant}");
            rows.push(row);
        } else {
            let mut row = check.row(4, &format!("{what} (other coding)"), name, storage);
            row.storage = format!("{storage} → {variant}");
            row.nonfinite = nonfinite;
            row.note = format!("not chosen: {}", row.note);
            row.verdict = super::Verdict::Reported;
            rows.push(row);
        }
    }
    Ok(rows)
}

/// Builds the table on the GPU and checks window means of every channel, in units of the
/// channel's range, against f64 sums of the encoded texels. Returns the check and the NaN/Inf
/// count of the table.
pub(crate) fn sat_check(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    texels: &Texels,
    coding: &SatCoding,
    (lo, hi): ([f32; 4], [f32; 4]),
) -> Result<(Check, u64)> {
    let (w, h) = (texels.width, texels.height);
    let mut graph = Graph::default();
    graph.import("in", texture.format(), w as u32, h as u32, Some(0));
    let out = add_sat(&mut graph, 0, "in", coding);
    let imports = HashMap::from([("in".to_string(), texture.clone())]);
    let mut exec = Executor::new();
    let ran = run_graph(gpu, &mut exec, &graph, &[&out], imports, false, Poison::All)?;
    let bytes = read_texture(&gpu.device, &gpu.queue, &ran.outputs.textures[&out], 0)?;
    // The table's words, each texel widened to 4 (the channels it lacks read 0).
    let fixed = cpu::sat::widen(bytemuck::cast_slice(&bytes), w * h);
    let words = fixed.as_flattened();
    let exact = cpu::sat::sat(texels);
    let k = texels.channels.min(4);
    let dev = |c: usize| {
        let o = f64::from(coding.offset[c]);
        cpu::sat::sat(&Texels {
            data: texels.data.iter().map(|v| (v - o).abs()).collect(),
            ..texels.clone()
        })
    };
    let devs: Vec<Texels> = (0..k).map(dev).collect();
    let float_table = Texels {
        width: w,
        height: h,
        channels: 4,
        data: words
            .iter()
            .map(|&b| f64::from(f32::from_bits(b)))
            .collect(),
    };
    let nonfinite = match coding.variant {
        SatVariant::Float => float_table.data.iter().filter(|v| !v.is_finite()).count() as u64,
        SatVariant::Fixed => 0,
    };
    let depth = f64::from(float_sum_depth(w as u32, h as u32));
    let mut check = Check::new();
    let mut rng = Rng::new(0x4E5A7);
    let mut wins = vec![
        [0, 0, w, h],
        [w - 1, h - 1, w, h],
        [0, 0, 1, 1],
        [w - 5, h - 3, w, h],
    ];
    for _ in 0..300 {
        let (a, b) = (rng.below(w + 1), rng.below(w + 1));
        let (c, d) = (rng.below(h + 1), rng.below(h + 1));
        if a != b && c != d {
            wins.push([a.min(b), c.min(d), a.max(b), c.max(d)]);
        }
    }
    for [x0, y0, x1, y1] in wins {
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let want = cpu::sat::window(&exact, x0, y0, x1, y1);
        let codes = cpu::sat::window_fixed(&fixed, w, x0, y0, x1, y1);
        let floats = cpu::sat::window(&float_table, x0, y0, x1, y1);
        let corner_sum = |c: usize| -> f64 {
            [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
                .iter()
                .map(|&(x, y)| cpu::sat::window(&devs[c], 0, 0, x, y)[c])
                .sum()
        };
        for c in 0..k {
            let o = f64::from(coding.offset[c]);
            let spread = cpu::sat::window(&devs[c], x0, y0, x1, y1)[c];
            let (got, bound) = match coding.variant {
                SatVariant::Fixed => (
                    cpu::sat::decode_window(f64::from(codes[c]), area, coding, c),
                    area * 0.5 / f64::from(coding.scale[c]) + U * spread,
                ),
                SatVariant::Float => (
                    floats[c] + area * o,
                    (depth + 3.0) * U * corner_sum(c) + U * (want[c] - area * o).abs() + U * spread,
                ),
            };
            let unit = (f64::from(hi[c]) - f64::from(lo[c])).max(f64::MIN_POSITIVE) * area;
            let bound = (bound + U * want[c].abs()) / unit + 1e-12;
            check.compare(got / unit, want[c] / unit, bound, || {
                format!("{}x{} window ({x0}, {y0}) channel {c}", x1 - x0, y1 - y0)
            });
        }
    }
    Ok((check, nonfinite))
}

/// Encodes with an exponent the validator would clamp: the Inf count and the largest relative
/// error against the f64 encoding (a driver that converts to f16 toward zero saturates at
/// 65504 instead of overflowing, so the values are wrong without being infinite).
fn unclamped(
    gpu: &Gpu,
    exec: &mut Executor,
    raw: &[f32],
    storage: Storage,
    c: f32,
) -> Result<StabilityRow> {
    let l = light(DIRECTIONAL, evsm4(storage, Filter::None, c), MAP, 0.002);
    let s = run_stages(gpu, exec, &l, raw)?
        .ok_or_else(|| Error::Invalid("evsm has a prefiltered map".into()))?;
    let linear = s.ran.texels(gpu, &crate::technique::linear_name(0), 0)?;
    let want = cpu::evsm::evsm(&linear, c.into(), c.into());
    let got = &s.encoded[0].2;
    let (mut inf, mut worst) = (0u64, 0.0f64);
    for (g, w) in got.data.iter().zip(&want.data) {
        if g.is_finite() {
            worst = worst.max((g - w).abs() / w.abs());
        } else {
            inf += 1;
        }
    }
    let limit = exponent_limit(storage);
    let overflow = if storage == Storage::F32 {
        f64::from(f32::MAX).ln() / 2.0
    } else {
        65504f64.ln() / 2.0
    };
    Ok(Check::reported(
        4,
        [
            "encode past the limit (what the clamp prevents)",
            &format!("evsm4 c={c}"),
            super::planar::storage_name(storage),
        ],
        worst,
        f64::NAN,
        inf,
        format!(
            "largest relative error of the finite values; exp(2c) leaves the format past \
             c = {overflow:.2}; scenes clamp to {limit}"
        ),
    ))
}

/// The scene path of `filter = "sat"`: EVSM4 (f32 and f16) and ESM with their default
/// exponents (40, 5 and 80, which the validator clamps to the table's limit for a 9-texel box:
/// ½ ln(2²²/100) = 5.3 and 4× that), a box over a plane at a grazing light so the map spans
/// its depth range. The table decoded texel by texel (`sat::decode_table`, what the lookups
/// integrate) equals the f64 encoding of the GPU's linear map within ½/scale per channel (plus
/// SPIR-V's `exp` to (3 + 2|x|) ULP and 2⁻¹⁰ relative for f16 storage); visibility is finite
/// and in [0, 1].
pub(crate) fn scene_sat_rows(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let path = Path::new("stability.toml");
    let mut rows = Vec::new();
    for (name, shadow, storage) in [
        (
            "evsm4",
            "technique = \"evsm4\"\nformat = \"f32\"",
            Storage::F32,
        ),
        (
            "evsm4",
            "technique = \"evsm4\"\nformat = \"f16\"",
            Storage::F16,
        ),
        ("esm", "technique = \"esm\"", Storage::F32),
    ] {
        let text = format!(
            "[output]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0.0, 4.0, 7.5]\n\
             target = [0.0, 0.0, 0.0]\nfov_y_degrees = 40.0\n\n[[light]]\nkind = \"directional\"\n\
             position = [-5.0, 3.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nextent = 4.0\nnear = 1.0\n\
             far = 14.0\nshadow_map = 128\n\n[light.shadow]\n{shadow}\nfilter = \"sat\"\n\
             filter_width = 9.0\n\n[[object]]\nshape = \"plane\"\nsize = [8.0, 8.0]\n\n\
             [[object]]\nshape = \"box\"\nsize = [1.0, 2.0, 1.0]\ntranslate = [0.0, 1.0, 0.0]\n"
        );
        let scene = Scene::parse(path, &text)?;
        let light = &scene.lights[0];
        let technique = light.shadow.technique;
        let coding = crate::technique::sat_coding(light)?
            .ok_or_else(|| Error::Invalid("sat filter without a coding".into()))?;
        let mut renderer = crate::render::Renderer::new(&gpu.device);
        let frame = renderer.render(
            &gpu.device,
            &gpu.queue,
            &scene,
            crate::render::RenderOptions {
                aux: true,
                repeat: 1,
                dump: false,
            },
        )?;
        let linear = frame.linear_maps[0]
            .as_ref()
            .ok_or_else(|| Error::Invalid("no linear map".into()))?;
        let lin = Texels::from_f32(
            linear.width as usize,
            linear.height as usize,
            1,
            &linear.data,
        );
        let (want, exponent) = match encoding(&technique) {
            Some(Encoding::Evsm { exp_pos, exp_neg }) => (
                cpu::evsm::evsm(&lin, exp_pos.into(), exp_neg.into()),
                exp_pos.max(exp_neg),
            ),
            Some(Encoding::Esm { exponent }) => {
                (cpu::esm::esm_linear(&lin, exponent.into()), exponent)
            }
            _ => return Err(Error::Invalid("case 4 runs exponential techniques".into())),
        };
        let got = &frame.shade_maps[0];
        let mut check = Check::new();
        let f16 = if storage == Storage::F16 {
            2f64.powi(-10)
        } else {
            0.0
        };
        let exp_ulp = (3.0 + 4.0 * f64::from(exponent)) * U * 2.0;
        for (i, (g, w)) in got
            .data
            .chunks(got.channels)
            .zip(want.data.chunks(want.channels))
            .enumerate()
        {
            for c in 0..want.channels.min(got.channels) {
                let step = 0.5 / f64::from(coding.scale[c]) * (1.0 + 2f64.powi(-20));
                let bound = step + (exp_ulp + f16 + 4.0 * U) * w[c].abs();
                check.compare(f64::from(g[c]), w[c], bound, || {
                    format!("texel {i} channel {c}")
                });
            }
        }
        for (i, v) in frame.visibility.iter().enumerate() {
            if !(v.is_finite() && (0.0..=1.0).contains(v)) {
                check.problem(format!("visibility {v} at pixel {i}"));
            }
        }
        let label = format!("{name} c={exponent:.2}");
        rows.push(check.row(
            4,
            "scene filter = \"sat\" (exponent clamped to the table): decoded table vs f64",
            &label,
            &format!("{} → sat fixed u32", super::planar::storage_name(storage)),
        ));
    }
    Ok(rows)
}

/// A one-light scene whose shadow table has `shadow`.
fn scene_text(shadow: &str) -> String {
    format!(
        "[output]\nwidth = 8\nheight = 8\n\n[camera]\nposition = [0.0, 4.0, 7.5]\n\
         target = [0.0, 0.0, 0.0]\nfov_y_degrees = 40.0\n\n[[light]]\nkind = \"directional\"\n\
         position = [-5.0, 9.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nextent = 5.0\n\n\
         [light.shadow]\n{shadow}\n\n[[object]]\nshape = \"plane\"\nsize = [4.0, 4.0]\n"
    )
}

/// The validator: exponents past the storage limit are clamped to it with a warning naming
/// the key; exponents past the accepted range are errors naming the key.
fn validator_rows() -> [StabilityRow; 2] {
    let path = Path::new("stability.toml");
    let mut clamped = Check::new();
    for (shadow, storage, keys) in [
        (
            "technique = \"evsm4\"\nformat = \"f32\"\nexponent_pos = 50.0\nexponent_neg = 60.0",
            Storage::F32,
            2,
        ),
        (
            "technique = \"evsm2\"\nformat = \"f16\"\nexponent_pos = 6.0",
            Storage::F16,
            1,
        ),
    ] {
        let limit = f64::from(exponent_limit(storage));
        match Scene::parse(path, &scene_text(shadow)) {
            Ok(scene) => {
                if let Some(Encoding::Evsm { exp_pos, exp_neg }) =
                    encoding(&scene.lights[0].shadow.technique)
                {
                    clamped.compare(f64::from(exp_pos), limit, 0.0, || "exponent_pos".into());
                    if keys == 2 {
                        clamped.compare(f64::from(exp_neg), limit, 0.0, || "exponent_neg".into());
                    }
                }
                let warned = scene
                    .warnings
                    .iter()
                    .filter(|w| w.contains("exceeds the safe limit"))
                    .count();
                if warned != keys {
                    clamped.problem(format!("{warned} clamp warnings, expected {keys}"));
                }
            }
            Err(e) => clamped.problem(format!("rejected: {e}")),
        }
    }
    let mut refused = Check::new();
    for (shadow, key) in [
        ("technique = \"evsm4\"\nexponent_pos = 2e4", "exponent_pos"),
        ("technique = \"esm\"\nexponent = 2e4", "exponent"),
    ] {
        match Scene::parse(path, &scene_text(shadow)) {
            Ok(_) => refused.problem(format!("`{key}` = 2e4 accepted")),
            Err(e) => {
                let named =
                    e.to_string().contains(key) && e.to_string().contains("stability.toml:");
                refused.compare(f64::from(u8::from(!named)), 0.0, 0.0, || e.to_string());
            }
        }
    }
    [
        clamped.row(
            4,
            "validator: past the limit → clamped, warned",
            "evsm",
            "f32, f16",
        ),
        refused.row(
            4,
            "validator: past the range → error naming key and line",
            "evsm, esm",
            "f32",
        ),
    ]
}

/// Case 4.
pub(crate) fn exponent_case(gpu: &Gpu) -> Result<Vec<StabilityRow>> {
    let mut rng = Rng::new(0xE4);
    let raw = depth_map(&mut rng);
    let mut exec = Executor::new();
    let mut rows = Vec::new();
    for storage in [Storage::F32, Storage::F16] {
        let c = exponent_limit(storage);
        let name = format!("evsm4 c={c}");
        let label = super::planar::storage_name(storage);
        rows.extend(configuration(gpu, &mut exec, &raw, &name, label, |f| {
            evsm4(storage, f, c)
        })?);
    }
    for c in [200.0, 1e4] {
        rows.extend(configuration(
            gpu,
            &mut exec,
            &raw,
            &format!("esm c={c}"),
            "f32",
            |f| esm(f, c),
        )?);
    }
    rows.extend(scene_sat_rows(gpu)?);
    rows.push(unclamped(gpu, &mut exec, &raw, Storage::F32, 45.0)?);
    rows.push(unclamped(gpu, &mut exec, &raw, Storage::F16, 5.6)?);
    rows.extend(validator_rows());
    Ok(rows)
}
