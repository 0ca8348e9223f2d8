// The thin shading pass: Lambert + ambient over the G-buffer, one visibility function per
// light's technique. The `// #generated` block binds each light's maps (group 1) and defines
// `light_visibility(i, p, n, dpdx, dpdy)`, calling only the techniques the scene uses.
// #import shared/light

// Keep in sync with `FrameGpu` in src/render.rs.
struct Frame {
    size: vec2<u32>,
    light_count: u32,
    has_camera: u32,         // 1: the ray fields below hold the camera (else footprints are 0)
    ambient: vec3<f32>,
    _pad1: f32,
    background: vec3<f32>,
    _pad2: f32,
    camera: vec3<f32>,       // eye position
    _pad3: f32,
    ray00: vec3<f32>,        // unnormalized view ray through pixel corner (0, 0) ...
    _pad4: f32,
    ray_dx: vec3<f32>,       // ... plus (x + ½)·ray_dx + (y + ½)·ray_dy through pixel (x, y)
    _pad5: f32,
    ray_dy: vec3<f32>,
    _pad6: f32,
}

// Traffic (the cost model, src/graph/cost): the G-buffer and outputs once per pixel; the maps are
// fetched by the visibility functions (`// #fetches`).
// #traffic g_position: all
// #traffic g_normal: all
// #traffic materials: all
// #traffic lights: all
// #traffic out_color: all
// #traffic out_visibility: all
@group(0) @binding(0) var g_position: texture_2d<f32>;
@group(0) @binding(1) var g_normal: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> materials: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
@group(0) @binding(4) var<uniform> frame: Frame;
@group(0) @binding(5) var out_color: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(6) var<storage, read_write> out_visibility: array<f32>;
@group(0) @binding(7) var cmp_sampler: sampler_comparison;
// Linear filtering, clamped to the edge: f32 summed-area tables' corner fetches (`sat_mean_linear`).
@group(0) @binding(8) var sat_sampler: sampler;

// #generated

const WG_SIZE: u32 = 8u;
// Pixels an invocation shades along a row, WG_SIZE apart, so that neighbouring lanes stay on
// neighbouring pixels (`kernels::TEXELS_X_CONSTANT`: the dispatch covers WG_SIZE · TEXELS_X
// columns a workgroup). On an H200 a kernel that only tests its bounds costs 0.040 ms over
// 1080p in 8 × 8 workgroups, most of `hard`'s 0.066 (benches/RESULTS.md,
// 2026-11-27): fewer workgroups are the candidate, to be measured there
// (`benches/gpu_check.sh`'s tx2 and tx4 variants).
const TEXELS_X: u32 = 1u;

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

// How far the receiver p (normal n) seen through pixel xy moves to the next pixel in x and in
// y: ray differentials on the receiver's tangent plane, p(x) = eye + t(x)·d(x) with
// t = (p − eye)·n / (d·n), so dp/dx = t·(d_x − d·(d_x·n)/(d·n)). Grazing views (|d·n| below
// 10⁻³|d|) are held at that slope. Zero without a camera (the probe).
struct Differentials {
    dpdx: vec3<f32>,
    dpdy: vec3<f32>,
}

fn pixel_differentials(xy: vec2<u32>, p: vec3<f32>, n: vec3<f32>) -> Differentials {
    var out: Differentials;
    out.dpdx = vec3<f32>(0.0);
    out.dpdy = vec3<f32>(0.0);
    if frame.has_camera == 0u {
        return out;
    }
    let d = frame.ray00 + (f32(xy.x) + 0.5) * frame.ray_dx + (f32(xy.y) + 0.5) * frame.ray_dy;
    let dn0 = dot(d, n);
    let floor = 1e-3 * length(d);
    let dn = select(min(dn0, -floor), max(dn0, floor), dn0 >= 0.0);
    let t = dot(p - frame.camera, n) / dn;
    out.dpdx = t * (frame.ray_dx - d * (dot(frame.ray_dx, n) / dn));
    out.dpdy = t * (frame.ray_dy - d * (dot(frame.ray_dy, n) / dn));
    return out;
}

// Spot lights light only their cone (soft edge over the outer 10% of the angle); directional
// and point lights light every direction.
fn cone(l: Light, p: vec3<f32>) -> f32 {
    if l.kind != 1u {
        return 1.0;
    }
    let c = dot(normalize(p - l.position), l.direction);
    return smoothstep(l.cos_outer, mix(l.cos_outer, 1.0, 0.1), c);
}

@compute @workgroup_size(WG_SIZE, WG_SIZE)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    for (var k = 0u; k < TEXELS_X; k++) {
        let xy = vec2<u32>((wg.x * TEXELS_X + k) * WG_SIZE + lid.x, wg.y * WG_SIZE + lid.y);
        if all(xy < frame.size) {
            shade_pixel(xy);
        }
    }
}

// Pixel xy's colour and visibilities.
fn shade_pixel(xy: vec2<u32>) {
    let base = (xy.y * frame.size.x + xy.x) * frame.light_count;
    let gp = textureLoad(g_position, xy, 0);
    if gp.w == 0.0 {
        // Background: no receiver, nothing shadowed, no lookup.
        for (var i = 0u; i < frame.light_count; i++) {
            out_visibility[base + i] = 1.0;
        }
        textureStore(out_color, xy, vec4<f32>(linear_to_srgb(frame.background), 1.0));
        return;
    }
    let gn = textureLoad(g_normal, xy, 0);
    let n = select(normalize(gn.xyz), vec3<f32>(0.0, 1.0, 0.0), dot(gn.xyz, gn.xyz) == 0.0);
    let albedo = materials[min(u32(gn.w), arrayLength(&materials) - 1u)].rgb;
    var radiance = frame.ambient * albedo;
    let dp = pixel_differentials(xy, gp.xyz, n);
    for (var i = 0u; i < frame.light_count; i++) {
        let l = lights[i];
        let v = light_visibility(i, gp.xyz, n, dp.dpdx, dp.dpdy);
        out_visibility[base + i] = v;
        let ndl = max(dot(n, light_to_light(l, gp.xyz)), 0.0);
        radiance += albedo * l.radiance * (ndl * v * cone(l, gp.xyz));
    }
    textureStore(out_color, xy, vec4<f32>(linear_to_srgb(radiance), 1.0));
}
