//! `shadowgraph dump`: every resource of the executed plan written to disk for inspection.
//!
//! Per texture and mip level: one 32-bit float OpenEXR with named channels, one grayscale PNG
//! preview per channel (normalized by that channel's own finite range, non-finite texels red),
//! and an entry in `manifest.json` with provenance and per-channel statistics. Two-moment VSM
//! maps also get a variance view, σ² = max(E\[z²\] − E\[z\]², 0).

use std::collections::HashSet;
use std::fmt::Write;
use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::io::{deinterleave, write_exr, write_png};
use crate::render::{DumpedResource, FloatMap, RenderOptions, Renderer, plan_lights_for};
use crate::scene::Scene;
use crate::technique::{ChannelNaming, MapChannels, map_kinds};

/// Statistics of one channel: range and mean over the finite values, and the non-finite count.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ChannelStats {
    /// Smallest finite value (`None` when no value is finite).
    pub min: Option<f64>,
    /// Largest finite value (`None` when no value is finite).
    pub max: Option<f64>,
    /// Mean of the finite values, summed in f64 (`None` when no value is finite).
    pub mean: Option<f64>,
    /// Number of NaN values.
    pub nan: u64,
    /// Number of ±Inf values.
    pub inf: u64,
}

/// Min, max and mean over the finite values of `values`, and the NaN and ±Inf counts.
pub fn channel_stats(values: &[f32]) -> ChannelStats {
    let mut s = ChannelStats::default();
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, 0u64);
    for &v in values {
        if v.is_nan() {
            s.nan += 1;
        } else if v.is_infinite() {
            s.inf += 1;
        } else {
            let v = f64::from(v);
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
            n += 1;
        }
    }
    if n > 0 {
        s.min = Some(lo);
        s.max = Some(hi);
        s.mean = Some(sum / n as f64);
    }
    s
}

/// Channel names of the kinds every light has; each technique's maps name theirs in its
/// registry entry ([`crate::technique::TechniqueDef::maps`]). Kinds named in neither get generic
/// names `c0`, `c1`, ….
const LIGHT_MAPS: &[MapChannels] = &[
    // Rasterized depth (Depth32Float, the imported map).
    MapChannels {
        kind: "depth",
        naming: ChannelNaming::Fixed(&["depth"]),
    },
    // Linear depth (R32Float).
    MapChannels {
        kind: "linear",
        naming: ChannelNaming::Fixed(&["z"]),
    },
];

/// The kind of a resource: what follows `light{i}.` up to the next `.` (`light0.vsm.blur_h` →
/// `vsm`). `None` for names not of that shape.
pub fn resource_kind(resource: &str) -> Option<&str> {
    let (light, rest) = resource.split_once('.')?;
    let index = light.strip_prefix("light")?;
    if index.is_empty() || !index.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    rest.split('.').next().filter(|k| !k.is_empty())
}

/// Every kind with named channels: the light's own, then each technique's.
fn kinds() -> impl Iterator<Item = &'static MapChannels> {
    LIGHT_MAPS.iter().chain(map_kinds())
}

/// Looks `kind` up in [`kinds`]: an exact match, else a [`ChannelNaming::Fourier`] row whose
/// kind is `kind` without its trailing chunk index. Returns the row and the index.
fn lookup(kind: &str) -> Option<(&'static MapChannels, usize)> {
    if let Some(row) = kinds().find(|r| r.kind == kind) {
        return Some((row, 0));
    }
    let base = kind.trim_end_matches(|c: char| c.is_ascii_digit());
    let chunk = kind[base.len()..].parse().ok()?;
    kinds()
        .find(|r| r.kind == base && matches!(r.naming, ChannelNaming::Fourier))
        .map(|r| (r, chunk))
}

/// The names of the channels of `resource` worth dumping, from its kind (the light's maps and
/// each technique's entry, [`crate::technique::TechniqueDef::maps`]); their count may be below `channels` (padding is dropped). Unknown kinds
/// get `c0`, `c1`, … (`depth` for depth formats).
pub fn channel_names(resource: &str, format: wgpu::TextureFormat, channels: usize) -> Vec<String> {
    let generic = || -> Vec<String> {
        if format.is_depth_stencil_format() && channels == 1 {
            return vec!["depth".into()];
        }
        (0..channels).map(|c| format!("c{c}")).collect()
    };
    let Some((row, chunk)) = resource_kind(resource).and_then(lookup) else {
        return generic();
    };
    match row.naming {
        ChannelNaming::Fixed(names) => names.iter().take(channels).map(|s| s.to_string()).collect(),
        ChannelNaming::Fourier => {
            let pairs = channels / 2;
            (0..pairs * 2)
                .map(|c| {
                    let j = 2 * chunk + c / 2 + 1;
                    format!("{}_{j}", if c % 2 == 0 { "sin" } else { "cos" })
                })
                .collect()
        }
    }
}

