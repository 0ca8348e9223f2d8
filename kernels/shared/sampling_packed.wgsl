// `sample_map` for a map of packed f16 pairs (`graph::PACKED_F16X2`: an r32uint texture, each
// word pack2x16float(moments.xy); import-only module). The same taps and the same arithmetic
// as shared/sampling on the unpacked texels, so a packed map filters exactly as the
// rgba16float map of the same f16 values did; written out again because WGSL has no generic
// over a texture's sample type.
// #import shared/light
// #import shared/sampling
// #import shared/packed

// `bilinear_level` of a packed map.
// #fetches bilinear_level_packed: 4
fn bilinear_level_packed(map: texture_2d<u32>, uv: vec2<f32>, level: i32) -> vec4<f32> {
    let size = level_size_of(textureDimensions(map), level);
    let f = uv * size - 0.5;
    let i = vec2<i32>(floor(f));
    let a = f - floor(f);
    let smax = vec2<i32>(size) - 1;
    let t00 = unpack_f16x2(textureLoad(map, clamp(i, vec2<i32>(0), smax), level));
    let t10 = unpack_f16x2(textureLoad(map, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), smax), level));
    let t01 = unpack_f16x2(textureLoad(map, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), smax), level));
    let t11 = unpack_f16x2(textureLoad(map, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), smax), level));
    return mix(mix(t00, t10, a.x), mix(t01, t11, a.x), a.y);
}

// `trilinear` of a packed map.
// #fetches trilinear_packed: 8
fn trilinear_packed(map: texture_2d<u32>, l: Light, uv: vec2<f32>, lod_in: f32) -> vec4<f32> {
    let lod = clamp(lod_in, 0.0, f32(l.mip_levels - 1u));
    let l0 = i32(floor(lod));
    let l1 = min(l0 + 1, i32(l.mip_levels) - 1);
    let v0 = bilinear_level_packed(map, uv, l0);
    return mix(v0, bilinear_level_packed(map, uv, l1), lod - floor(lod));
}

// `sample_map` of a packed map: the light's filtered two moments at a receiver (.zw are 0, 1).
// #fetches sample_map_packed: select(4, 8 * max(l.max_anisotropy, 1), l.mip_levels > 1)
fn sample_map_packed(map: texture_2d<u32>, l: Light, s: LightSample) -> vec4<f32> {
    if l.mip_levels <= 1u {
        return bilinear_level_packed(map, s.uv, 0);
    }
    let t = mip_taps(l, s);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < t.count; k++) {
        sum += trilinear_packed(map, l, mip_tap_uv(t, s.uv, k), t.lod);
    }
    return sum / f32(t.count);
}
