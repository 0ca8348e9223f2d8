// Shared light description and light-space helpers (import-only module).
//
// Linear light-space depth, the quantity every technique compares, is
//   d = (Z − near) / (far − near),  Z = distance along the light's view axis,
// for both the orthographic (directional) and the perspective (spot) light.

// Keep in sync with `LightGpu` in src/wgsl_mirrors.rs.
struct Light {
    view_proj: mat4x4<f32>,  // world → light clip
    view: mat4x4<f32>,       // world → light view
    radiance: vec3<f32>,     // colour × intensity
    kind: u32,               // 0 directional (orthographic), 1 spot (perspective), 2 point (six faces)
    position: vec3<f32>,
    near: f32,
    direction: vec3<f32>,    // unit, light → target
    far: f32,
    map_size: vec2<f32>,     // shadow-map texels
    width_at_unit: f32,      // map (a point light's face) width in world units: directional 2·extent; spot, point 2·tan(fov/2) per unit distance
    size: f32,               // area-light width, world units
    bias: f32,               // constant bias, linear depth units
    normal_bias: f32,        // normal offset, texels, scaled by (1 − N·L)
    cos_outer: f32,          // spot cone: cos(fov/2); directional: −1
    technique: u32,          // TECHNIQUE_* below
    radius: u32,             // pcf: window radius in texels
    kernel: u32,             // pcf: 0 box, 1 tent, 2 hardware 2×2
    blocker_samples: u32,    // pcss
    filter_samples: u32,     // pcss
    max_search: f32,         // pcss, soft techniques: cap on the blocker-search radius, UV
    bleed: f32,              // vsm, evsm: light-bleeding reduction amount
    min_variance: f32,       // vsm, evsm: variance floor (depth units²)
    exp_pos: f32,            // evsm: positive exponent c⁺; esm: exponent c
    exp_neg: f32,            // evsm: negative exponent c⁻
    moments: u32,            // evsm: 2 or 4 stored moments
    moment_bias: f32,        // msm: bias α toward the three-point moments
    msm_flags: u32,          // msm: bit 0 Hausdorff (else Hamburger), bit 1 quantized storage
    csm_terms: u32,          // csm: Fourier terms M
    csm_attenuation: f32,    // csm: ringing attenuation α
    csm_offset: f32,         // csm: receiver-depth offset
    csm_scale: f32,          // csm: response scale about ½
    mip_levels: u32,         // mips filter: levels in the map's chain (0: no mips)
    filter_lod: f32,         // mips filter: log2 of the filter width in texels
    filter_width: f32,       // sat filter: box width in texels (0: no sat)
    max_anisotropy: u32,     // mips filter: 0 fixed width; ≥ 1 per-pixel footprint, up to this many taps
    sat_offset: vec4<f32>,   // sat filter, soft techniques: the table's coding (SatCoding in src/sat.rs)
    sat_scale: vec4<f32>,
    sharpen: f32,            // cssm: sharpening strength A of v^p, p = 1 + A·exp(−B (d − z_avg))
    sharpen_falloff: f32,    // cssm: sharpening falloff B, per linear depth unit
    max_width: f32,          // soft techniques: cap on the search and filter widths, texels
    receiver_plane: f32,     // receiver-plane bias: cap on a tap's depth correction (0: off)
    smrt_rays: u32,          // smrt: rays per receiver
    smrt_steps: u32,         // smrt: depth-map samples per ray
    smrt_max_slope: f32,     // smrt: cap on the receding slope extrapolated behind an occluder
    target_distance: f32,    // position–target distance (directional emitter rays, smrt)
    cascade_eye: vec3<f32>,  // cascades (directional): the camera's eye
    cascade_count: u32,      // cascades: 0 or 1 one map; N: this entry is cascade 0 of N
    cascade_forward: vec3<f32>, // cascades: the camera's unit forward direction
    cascade_first: u32,      // cascades: index in `lights` of cascade 1 (the rest follow)
    cascade_near: f32,       // cascades: view distance the first cascade starts at
    cascade_blend: f32,      // cascades: blend band, fraction of each cascade's range
    face_uv: vec2<f32>,      // map UV per unit of a face's UV: (1, 1); a point light's atlas (1/3, 1/2)
    cascade_far: array<vec4<f32>, 2>, // cascades: far view distance of cascade c at [c / 4][c % 4]
    sat_filtered: u32,       // tables: 1 where f32 and read with filtered fetches (the CPU references read it)
    sat_amplitude: f32,      // tables: the largest |v − sat_offset| over the value range (the CPU references read it)
    cssm_two_depth: u32,     // cssm: 0 sharpening alone; two-depth resolve (needs the receiver plane's slope) with the search's z_avg 1, the filter square's 2
    capped_filter: u32,      // pcss: 1 where the filter radius is capped at max_search (a point light's faces, a cascade's guard band)
}

