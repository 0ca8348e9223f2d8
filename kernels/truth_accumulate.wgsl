// Ground truth of an area light: adds one emitter sample's hard-shadow test to a per-pixel
// count. The sample's raw depth map is linearized at the one texel read (the `linearize`
// kernel's formula, operation for operation) and compared like `vis_hard`, so a sample at the
// light's centre with the light's own map reproduces the renderer's `hard` technique.
// #import shared/light
// #import shared/sampling

// Traffic (the cost model, src/graph/cost): the G-buffer once per pixel and one depth texel per
// pixel (scattered).
// #traffic g_position: all
// #traffic g_normal: all
// #traffic depth: WG_SIZE * WG_SIZE per group
// #traffic sample_light: all
// #traffic lit_count: all
@group(0) @binding(0) var g_position: texture_2d<f32>;
@group(0) @binding(1) var g_normal: texture_2d<f32>;
@group(0) @binding(2) var depth: texture_depth_2d;
@group(0) @binding(3) var<storage, read> sample_light: array<Light>;
@group(0) @binding(4) var<storage, read_write> lit_count: array<u32>;

const WG_SIZE: u32 = 8u;

// WGSL lets implementations assume finite floats, so test the exponent bits instead.
fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// `linearize.wgsl` for one texel: raw depth → linear depth in [0, 1], non-finite → 1.
fn linear_depth(l: Light, raw: f32) -> f32 {
    var z = 1.0;
    if is_finite(raw) {
        let d = clamp(raw, 0.0, 1.0);
        z = d;
        if l.kind != 0u {
            z = l.near * d / (l.far * (1.0 - d) + l.near * d);
        }
        z = clamp(z, 0.0, 1.0);
    }
    return z;
}

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    // Every invocation samples the map before anything branches on its pixel (llvmpipe
    // mis-fetches when part of a SIMD group has left the code path).
    let size = textureDimensions(g_position);
    let inside_image = all(id.xy < size);
    let xy = min(id.xy, size - 1u);
    let gp = textureLoad(g_position, xy, 0);
    let gn = textureLoad(g_normal, xy, 0);
    let n = select(normalize(gn.xyz), vec3<f32>(0.0, 1.0, 0.0), gp.w == 0.0 || dot(gn.xyz, gn.xyz) == 0.0);
    let l = sample_light[0];
    let s = light_sample(l, gp.xyz, n);
    let t = texel_of(s.uv, l.map_size);
    let raw = textureLoad(depth, t, 0);
    let z = linear_depth(l, raw);
    // The scene's bias, the receiver-plane bias included (0 when off).
    let d = s.depth + light_receiver_offset(l, s, light_tap_offset(l, s, t));
    let lit = select(1u, select(0u, 1u, d <= z + l.bias), s.inside);
    if inside_image {
        let i = xy.y * size.x + xy.x;
        lit_count[i] = lit_count[i] + lit;
    }
}
