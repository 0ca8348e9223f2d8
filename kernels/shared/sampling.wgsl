// Texel and tap helpers shared by the visibility functions (import-only module).
// #import shared/light

const GOLDEN_ANGLE: f32 = 2.399963229728653;

// Tap i of n on a Vogel (golden-angle) spiral covering the unit disc evenly.
fn vogel_disc(i: u32, n: u32) -> vec2<f32> {
    let r = sqrt((f32(i) + 0.5) / f32(n));
    let theta = f32(i) * GOLDEN_ANGLE;
    return r * vec2<f32>(cos(theta), sin(theta));
}

// The texel containing uv, clamped to the map.
fn texel_of(uv: vec2<f32>, size: vec2<f32>) -> vec2<i32> {
    let t = vec2<i32>(floor(uv * size));
    return clamp(t, vec2<i32>(0), vec2<i32>(size) - 1);
}

// Linear depth at texel t, clamped to the edge.
// #fetches load_depth: 1
fn load_depth(map: texture_2d<f32>, t: vec2<i32>) -> f32 {
    let size = vec2<i32>(textureDimensions(map));
    return textureLoad(map, clamp(t, vec2<i32>(0), size - 1), 0).r;
}

// Bilinear interpolation of all four channels at uv (texel centres at (i + ½) / size),
// clamp-to-edge, from four loads: exact and filter-feature independent (f32 maps need not be
// filterable).
// #fetches sample_bilinear: 4
fn sample_bilinear(map: texture_2d<f32>, uv: vec2<f32>) -> vec4<f32> {
    return bilinear_level(map, uv, 0);
}

// The size of mip `level`, max(1, size >> level), from level 0's: llvmpipe answers
// textureDimensions(map, level) with one invocation's level when the invocations' levels differ
// (per-pixel footprints), which sends the others' loads out of range.
fn level_size(map: texture_2d<f32>, level: i32) -> vec2<f32> {
    return level_size_of(textureDimensions(map), level);
}

// The size of mip `level` of a map whose level 0 is `size0` texels.
fn level_size_of(size0: vec2<u32>, level: i32) -> vec2<f32> {
    return vec2<f32>(max(size0 >> vec2<u32>(u32(level)), vec2<u32>(1u)));
}

// `sample_bilinear` on mip `level` (texel centres at (i + ½) / level size).
// #fetches bilinear_level: 4
fn bilinear_level(map: texture_2d<f32>, uv: vec2<f32>, level: i32) -> vec4<f32> {
    let size = level_size(map, level);
    let f = uv * size - 0.5;
    let i = vec2<i32>(floor(f));
    let a = f - floor(f);
    let smax = vec2<i32>(size) - 1;
    let t00 = textureLoad(map, clamp(i, vec2<i32>(0), smax), level);
    let t10 = textureLoad(map, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), smax), level);
    let t01 = textureLoad(map, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), smax), level);
    let t11 = textureLoad(map, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), smax), level);
    return mix(mix(t00, t10, a.x), mix(t01, t11, a.x), a.y);
}

// Trilinear sample of a mip chain at `lod` (clamped to the chain).
// #fetches trilinear: 8
fn trilinear(map: texture_2d<f32>, l: Light, uv: vec2<f32>, lod_in: f32) -> vec4<f32> {
    let lod = clamp(lod_in, 0.0, f32(l.mip_levels - 1u));
    let l0 = i32(floor(lod));
    let l1 = min(l0 + 1, i32(l.mip_levels) - 1);
    return mix(bilinear_level(map, uv, l0), bilinear_level(map, uv, l1), lod - floor(lod));
}

// How a pixel's footprint is read from a mip chain: `count` trilinear taps at `lod`, spaced by
// `step` (UV) along the footprint's major axis and centred on the receiver.
struct MipTaps {
    lod: f32,
    count: u32,
    step: vec2<f32>,
}

// With `max_anisotropy` 0 (or no footprint): one tap at log2(filter width). Otherwise the
// footprint's axes a, b (texels) give major = max(|a|, |b|), minor = min; the width is
// w = max(filter width, minor), the taps n = clamp(⌈major / w⌉, 1, max_anisotropy), each at
// level log2(max(w, major / n)), spaced major / n apart along the major axis.
fn mip_taps(l: Light, s: LightSample) -> MipTaps {
    var t: MipTaps;
    t.lod = l.filter_lod;
    t.count = 1u;
    t.step = vec2<f32>(0.0);
    let la = length(s.footprint.xy);
    let lb = length(s.footprint.zw);
    let major = max(la, lb);
    if l.max_anisotropy == 0u || !(major > 0.0) {
        return t;
    }
    let axis = select(s.footprint.zw, s.footprint.xy, la >= lb);
    let w = max(exp2(l.filter_lod), min(la, lb));
    t.count = u32(clamp(ceil(major / w), 1.0, f32(l.max_anisotropy)));
    let n = f32(t.count);
    t.lod = log2(max(w, major / n));
    t.step = axis / (n * l.map_size);
    return t;
}

