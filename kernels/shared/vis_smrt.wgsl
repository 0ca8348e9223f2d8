// Shadow-map ray tracing (SMRT), after Unreal Engine 5's virtual shadow maps and Blender
// EEVEE-Next (descended from Xie, Tabellion & Pearce, EGSR 2007): from the receiver, one ray
// toward each of `smrt_rays` fixed points on the emitter, each marched through the one linear
// depth map with `smrt_steps` samples; visibility is the share of rays no sample occludes.
//
// The emitter is the truth's (src/truth/emitter.rs): a square of side `size` in the light's
// plane. A spot's rays converge on the emitter point (the map UV moves with 1/Z); a
// directional light's rays are parallel, from the emitter point to the target `target_distance`
// away (the UV moves with Z). A ray runs from the receiver (t = 0) to the near plane (t = 1),
// where the map's depths end. Steps are spaced in the light's depth, quadratically from the
// light end, t_i = ((S − i − ½) / S)², i = 0 … S − 1: dense near the receiver, where contact
// shadows are decided within a few texels, sparse near the light, where the ray is in front of
// everything; the last is ¼ S⁻² of the ray away from the receiver, not on its own surface.
//
// The map is a height field with no thickness. A sample behind the stored surface (by more
// than the bias) is a hit only if the last surface seen in front of the ray, continued at its
// slope along the ray (its receding rate capped at `smrt_max_slope` times the ray's own depth
// rate), still covers it: a ray passing behind an occluder's silhouette, seen last as the floor
// far behind it, goes on (UE's and EEVEE's extrapolation behind occluders). The first sample
// has no history: behind is a hit. Samples off the map are skipped.
// #import shared/light
// #import shared/sampling

// Emitter point k of n in units of the light's size, in [−½, ½]²: the centre of stratum k on the
// truth's grid (`stratified_offsets`): ⌊√n⌋ rows, the first (n mod rows) holding one point more,
// each row's height in proportion to its count.
fn smrt_emitter_point(k: u32, n: u32) -> vec2<f32> {
    var rows = 1u;
    while (rows + 1u) * (rows + 1u) <= n {
        rows++;
    }
    var before = 0u;
    var r = 0u;
    var cols = n / rows + select(0u, 1u, 0u < n % rows);
    while k >= before + cols {
        before += cols;
        r++;
        cols = n / rows + select(0u, 1u, r < n % rows);
    }
    let x = (f32(k - before) + 0.5) / f32(cols);
    let y = (f32(before) + 0.5 * f32(cols)) / f32(n);
    return vec2<f32>(x - 0.5, y - 0.5);
}

// Whether the ray toward emitter point `o` is occluded.
// #fetches smrt_ray: l.smrt_steps
fn smrt_ray(map: texture_2d<f32>, l: Light, s: LightSample, o: vec2<f32>) -> bool {
    let n = l.smrt_steps;
    let span = s.view_z - l.near;
    // The emitter point's view-space offset as a UV direction (UV y runs down).
    let e = l.size * vec2<f32>(o.x, -o.y) / l.width_at_unit;
    let cap = l.smrt_max_slope * s.depth;
    var seen = false;
    var t_seen = 0.0;
    var z_seen = 0.0;
    var slope = 0.0;
    for (var i = 0u; i < n; i++) {
        let f = (f32(n - i) - 0.5) / f32(n);
        let t = f * f;
        let z_view = s.view_z - t * span;
        let k = select(l.target_distance, z_view * s.view_z, l.kind == 1u);
        let uv = s.uv + e * (t * span / k);
        if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
            continue;
        }
        let z = load_depth(map, texel_of(uv, l.map_size));
        let ray = s.depth * (1.0 - t);
        if ray > z + l.bias {
            if !seen {
                return true;
            }
            let z_ext = z_seen + min(slope, cap) * (t_seen - t);
            if ray > z_ext + l.bias {
                return true;
            }
        } else {
            if seen {
                slope = (z - z_seen) / (t_seen - t);
            }
            seen = true;
            t_seen = t;
            z_seen = z;
        }
    }
    return false;
}

// #fetches vis_smrt: l.smrt_rays * smrt_ray
fn vis_smrt(map: texture_2d<f32>, l: Light, s: LightSample) -> f32 {
    if s.view_z <= l.near {
        return 1.0;
    }
    var lit = 0u;
    for (var k = 0u; k < l.smrt_rays; k++) {
        lit += select(1u, 0u, smrt_ray(map, l, s, smrt_emitter_point(k, l.smrt_rays)));
    }
    return f32(lit) / f32(l.smrt_rays);
}