// `Light::technique` (keep in sync with the `TECHNIQUE_*` constants of src/wgsl_mirrors.rs; a test
// compares them).
const TECHNIQUE_HARD: u32 = 0u;
const TECHNIQUE_PCF: u32 = 1u;
const TECHNIQUE_PCSS: u32 = 2u;
const TECHNIQUE_VSM: u32 = 3u;
const TECHNIQUE_EVSM: u32 = 4u;
const TECHNIQUE_ESM: u32 = 5u;
const TECHNIQUE_MSM: u32 = 6u;
const TECHNIQUE_CSM: u32 = 7u;
const TECHNIQUE_CSSM: u32 = 8u;
const TECHNIQUE_VSSM: u32 = 9u;
const TECHNIQUE_MSM_SOFT: u32 = 10u;
const TECHNIQUE_SMRT: u32 = 20u;
const TECHNIQUE_MIDPOINT: u32 = 30u;
const TECHNIQUE_SECOND_DEPTH: u32 = 31u;

// Where a receiver lands in a light's shadow map.
struct LightSample {
    uv: vec2<f32>,   // shadow-map UV, y down
    depth: f32,      // receiver's linear depth d
    view_z: f32,     // receiver's distance Z along the light axis
    inside: bool,    // inside the map and the depth range
    footprint: vec4<f32>, // the pixel's footprint in the map, texels: axes (x, y) and (z, w); 0 unknown
    depth_slope: vec2<f32>, // receiver plane: d(depth)/d(texel) along u and v (0 unless light_plane_slope)
}

// World width of the whole map at view distance z.
fn light_map_width(l: Light, z: f32) -> f32 {
    if l.kind == 0u {
        return l.width_at_unit;
    }
    return l.width_at_unit * z;
}

// Unit vector from p toward the light.
fn light_to_light(l: Light, p: vec3<f32>) -> vec3<f32> {
    if l.kind == 0u {
        return -l.direction;
    }
    return normalize(l.position - p);
}

// Whether a receiver p with unit normal n faces light l (N·L > 0). One that faces away is in
// its own shadow: its visibility is 0, known without reading a map (and its N·L, hence its
// light, is 0 whatever a map says), so the shading skips its lookups.
fn light_faces(l: Light, p: vec3<f32>, n: vec3<f32>) -> bool {
    return dot(n, light_to_light(l, p)) > 0.0;
}

// World size of one texel at view distance z.
fn light_texel(l: Light, z: f32) -> f32 {
    return light_map_width(l, z) / (l.map_size.x * l.face_uv.x);
}

// Projects p, first moved along n by normal_bias texels scaled by (1 − N·L), into the map of
// a light of any kind. The renderer's shading calls `map_sample` or `point_sample` as the
// light's kind says (its block is generated per scene): llvmpipe runs a point light's
// projection for every pixel of a one-map light even behind a uniform branch or a loop of no
// trips (8% of `hard`'s shading pass), which a GPU would not.
fn light_sample(l: Light, p: vec3<f32>, n: vec3<f32>) -> LightSample {
    if l.kind == 2u {
        return point_sample(l, p, n);
    }
    return map_sample(l, p, n);
}

