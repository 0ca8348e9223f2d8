//! Helpers of the evaluation tests: images compared with the GPU's, regions recomputed.

/// `rgb` (RGB8) equals `rgba` (RGBA8) within one step per channel; prints how many differ.
pub fn assert_same_image(what: &str, rgb: &[u8], rgba: &[u8]) {
    assert_eq!(rgb.len() / 3, rgba.len() / 4, "{what}: size");
    let mut off = 0;
    for (i, (a, b)) in rgb.chunks(3).zip(rgba.chunks(4)).enumerate() {
        for k in 0..3 {
            let d = (i32::from(a[k]) - i32::from(b[k])).abs();
            assert!(
                d <= 1,
                "{what}: pixel {i} channel {k}: {} vs GPU {}",
                a[k],
                b[k]
            );
            off += usize::from(d == 1);
        }
    }
    eprintln!("{what}: {off} of {} channels one step off", rgb.len());
}

/// The region of each pixel by the definition, written out plainly (0 outside, 1 penumbra,
/// 2 umbra, 3 lit): a relevant pixel is penumbra when its truth is strictly inside
/// (0.02, 0.98) or when some pixel within 2 in x and y is an edge pixel (relevant, with a
/// relevant 4-neighbour on the other side of 0.5).
pub fn regions_direct(t: &[f32], m: &[bool], w: i64, h: i64) -> Vec<u8> {
    let at = |x: i64, y: i64| (y * w + x) as usize;
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h;
    let edge = |x: i64, y: i64| {
        let i = at(x, y);
        m[i] && [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|(dx, dy)| {
            let (u, v) = (x + dx, y + dy);
            inside(u, v) && m[at(u, v)] && ((t[i] >= 0.5) != (t[at(u, v)] >= 0.5))
        })
    };
    let mut out = vec![0u8; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = at(x, y);
            if !m[i] {
                continue;
            }
            let band = (-2..=2)
                .any(|dy| (-2..=2).any(|dx| inside(x + dx, y + dy) && edge(x + dx, y + dy)));
            let v = f64::from(t[i]);
            out[i] = if band || (v > 0.02 && v < 0.98) {
                1
            } else if v <= 0.02 {
                2
            } else {
                3
            };
        }
    }
    out
}