// The UV of tap k of `t` around uv.
fn mip_tap_uv(t: MipTaps, uv: vec2<f32>, k: u32) -> vec2<f32> {
    return uv + t.step * (f32(k) + 0.5 - 0.5 * f32(t.count));
}

// A light's filtered representation at a receiver: bilinear, or with the `mips` filter
// trilinear at log2(filter width), or along the pixel's footprint (`mip_taps`): each pixel reads
// its own tap count, so the declaration is the most a pixel reads (`max_anisotropy` taps).
// #fetches sample_map: select(4, 8 * max(l.max_anisotropy, 1), l.mip_levels > 1)
fn sample_map(map: texture_2d<f32>, l: Light, s: LightSample) -> vec4<f32> {
    if l.mip_levels <= 1u {
        return sample_bilinear(map, s.uv);
    }
    let t = mip_taps(l, s);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < t.count; k++) {
        sum += trilinear(map, l, mip_tap_uv(t, s.uv, k), t.lod);
    }
    return sum / f32(t.count);
}

// Trilinear sample of a map of logarithms at `lod`, as a logarithm.
// #fetches trilinear_log: 8
fn trilinear_log(map: texture_2d<f32>, l: Light, uv: vec2<f32>, lod_in: f32) -> f32 {
    let lod = clamp(lod_in, 0.0, f32(l.mip_levels - 1u));
    let l0 = i32(floor(lod));
    let l1 = min(l0 + 1, i32(l.mip_levels) - 1);
    let v0 = bilinear_log_level(map, uv, l0);
    let v1 = bilinear_log_level(map, uv, l1);
    let t = lod - floor(lod);
    let m = max(v0, v1);
    return m + log((1.0 - t) * exp(v0 - m) + t * exp(v1 - m));
}

// linstep(lo, hi, x): the light-bleeding reduction of VSM-family techniques.
fn linstep(lo: f32, hi: f32, x: f32) -> f32 {
    return clamp((x - lo) / (hi - lo), 0.0, 1.0);
}

// Bilinear interpolation of exp(v) for a map of logarithms v (channel 0), returned as a
// logarithm: log Σ wᵢ exp(vᵢ), evaluated around the largest tap so nothing overflows.
// #fetches sample_bilinear_log: 4
fn sample_bilinear_log(map: texture_2d<f32>, uv: vec2<f32>) -> f32 {
    return bilinear_log_level(map, uv, 0);
}

// `sample_map` for a map of logarithms: the same weights applied to exp(v), as a logarithm
// (taps combined around the largest so far, so nothing overflows).
// #fetches sample_map_log: select(4, 8 * max(l.max_anisotropy, 1), l.mip_levels > 1)
fn sample_map_log(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    if l.mip_levels <= 1u {
        return sample_bilinear_log(map, s.uv);
    }
    let t = mip_taps(l, s);
    // A running log-sum-exp: m the largest tap so far, sum = Σ exp(tap − m).
    var m = trilinear_log(map, l, mip_tap_uv(t, s.uv, 0u), t.lod);
    var sum = 1.0;
    for (var k = 1u; k < t.count; k++) {
        let v = trilinear_log(map, l, mip_tap_uv(t, s.uv, k), t.lod);
        let m2 = max(m, v);
        sum = sum * exp(m - m2) + exp(v - m2);
        m = m2;
    }
    return m + log(sum / f32(t.count));
}

// `sample_bilinear_log` on mip `level`.
// #fetches bilinear_log_level: 4
fn bilinear_log_level(map: texture_2d<f32>, uv: vec2<f32>, level: i32) -> f32 {
    let size = level_size(map, level);
    let f = uv * size - 0.5;
    let i = vec2<i32>(floor(f));
    let a = f - floor(f);
    let smax = vec2<i32>(size) - 1;
    let v00 = textureLoad(map, clamp(i, vec2<i32>(0), smax), level).r;
    let v10 = textureLoad(map, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), smax), level).r;
    let v01 = textureLoad(map, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), smax), level).r;
    let v11 = textureLoad(map, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), smax), level).r;
    let m = max(max(v00, v10), max(v01, v11));
    let sum = (1.0 - a.y) * ((1.0 - a.x) * exp(v00 - m) + a.x * exp(v10 - m))
        + a.y * ((1.0 - a.x) * exp(v01 - m) + a.x * exp(v11 - m));
    return m + log(sum);
}