// light_sample for a one-map light (directional or spot).
fn map_sample(l: Light, p: vec3<f32>, n: vec3<f32>) -> LightSample {
    let z0 = -(l.view * vec4<f32>(p, 1.0)).z;
    let texel = light_texel(l, max(z0, l.near));
    let ndl = clamp(dot(n, light_to_light(l, p)), 0.0, 1.0);
    let q = p + n * (l.normal_bias * texel * (1.0 - ndl));
    let clip = l.view_proj * vec4<f32>(q, 1.0);
    let ndc = clip.xy / clip.w;
    var s: LightSample;
    s.uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
    s.view_z = -(l.view * vec4<f32>(q, 1.0)).z;
    s.depth = (s.view_z - l.near) / (l.far - l.near);
    s.inside = clip.w > 0.0 && all(s.uv >= vec2<f32>(0.0)) && all(s.uv <= vec2<f32>(1.0))
        && s.depth >= 0.0 && s.depth <= 1.0;
    s.footprint = vec4<f32>(0.0);
    s.depth_slope = vec2<f32>(0.0);
    if light_plane_slope(l) {
        s.depth_slope = light_depth_slope(l, q, n, s.view_z);
    }
    return s;
}

// A point light's face for direction d from the light: its major axis and sign, ties to x then
// y (src/model/point.rs, face_of).
fn point_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(0u, 1u, d.x < 0.0);
    }
    if a.y >= a.z {
        return select(2u, 3u, d.y < 0.0);
    }
    return select(4u, 5u, d.z < 0.0);
}

// Direction d in face f's view: (right, up, distance along the face's axis), the view that
// Mat4::look_at_rh(position, position + forward, up) builds for the faces +X, −X, +Y, −Y, +Z, −Z
// with up +Y, +Y, +Z, +Z, +Y, +Y (point::face_axes).
fn point_coords(d: vec3<f32>, f: u32) -> vec3<f32> {
    switch f {
        case 0u: { return vec3<f32>(d.z, d.y, d.x); }
        case 1u: { return vec3<f32>(-d.z, d.y, -d.x); }
        case 2u: { return vec3<f32>(d.x, d.z, d.y); }
        case 3u: { return vec3<f32>(-d.x, d.z, -d.y); }
        case 4u: { return vec3<f32>(-d.x, d.y, d.z); }
        default: { return vec3<f32>(d.x, d.y, -d.z); }
    }
}

// light_sample for a point light: the receiver, moved by the normal offset at the texel size of
// the face that sees it, is projected into the face that sees the moved point, whose 90° core
// holds it; the face's tile sits at column f % 3, row f / 3 of the atlas. Its depth is the
// distance along that face's axis, so every texel a lookup reads around it (within the guard
// band) was rasterized from the same view.
fn point_sample(l: Light, p: vec3<f32>, n: vec3<f32>) -> LightSample {
    let a = abs(p - l.position);
    let texel = light_texel(l, max(max(a.x, max(a.y, a.z)), l.near));
    let ndl = clamp(dot(n, light_to_light(l, p)), 0.0, 1.0);
    let q = p + n * (l.normal_bias * texel * (1.0 - ndl));
    let d = q - l.position;
    let f = point_face(d);
    let c = point_coords(d, f);
    let t = 0.5 * l.width_at_unit * c.z;
    let tile = vec2<f32>(0.5 + 0.5 * c.x / t, 0.5 - 0.5 * c.y / t);
    var s: LightSample;
    s.uv = (vec2<f32>(f32(f % 3u), f32(f / 3u)) + tile) * l.face_uv;
    s.view_z = c.z;
    s.depth = (c.z - l.near) / (l.far - l.near);
    s.inside = c.z > 0.0 && s.depth >= 0.0 && s.depth <= 1.0;
    s.footprint = vec4<f32>(0.0);
    s.depth_slope = vec2<f32>(0.0);
    if light_plane_slope(l) {
        // The face's view space: point_coords gives (x, y, distance) and looks down −z.
        let nf = point_coords(n, f);
        let v = vec3<f32>(c.x, c.y, -c.z);
        s.depth_slope = light_depth_slope_view(l, v, vec3<f32>(nf.x, nf.y, -nf.z), c.z, true);
    }
    return s;
}

