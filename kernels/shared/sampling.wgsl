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
fn load_depth(map: texture_2d<f32>, t: vec2<i32>) -> f32 {
    let size = vec2<i32>(textureDimensions(map));
    return textureLoad(map, clamp(t, vec2<i32>(0), size - 1), 0).r;
}

// Bilinear interpolation of all four channels at uv (texel centres at (i + ½) / size),
// clamp-to-edge, from four loads: exact and filter-feature independent (f32 maps need not be
// filterable).
fn sample_bilinear(map: texture_2d<f32>, uv: vec2<f32>) -> vec4<f32> {
    return bilinear_level(map, uv, 0);
}

// `sample_bilinear` on mip `level` (texel centres at (i + ½) / level size).
fn bilinear_level(map: texture_2d<f32>, uv: vec2<f32>, level: i32) -> vec4<f32> {
    let size = vec2<f32>(textureDimensions(map, level));
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

// A light's filtered representation at uv: bilinear, or with the `mips` filter trilinear at
// level log2(filter width) (clamped to the chain).
fn sample_map(map: texture_2d<f32>, l: Light, uv: vec2<f32>) -> vec4<f32> {
    if l.mip_levels <= 1u {
        return sample_bilinear(map, uv);
    }
    let lod = clamp(l.filter_lod, 0.0, f32(l.mip_levels - 1u));
    let l0 = i32(floor(lod));
    let l1 = min(l0 + 1, i32(l.mip_levels) - 1);
    return mix(bilinear_level(map, uv, l0), bilinear_level(map, uv, l1), lod - floor(lod));
}

// linstep(lo, hi, x): the light-bleeding reduction of VSM-family techniques.
fn linstep(lo: f32, hi: f32, x: f32) -> f32 {
    return clamp((x - lo) / (hi - lo), 0.0, 1.0);
}

// Bilinear interpolation of exp(v) for a map of logarithms v (channel 0), returned as a
// logarithm: log Σ wᵢ exp(vᵢ), evaluated around the largest tap so nothing overflows.
fn sample_bilinear_log(map: texture_2d<f32>, uv: vec2<f32>) -> f32 {
    return bilinear_log_level(map, uv, 0);
}

// `sample_map` for a map of logarithms: the same weights applied to exp(v), as a logarithm.
fn sample_map_log(map: texture_2d<f32>, l: Light, uv: vec2<f32>) -> f32 {
    if l.mip_levels <= 1u {
        return sample_bilinear_log(map, uv);
    }
    let lod = clamp(l.filter_lod, 0.0, f32(l.mip_levels - 1u));
    let l0 = i32(floor(lod));
    let l1 = min(l0 + 1, i32(l.mip_levels) - 1);
    let v0 = bilinear_log_level(map, uv, l0);
    let v1 = bilinear_log_level(map, uv, l1);
    let t = lod - floor(lod);
    let m = max(v0, v1);
    return m + log((1.0 - t) * exp(v0 - m) + t * exp(v1 - m));
}

// `sample_bilinear_log` on mip `level`.
fn bilinear_log_level(map: texture_2d<f32>, uv: vec2<f32>, level: i32) -> f32 {
    let size = vec2<f32>(textureDimensions(map, level));
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
