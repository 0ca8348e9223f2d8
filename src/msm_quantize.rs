//! MSM's optimized 16-bit quantization of moments (Peters & Klein 2015, §4.3), in f64: the
//! matrices of `kernels/shared/msm_quantize.wgsl`, used by the technique code (the range of
//! quantized moments a table codes) and by the CPU reference (`cpu::msm`).

/// Columns of the optimized quantization: `q_j = b · Q_j`.
const QUANTIZE: [[f64; 4]; 4] = [
    [-2.07224649, 32.23703778, -68.571074599, 39.3703274134],
    [13.7948857237, -59.4683975703, 82.0359750338, -35.364903257],
    [0.105877704, -1.9077466311, 9.3496555107, -6.6543490743],
    [9.7924062118, -33.7652110555, 47.9456096605, -23.9728048165],
];
/// Its inverse, by columns likewise.
#[cfg(feature = "cli")]
const DEQUANTIZE: [[f64; 4]; 4] = [
    [0.2227744146, 0.0771972861, 0.7926986636, 0.0319417555],
    [0.1549679261, 0.1394629426, 0.7963415838, -0.1722823173],
    [0.1451988946, 0.2120202157, 0.7258694464, -0.2758014811],
    [0.163127443, 0.2591432266, 0.6539092497, -0.3376131734],
];
const QUANTIZE_OFFSET: f64 = 0.035955884801;

fn row_times(b: [f64; 4], cols: &[[f64; 4]; 4]) -> [f64; 4] {
    cols.map(|c| (0..4).map(|i| b[i] * c[i]).sum())
}

/// The optimized 16-bit quantization of moments `b`.
pub fn quantize(b: [f64; 4]) -> [f64; 4] {
    let mut q = row_times(b, &QUANTIZE);
    q[0] += QUANTIZE_OFFSET;
    q
}

/// The moments of quantized `q` (the CPU reference's).
#[cfg(feature = "cli")]
pub fn dequantize(mut q: [f64; 4]) -> [f64; 4] {
    q[0] -= QUANTIZE_OFFSET;
    row_times(q, &DEQUANTIZE)
}