// Whether a sample carries its receiver plane's slope: for the receiver-plane bias, and for
// CSSM's two-depth resolve (the receivers' mean series over its filter square).
fn light_plane_slope(l: Light) -> bool {
    return l.receiver_plane > 0.0 || l.cssm_two_depth != 0u;
}

// Receiver-plane depth bias (Isidoro, GDC 2006): the depth of the plane through the receiver q
// with normal n, per texel of offset in the map. A compute shading pass has no dpdx, so the
// plane comes from the G-buffer normal: exact for planar receivers. View space v = V q; a point
// of the plane seen through map coordinates (a, b) at distance Z is Z·(a, b, −1) (spot) or
// (x, y, −Z) (directional), so Z = n·v / (n_x a + n_y b − n_z) and dZ/da = −Z² n_x / n·v
// (directional: dZ/dx = n_x / n_z); a and x grow with u, b and y with −v.
fn light_depth_slope(l: Light, q: vec3<f32>, n: vec3<f32>, z: f32) -> vec2<f32> {
    let v = (l.view * vec4<f32>(q, 1.0)).xyz;
    let nv = (l.view * vec4<f32>(n, 0.0)).xyz;
    return light_depth_slope_view(l, v, nv, z, l.kind != 0u);
}

// light_depth_slope of the receiver at v with normal nv, both in the view the map was drawn
// from (a point light's: its face's), perspective or orthographic.
fn light_depth_slope_view(l: Light, v: vec3<f32>, nv: vec3<f32>, z: f32, perspective: bool) -> vec2<f32> {
    var per_world: vec2<f32>;
    if !perspective {
        per_world = vec2<f32>(nv.x, -nv.y) / nv.z;
    } else {
        per_world = vec2<f32>(-nv.x, nv.y) * (z * z / dot(nv, v));
    }
    let texel = l.width_at_unit / (l.map_size.x * l.face_uv.x);
    let slope = per_world * texel / (l.far - l.near);
    // Edge-on (n·v or n_z → 0) the slope is unbounded or NaN: the cap bounds each tap instead.
    return select(vec2<f32>(0.0), slope, all(abs(slope) < vec2<f32>(1e30)));
}

// The receiver plane's depth change to a tap `offset` texels from the receiver, capped at
// ±receiver_plane (0 when the bias is off).
fn light_receiver_offset(l: Light, s: LightSample, offset: vec2<f32>) -> f32 {
    return clamp(dot(s.depth_slope, offset), -l.receiver_plane, l.receiver_plane);
}

// The offset in texels from the receiver to texel t's centre.
fn light_tap_offset(l: Light, s: LightSample, t: vec2<i32>) -> vec2<f32> {
    return vec2<f32>(t) + 0.5 - s.uv * l.map_size;
}

// The footprint in light l's map, in texels, of the pixel whose receiver p (normal n) moves by
// dpdx and dpdy from one pixel to the next: the differences of the projected points.
fn light_footprint(l: Light, s: LightSample, p: vec3<f32>, n: vec3<f32>, dpdx: vec3<f32>, dpdy: vec3<f32>) -> vec4<f32> {
    let a = (light_sample(l, p + dpdx, n).uv - s.uv) * l.map_size;
    let b = (light_sample(l, p + dpdy, n).uv - s.uv) * l.map_size;
    return vec4<f32>(a, b);
}

// Linear depth → the depth buffer's value (for the hardware comparison sampler).
fn light_linear_to_ndc(l: Light, d: f32) -> f32 {
    if l.kind == 0u {
        return d;
    }
    let z = l.near + d * (l.far - l.near);
    return l.far * (z - l.near) / ((l.far - l.near) * z);
}

// Linear depth → view distance.
fn light_linear_to_z(l: Light, d: f32) -> f32 {
    return l.near + d * (l.far - l.near);
}
