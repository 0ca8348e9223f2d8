//! IEEE half precision on the CPU: what an f16 map holds (`rgba16float` texels, or two halves
//! packed in an `r32uint` word by `pack2x16float`, `graph::PACKED_F16X2`).

/// IEEE half → single.
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = u32::from(h >> 15) << 31;
    let exp = u32::from((h >> 10) & 0x1f);
    let mant = u32::from(h & 0x3ff);
    let bits = match (exp, mant) {
        (0, 0) => sign,
        (0, m) => {
            // Subnormal m·2⁻²⁴: shift the leading 1 up to bit 10 (the implicit bit).
            let shift = m.leading_zeros() - 21;
            sign | ((113 - shift) << 23) | ((m << shift) & 0x3ff) << 13
        }
        (31, m) => sign | 0x7f80_0000 | (m << 13),
        (e, m) => sign | ((e + 112) << 23) | (m << 13),
    };
    f32::from_bits(bits)
}

/// Single → IEEE half, rounding to nearest even (overflow to ±∞, NaN kept NaN), as
/// `pack2x16float` does where the device rounds to nearest.
pub fn f32_to_f16(v: f32) -> u16 {
    let bits = v.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exp = ((bits >> 23) & 0xff) as i32;
    let mant = bits & 0x7f_ffff;
    if exp == 0xff {
        return sign | 0x7c00 | if mant != 0 { 0x200 } else { 0 };
    }
    // The value as an integer multiple of 2⁻²⁴ (f16's smallest subnormal) below 2⁻¹⁴, else the
    // 11-bit significand at its exponent; either rounded to nearest even.
    let e = exp - 127;
    if e < -25 {
        return sign;
    }
    let full = mant | 0x80_0000; // 24-bit significand (exp > 0 here, or the value flushes)
    let (shift, base) = if e < -14 {
        ((-14 - e) as u32 + 13, 0u32)
    } else {
        (13, ((e + 15) as u32) << 10)
    };
    let kept = full >> shift;
    let rest = full & ((1 << shift) - 1);
    let half = 1 << (shift - 1);
    let rounded = kept + u32::from(rest > half || (rest == half && kept & 1 == 1));
    // Normal: drop the implicit bit and add the exponent (a carry out of the significand
    // bumps the exponent, to ∞ past the largest finite value).
    let h = if base == 0 {
        rounded
    } else {
        base + (rounded - 0x400)
    };
    sign | h.min(0x7c00) as u16
}

/// Two f32 values per texel → `pack2x16float` words (low half first).
pub fn pack_f16x2(values: &[f32]) -> Vec<u32> {
    values
        .chunks(2)
        .map(|p| {
            let lo = u32::from(f32_to_f16(p[0]));
            let hi = u32::from(f32_to_f16(p.get(1).copied().unwrap_or(0.0)));
            lo | (hi << 16)
        })
        .collect()
}

/// `pack2x16float` words → their two halves as f32 (low half first, as `unpack2x16float`).
pub fn unpack_f16x2(words: &[u32]) -> Vec<f32> {
    words
        .iter()
        .flat_map(|w| [f16_to_f32(*w as u16), f16_to_f32((*w >> 16) as u16)])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{f16_to_f32, f32_to_f16};

    /// Every finite half round-trips; a value halfway between two neighbours goes to the even
    /// one, a quarter of the way to the nearer; past the largest half, ∞; below half the
    /// smallest subnormal, 0.
    #[test]
    fn f32_to_f16_rounds_to_nearest_even() {
        for h in 0..=u16::MAX {
            let v = f16_to_f32(h);
            if v.is_nan() {
                assert!(f16_to_f32(f32_to_f16(v)).is_nan(), "{h:#06x}");
                continue;
            }
            assert_eq!(f32_to_f16(v), h, "{h:#06x} ({v})");
            let next = h.wrapping_add(1);
            let w = f16_to_f32(next);
            if h & 0x7fff < 0x7c00 && next & 0x7fff <= 0x7c00 && w.is_finite() {
                let (a, b) = (f64::from(v), f64::from(w));
                let mid = ((a + b) / 2.0) as f32;
                let even = if h & 1 == 0 { h } else { next };
                assert_eq!(f32_to_f16(mid), even, "{h:#06x}: midpoint {mid}");
                assert_eq!(f32_to_f16((a + (b - a) / 4.0) as f32), h, "{h:#06x}");
            }
        }
        assert_eq!(f32_to_f16(65520.0), 0x7c00);
        assert_eq!(f32_to_f16(2f32.powi(-25)), 0);
        assert_eq!(f32_to_f16(2f32.powi(-25) * 1.01), 1);
    }

    /// Every half against its definition: `m·2⁻²⁴` (subnormal), `(1 + m/1024)·2^(e − 15)`,
    /// infinities and NaNs.
    #[test]
    fn f16_to_f32_is_exact_for_every_half() {
        for h in 0..=u16::MAX {
            let (e, m) = (i32::from((h >> 10) & 0x1f), f64::from(h & 0x3ff));
            let sign = if h >> 15 == 1 { -1.0 } else { 1.0 };
            let want = match e {
                0 => sign * m * 2f64.powi(-24),
                31 if m == 0.0 => sign * f64::INFINITY,
                31 => f64::NAN,
                _ => sign * (1.0 + m / 1024.0) * 2f64.powi(e - 15),
            };
            let got = f64::from(f16_to_f32(h));
            assert!(
                got == want || (got.is_nan() && want.is_nan()),
                "{h:#06x}: {got} vs {want}"
            );
        }
    }
}
