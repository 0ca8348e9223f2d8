// Texel and tap helpers shared by the visibility functions (import-only module).

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
    let size = vec2<f32>(textureDimensions(map));
    let f = uv * size - 0.5;
    let i = vec2<i32>(floor(f));
    let a = f - floor(f);
    let smax = vec2<i32>(size) - 1;
    let t00 = textureLoad(map, clamp(i, vec2<i32>(0), smax), 0);
    let t10 = textureLoad(map, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), smax), 0);
    let t01 = textureLoad(map, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), smax), 0);
    let t11 = textureLoad(map, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), smax), 0);
    return mix(mix(t00, t10, a.x), mix(t01, t11, a.x), a.y);
}

// linstep(lo, hi, x): the light-bleeding reduction of VSM-family techniques.
fn linstep(lo: f32, hi: f32, x: f32) -> f32 {
    return clamp((x - lo) / (hi - lo), 0.0, 1.0);
}

// Bilinear interpolation of exp(v) for a map of logarithms v (channel 0), returned as a
// logarithm: log Σ wᵢ exp(vᵢ), evaluated around the largest tap so nothing overflows.
fn sample_bilinear_log(map: texture_2d<f32>, uv: vec2<f32>) -> f32 {
    let size = vec2<f32>(textureDimensions(map));
    let f = uv * size - 0.5;
    let i = vec2<i32>(floor(f));
    let a = f - floor(f);
    let smax = vec2<i32>(size) - 1;
    let v00 = textureLoad(map, clamp(i, vec2<i32>(0), smax), 0).r;
    let v10 = textureLoad(map, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), smax), 0).r;
    let v01 = textureLoad(map, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), smax), 0).r;
    let v11 = textureLoad(map, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), smax), 0).r;
    let m = max(max(v00, v10), max(v01, v11));
    let sum = (1.0 - a.y) * ((1.0 - a.x) * exp(v00 - m) + a.x * exp(v10 - m))
        + a.y * ((1.0 - a.x) * exp(v01 - m) + a.x * exp(v11 - m));
    return m + log(sum);
}
