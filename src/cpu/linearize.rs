//! Reference of `kernels/linearize.wgsl`.

/// Linear depth of one depth-buffer value; `None` where the input is non-finite (the kernel
/// writes 1.0 and counts it).
pub fn linearize_texel(raw: f32, perspective: bool, near: f64, far: f64) -> Option<f64> {
    if !raw.is_finite() {
        return None;
    }
    let d = f64::from(raw).clamp(0.0, 1.0);
    let z = if perspective {
        // Z = near·far / (far − d (far − near)); linear = (Z − near) / (far − near).
        let view_z = near * far / (far - d * (far - near));
        (view_z - near) / (far - near)
    } else {
        d
    };
    Some(z.clamp(0.0, 1.0))
}

/// The whole map, with the count of replaced texels.
pub fn linearize(raw: &[f32], perspective: bool, near: f64, far: f64) -> (Vec<f64>, u32) {
    let mut replaced = 0;
    let out = raw
        .iter()
        .map(|&r| {
            linearize_texel(r, perspective, near, far).unwrap_or_else(|| {
                replaced += 1;
                1.0
            })
        })
        .collect();
    (out, replaced)
}