/// One entry of `manifest.json`: one EXR (a resource at one mip level, or a derived view).
#[derive(Clone, Debug, Serialize)]
pub struct ManifestEntry {
    /// The graph resource (`<resource>.variance` for the variance view).
    pub name: String,
    /// The EXR file, relative to the output folder.
    pub file: String,
    /// The light it belongs to.
    pub light: Option<usize>,
    /// The kernel that wrote it (`null` for imports, i.e. the rasterized depth map).
    pub producer: Option<String>,
    /// Texel format (`Debug` of the `wgpu::TextureFormat`; `R32Float` for derived views).
    pub format: String,
    /// Width of this mip level.
    pub width: u32,
    /// Height of this mip level.
    pub height: u32,
    /// Mip level.
    pub mip_level: u32,
    /// For a derived view, the resource it was computed from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// Channels, in texel order.
    pub channels: Vec<ManifestChannel>,
}

/// One channel of a [`ManifestEntry`].
#[derive(Clone, Debug, Serialize)]
pub struct ManifestChannel {
    /// Channel name (as in the EXR).
    pub name: String,
    /// Its statistics.
    #[serde(flatten)]
    pub stats: ChannelStats,
    /// Its PNG preview, relative to the output folder.
    pub preview: String,
}

/// `manifest.json`: the scene, the adapter and every file written.
#[derive(Clone, Debug, Serialize)]
pub struct Manifest {
    /// The scene file, as given.
    pub scene: String,
    /// The adapter that rendered it.
    pub adapter: String,
    /// One entry per EXR written.
    pub resources: Vec<ManifestEntry>,
}

/// An image about to be written: `<stem>.exr` plus `<preview_stem>.<channel>.png` per channel.
struct Image {
    stem: String,
    preview_stem: String,
    width: u32,
    height: u32,
    channels: Vec<(String, Vec<f32>)>,
}

/// Writes files into one folder, remembering what it wrote (names must not repeat).
struct Writer<'a> {
    out: &'a Path,
    written: HashSet<String>,
    report: String,
}

impl Writer<'_> {
    fn claim(&mut self, file: &str) -> Result<std::path::PathBuf> {
        if !self.written.insert(file.to_string()) {
            return Err(Error::Invalid(format!("dump would write `{file}` twice")));
        }
        let path = self.out.join(file);
        let _ = writeln!(self.report, "wrote {}", path.display());
        Ok(path)
    }

    /// Writes the EXR and the previews of `img`; returns the EXR's name and its channels.
    fn image(&mut self, img: Image) -> Result<(String, Vec<ManifestChannel>)> {
        let mut channels = Vec::new();
        for (name, values) in &img.channels {
            let stats = channel_stats(values);
            let preview = format!("{}.{name}.png", img.preview_stem);
            let rgba = preview_rgba(values, &stats);
            write_png(&self.claim(&preview)?, img.width, img.height, &rgba)?;
            channels.push(ManifestChannel {
                name: name.clone(),
                stats,
                preview,
            });
        }
        let file = format!("{}.exr", img.stem);
        write_exr(&self.claim(&file)?, img.width, img.height, img.channels)?;
        Ok((file, channels))
    }
}

/// A grayscale RGBA8 preview of one channel whose statistics are `stats`: each value mapped
/// from the channel's finite `min..max` to black..white (mid-gray when the channel is
/// constant), NaN and ±Inf drawn red.
pub fn preview_rgba(values: &[f32], stats: &ChannelStats) -> Vec<u8> {
    let (lo, hi) = (stats.min.unwrap_or(0.0), stats.max.unwrap_or(0.0));
    values
        .iter()
        .flat_map(|&v| {
            if !v.is_finite() {
                return [255, 0, 0, 255];
            }
            let g = if hi > lo {
                ((f64::from(v) - lo) / (hi - lo) * 255.0).round() as u8
            } else {
                128
            };
            [g, g, g, 255]
        })
        .collect()
}

/// σ² = max(E\[z²\] − E\[z\]², 0) per texel, in f64; NaN where the moments give no number.
pub fn variance_view(z: &[f32], z2: &[f32]) -> Vec<f32> {
    z.iter()
        .zip(z2)
        .map(|(&m1, &m2)| {
            let (m1, m2) = (f64::from(m1), f64::from(m2));
            let v = m2 - m1 * m1;
            if v.is_nan() {
                f32::NAN
            } else {
                v.max(0.0) as f32
            }
        })
        .collect()
}

/// `<resource>` at mip 0, `<resource>.mip<L>` above: the stem of that level's files.
fn level_stem(resource: &str, level: u32) -> String {
    if level == 0 {
        resource.to_string()
    } else {
        format!("{resource}.mip{level}")
    }
}

