"""High-precision values for the MSM reference's unit tests (src/cpu/vis_msm.rs, `tests`).

Run: python3 tests/data/msm_reference.py  (needs mpmath: pip install mpmath). Not part of CI:
the printed constants are pasted into the tests.

Every input is an exact binary floating-point number (f64, or f32 where the GPU stores
moments), and everything after that is evaluated with 60 significant digits: the moments are
projected onto valid ones (variances clamped at 0, the covariance to Cauchy-Schwarz; a no-op
for the moments of a distribution), biased toward b0 = moments of {0, 1/2, 1} with weights
(3/16, 10/16, 3/16), the 3x3 Hankel system B c = (1, d, d^2) is solved by LU, and the
Hamburger (or Hausdorff) intensity of Peters & Klein (2015) follows; visibility is
linstep(bleed, 1, 1 - intensity). The solve here is independent of the Rust code's Cholesky.
"""
import struct
import mpmath as mp

mp.mp.dps = 60
B0 = [mp.mpf(x) for x in ("0.5", "0.34375", "0.265625", "0.2265625")]


def f32(x):
    """The f32 nearest to x, as an exact mpf."""
    return mp.mpf(struct.unpack("f", struct.pack("f", float(x)))[0])


def f64(x):
    return mp.mpf(float(x))


def fl(x):
    """x rounded to f64 (the result of one f64 operation)."""
    return mp.mpf(float(x))


def project(b):
    var1 = max(b[1] - b[0] ** 2, 0)
    var2 = max(b[3] - b[1] ** 2, 0)
    lim = mp.sqrt(var1 * var2)
    cov = min(max(b[2] - b[0] * b[1], -lim), lim)
    second = b[0] ** 2 + var1
    return [b[0], second, b[0] * second + cov, second**2 + var2]


def biased(data, alpha):
    p = project(data)
    return [(1 - alpha) * x + alpha * y for x, y in zip(p, B0)]


def roots(b, d):
    h = mp.matrix([[1, b[0], b[1]], [b[0], b[1], b[2]], [b[1], b[2], b[3]]])
    c = mp.lu_solve(h, mp.matrix([1, d, d * d]))
    disc = mp.sqrt(c[1] ** 2 - 4 * c[2] * c[0])
    r = sorted([(-c[1] - disc) / (2 * c[2]), (-c[1] + disc) / (2 * c[2])])
    return r[0], r[1]


def intensity(b, d, hausdorff=False):
    z2, z3 = roots(b, d)
    if hausdorff and (z2 < 0 or z3 > 1):
        free = ((b[2] - b[1]) * d + b[2] - b[3]) / ((b[1] - b[0]) * d + b[1] - b[2])
        w1 = 1 if d > free else 0
        return (b[1] - b[0] + (b[2] - b[0] - (free + 1) * (b[1] - b[0])) * (free - w1 - d)
                / (d * (d - free))) / (free - w1) + 1 - b[0]
    if d <= z2:
        return mp.mpf(0)
    if d <= z3:
        return (d * z3 - b[0] * (d + z3) + b[1]) / ((z3 - z2) * (d - z2))
    return 1 - (z2 * z3 - b[0] * (z2 + z3) + b[1]) / ((d - z2) * (d - z3))


def visibility(data, d, alpha, bleed=0, hausdorff=False):
    i = intensity(biased(data, alpha), d, hausdorff)
    v = 1 - min(max(i, 0), 1)
    return min(max((v - bleed) / (1 - bleed), 0), 1)


def flat(z):
    """The f64 moments the Rust test forms of a flat map at z: z, z*z, z*(z*z), (z*z)*(z*z)."""
    z = f64(z)
    z2 = fl(z * z)
    return [z, z2, fl(z * z2), fl(z2 * z2)]


def mixture(points):
    """Exact moments of a discrete distribution [(z, weight)], rounded to f64 once each."""
    return [fl(sum(w * z**k for z, w in points)) for k in range(1, 5)]


ALPHA_F32 = f32("1e-5")  # the moment_bias a light carried when the issue was filed
CASES = [
    # name, data moments, receiver depth d, alpha, bleed, hausdorff
    ("flat_behind_bleed", flat("0.9504754699392566"), f64("0.9506347094697088"),
     ALPHA_F32, f32("0.2"), False),
    ("stored_f32_behind_flat", [f32(x) for x in
                                ("0.90475309", "0.81857812", "0.74061108", "0.67007017")],
     f32("0.9051267"), ALPHA_F32, 0, False),
    ("flat_peters_bias", flat("0.25"), f64("0.2501"), f64("3e-7"), 0, False),
    ("two_points", mixture([(mp.mpf("0.3"), mp.mpf("0.5")), (mp.mpf("0.7"), mp.mpf("0.5"))]),
     f64("0.70001"), f32("6e-5"), 0, False),
    ("close_triple", mixture([(mp.mpf("0.6"), mp.mpf("0.25")), (mp.mpf("0.6001"), mp.mpf("0.5")),
                              (mp.mpf("0.6002"), mp.mpf("0.25"))]),
     f64("0.60025"), f64("1e-6"), 0, False),
    ("flat_near_zero", flat("0.02"), f64("0.03"), f32("5e-4"), 0, False),
    ("two_points_hausdorff", mixture([(mp.mpf("0.3"), mp.mpf("0.5")),
                                      (mp.mpf("0.7"), mp.mpf("0.5"))]),
     f64("0.70001"), f32("6e-5"), 0, True),
]

if __name__ == "__main__":
    for name, data, d, alpha, bleed, hausdorff in CASES:
        b = biased(data, alpha)
        z2, z3 = roots(b, d)
        v = visibility(data, d, alpha, bleed, hausdorff)
        moments = ", ".join(repr(float(x)) for x in data)
        print(f"    // {name}: z2, z3 = {mp.nstr(z2, 12)}, {mp.nstr(z3, 12)}; "
              f"visibility {mp.nstr(v, 20)}")
        print(f"    Case {{ moments: [{moments}], d: {float(d)!r}, alpha: {float(alpha)!r}, "
              f"bleed: {float(bleed)!r}, hausdorff: {str(hausdorff).lower()}, "
              f"visibility: {float(v)!r} }},")
