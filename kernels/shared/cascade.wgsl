// Cascaded shadow maps of a directional light (import-only module): which cascade a receiver
// reads, by its view distance from the camera, and how far into the blend band toward the
// next cascade it is. `src/cpu/cascade.rs` is its f64 reference.
// #import shared/light

struct CascadePick {
    index: u32,  // the cascade whose range holds the receiver (the last beyond it)
    blend: f32,  // 0 outside the band; rises to 1 at the cascade's far end
}

// Cascade c's far view distance (not `cascade_far`: a member of `Light` by that name).
fn cascade_far_of(l: Light, c: u32) -> f32 {
    var far = l.cascade_far;
    return far[c / 4u][c % 4u];
}

// The cascade of receiver p: the first whose far distance is at least p's view distance d
// (the last when d is beyond them all); within the last `cascade_blend` of its range, before
// the last cascade, the fraction of the band d has crossed.
fn cascade_pick(l: Light, p: vec3<f32>) -> CascadePick {
    let d = dot(p - l.cascade_eye, l.cascade_forward);
    var pick: CascadePick;
    pick.index = l.cascade_count - 1u;
    pick.blend = 0.0;
    var start = l.cascade_near;
    for (var c = 0u; c + 1u < l.cascade_count; c++) {
        let far = cascade_far_of(l, c);
        if d <= far {
            pick.index = c;
            let band = l.cascade_blend * (far - start);
            if band > 0.0 {
                pick.blend = clamp((d - (far - band)) / band, 0.0, 1.0);
            }
            return pick;
        }
        start = far;
    }
    return pick;
}
