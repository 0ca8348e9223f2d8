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