/// Writes every mip level of `res` (and its variance view for VSM kinds) with `w`.
fn write_resource(
    w: &mut Writer,
    res: &DumpedResource,
    entries: &mut Vec<ManifestEntry>,
) -> Result<()> {
    for (level, map) in (0u32..).zip(&res.levels) {
        let names = channel_names(&map.resource, res.format, map.channels);
        warn_padding(w, map, names.len());
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let channels = deinterleave(&map.data, map.channels, &refs);
        let stem = level_stem(&map.resource, level);
        let variance = (resource_kind(&map.resource) == Some("vsm") && channels.len() == 2)
            .then(|| variance_view(&channels[0].1, &channels[1].1));
        let (file, stats) = w.image(Image {
            stem: stem.clone(),
            preview_stem: stem.clone(),
            width: map.width,
            height: map.height,
            channels,
        })?;
        let entry = ManifestEntry {
            name: map.resource.clone(),
            file,
            light: res.light,
            producer: res.producer.clone(),
            format: crate::graph::format_label(res.format),
            width: map.width,
            height: map.height,
            mip_level: level,
            source: None,
            channels: stats,
        };
        if let Some(v) = variance {
            let (file, stats) = w.image(Image {
                stem: format!("{stem}.variance"),
                preview_stem: stem,
                width: map.width,
                height: map.height,
                channels: vec![("variance".into(), v)],
            })?;
            let view = ManifestEntry {
                name: format!("{}.variance", map.resource),
                file,
                producer: Some("dump (variance view)".into()),
                format: format!("{:?}", wgpu::TextureFormat::R32Float),
                source: Some(map.resource.clone()),
                channels: stats,
                ..entry.clone()
            };
            entries.extend([entry, view]);
        } else {
            entries.push(entry);
        }
    }
    Ok(())
}

/// Notes in the report when channels dropped as padding hold anything but zeros.
fn warn_padding(w: &mut Writer, map: &FloatMap, kept: usize) {
    if kept >= map.channels {
        return;
    }
    let nonzero = map
        .data
        .chunks_exact(map.channels)
        .filter(|t| t[kept..].iter().any(|&v| v != 0.0))
        .count();
    if nonzero > 0 {
        let _ = writeln!(
            w.report,
            "warning: {}: {nonzero} texel(s) with non-zero padding channels (not dumped)",
            map.resource
        );
    }
}

/// Notes in the report every channel with NaN or ±Inf values.
fn warn_non_finite(report: &mut String, entries: &[ManifestEntry]) {
    for e in entries {
        for c in e.channels.iter().filter(|c| c.stats.nan + c.stats.inf > 0) {
            let _ = writeln!(
                report,
                "warning: {} channel {}: {} NaN, {} Inf",
                e.file, c.name, c.stats.nan, c.stats.inf
            );
        }
    }
}

/// `shadowgraph dump`: renders `scene` and writes every resource of the executed plan (or only
/// the resource named `only`: a texture, or one of the tables interleaved in one, whose
/// texture named by `only` writes each of them) into `out` (created if missing) as OpenEXR,
/// PNG previews and `manifest.json`. Returns one line per file written. An unknown `only` is
/// [`Error::Invalid`], listing the resource names.
pub fn dump(gpu: &Gpu, scene: &Path, out: &Path, only: Option<&str>) -> Result<String> {
    let loaded = Scene::load(scene)?;
    let opts = RenderOptions {
        aux: false,
        repeat: 1,
        dump: true,
    };
    let sp = plan_lights_for(&loaded.lights, &opts)?;
    if let Some(name) = only {
        // The plan's textures, and the tables interleaved in one of them, which are dumped
        // (and named) one by one.
        let names: Vec<&str> = sp
            .plan
            .resources
            .iter()
            .flat_map(|r| {
                std::iter::once(r.resource.name.as_str())
                    .chain(r.resource.layers.iter().map(String::as_str))
            })
            .collect();
        if !names.contains(&name) {
            return Err(Error::Invalid(format!(
                "no resource `{name}` in the plan of {}; available: {}",
                scene.display(),
                names.join(", ")
            )));
        }
    }
    // Before the frame: an unusable folder is refused before the GPU work.
    crate::io::make_dir(out)?;
    let frame = Renderer::new(&gpu.device).render(&gpu.device, &gpu.queue, &loaded, opts)?;
    let mut w = Writer {
        out,
        written: HashSet::new(),
        report: String::new(),
    };
    let mut entries = Vec::new();
    for res in &frame.resources {
        let name = res.levels.first().map(|l| l.resource.as_str());
        // An interleaved texture named by `only` is dumped as the tables it holds.
        if only.is_none() || name == only || only == Some(res.texture.as_str()) {
            write_resource(&mut w, res, &mut entries)?;
        }
    }
    let mut report = std::mem::take(&mut w.report);
    warn_non_finite(&mut report, &entries);
    let manifest = Manifest {
        scene: scene.display().to_string(),
        adapter: gpu.describe(),
        resources: entries,
    };
    let json = serde_json::to_string_pretty(&manifest)
        .map_err(|e| Error::Invalid(format!("manifest.json: {e}")))?;
    let path = w.claim("manifest.json")?;
    std::fs::write(&path, json + "\n").map_err(|error| Error::Io { path, error })?;
    report.push_str(&w.report);
    Ok(report)
}
