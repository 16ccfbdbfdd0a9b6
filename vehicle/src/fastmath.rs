//! `atan2` and `sin_cos` for the right-hand side: branch-free, division-light, written with
//! plain IEEE-754 `f64` operations only (no fused multiply-add, no runtime CPU dispatch), so
//! the results are the same bit for bit on every x86-64 CPU and whether or not the compiler
//! vectorizes the four wheels. Accuracy (tests below, against glibc over random arguments of
//! every magnitude and quadrant and the special values): `atan2` within 2 ulp, `sin_cos`
//! within 2 ulp for `|x| <= SIN_COS_FAST_MAX` (beyond it, and for NaN/Inf, the standard
//! library's `sin` and `cos`).
//!
//! The polynomial coefficients are Chebyshev interpolants of the functions named at each
//! table, computed in 60-digit arithmetic (mpmath) and rounded to `f64`; their error before
//! rounding of the evaluation is below 1e-17 relative, a tenth of an ulp.

use core::f64::consts::FRAC_2_PI;

/// `h(z) = (atan(sqrt z) / sqrt z - 1) / z` on `0 <= z <= tan(pi/8)^2`, powers `z^0 .. z^10`:
/// `atan(t) = t + t z h(t^2)` for `|t| <= tan(pi/8)`.
const ATAN: [f64; 11] = [
    -0.3333333333333333,
    0.1999999999999552,
    -0.14285714284666542,
    0.11111111015256361,
    -0.09090904578123903,
    0.07692183190826087,
    -0.06664511447381948,
    0.0585814891280221,
    -0.0508544973794026,
    0.03923165829558719,
    -0.01917688711906226,
];

/// `tan(pi/8) = sqrt(2) - 1`: above it the argument is reduced around `pi/4`.
const TAN_PI_8: f64 = 0.41421356237309503;
/// `pi/4` in two parts: the nearest double (its three lowest significand bits are zero, so
/// `k * PI_4_HI` is exact for `k = 0 ..= 4`) and the rest.
const PI_4_HI: f64 = core::f64::consts::FRAC_PI_4;
const PI_4_LO: f64 = 3.061616997868383e-17;

#[inline(always)]
fn select(c: bool, a: f64, b: f64) -> f64 {
    if c {
        a
    } else {
        b
    }
}

/// `atan2(y, x)` \[rad\] in `[-pi, pi]`, with the IEEE-754 special values of C's `atan2`
/// (signed zeros, infinities, NaN). Within 2 ulp of glibc's (tested).
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    if is_plain(y, x) {
        atan2_plain(y, x)
    } else {
        atan2_special(y, x)
    }
}

/// At or above this `|y| + |x|` (and at 0, infinity, NaN) [`atan2_special`] takes over.
const ATAN2_PLAIN_MAX: f64 = 1e300;

/// `0 < |y| + |x| < ATAN2_PLAIN_MAX`: neither is NaN or infinite, not both are zero, and
/// `a + b` in [`atan2_octant`] cannot overflow.
#[inline(always)]
fn is_plain(y: f64, x: f64) -> bool {
    let sum = y.abs() + x.abs();
    (sum > 0.0) & (sum < ATAN2_PLAIN_MAX)
}

/// [`atan2`] where [`is_plain`] (no zero division, no overflow of `a + b`, no infinity, no
/// NaN): the common case, without a branch.
#[inline(always)]
fn atan2_plain(y: f64, x: f64) -> f64 {
    let (ay, ax) = (y.abs(), x.abs());
    let swap = ay > ax;
    let (a, b) = (select(swap, ax, ay), select(swap, ay, ax));
    atan2_octant(y, x, swap, a, b, false)
}

/// [`atan2`] of zeros, infinities, NaN and arguments near `f64::MAX`.
#[inline(never)]
fn atan2_special(y: f64, x: f64) -> f64 {
    let (ay, ax) = (y.abs(), x.abs());
    let swap = ay > ax;
    let (mut a, mut b) = (select(swap, ax, ay), select(swap, ay, ax));
    // both infinite: the answer is that of |y| = |x| (an odd multiple of pi/4)
    let both_infinite = ay == f64::INFINITY && ax == f64::INFINITY;
    a = select(both_infinite, 1.0, a);
    b = select(both_infinite, 1.0, b);
    // a + b would overflow near f64::MAX: halve both (exact at that size)
    let scale = select(b > ATAN2_PLAIN_MAX, 0.5, 1.0);
    atan2_octant(y, x, swap, a * scale, b * scale, true)
}

/// `atan2` from `0 <= a <= b` (`|y|, |x|` in some order, `swap` when `a = |x|`).
///
/// `t = a / b` in `[0, 1]`, or `(a - b) / (a + b)` (one division, no double rounding)
/// around `pi/4` when `a > tan(pi/8) b`; then `atan(t) = t + t z h(z)` and the octant is
/// restored by `k pi/4 +- atan(t)`, `k = 0 ..= 4`, with `pi/4` carried in two parts.
#[inline(always)]
fn atan2_octant(y: f64, x: f64, swap: bool, a: f64, b: f64, zero_possible: bool) -> f64 {
    let mid = a > TAN_PI_8 * b;
    let num = select(mid, a - b, a);
    let den = select(mid, a + b, b);
    // den = 0 only for x = y = 0 (t = 0, the signs of x and y then give +-0 or +-pi) or a
    // NaN y with x = 0 (t = NaN)
    let t = if zero_possible { select(den == 0.0, num, num / den) } else { num / den };
    let z = t * t;
    let mut p = ATAN[10];
    for &c in ATAN[..10].iter().rev() {
        p = p * z + c;
    }
    let r = t + t * (z * p);
    // octant: result = k pi/4 + s r, with s = -1 for (swap, x >= 0) and (no swap, x < 0)
    let negative_x = x.is_sign_negative();
    let base = select(negative_x, select(swap, 2.0, 4.0), select(swap, 2.0, 0.0));
    let s = select(swap != negative_x, -1.0, 1.0);
    let k = base + select(mid, s, 0.0);
    let angle = k * PI_4_HI + (s * r + k * PI_4_LO);
    angle.copysign(y)
}

/// [`atan2`] of four pairs at once (the four wheels): the same operations lane by lane, so
/// the same results bit for bit, laid out for the compiler to vectorize.
#[inline(always)]
pub fn atan2x4(y: [f64; 4], x: [f64; 4]) -> [f64; 4] {
    // `&`, not `&&`: four compares and no branch but one
    if is_plain(y[0], x[0]) & is_plain(y[1], x[1]) & is_plain(y[2], x[2]) & is_plain(y[3], x[3]) {
        core::array::from_fn(|i| atan2_plain(y[i], x[i]))
    } else {
        core::array::from_fn(|i| atan2(y[i], x[i]))
    }
}

/// `S(z) = (sin(sqrt z) / sqrt z - 1) / z` on `0 <= z <= (pi/4)^2`, powers `z^0 .. z^6`.
const SIN: [f64; 7] = [
    -0.16666666666666666,
    0.008333333333333331,
    -0.00019841269841265065,
    2.7557319219339167e-06,
    -2.5052106232447578e-08,
    1.6058531618986147e-10,
    -7.586697117706918e-13,
];
/// `C(z) = (cos(sqrt z) - 1 + z/2) / z^2` on `0 <= z <= (pi/4)^2`, powers `z^0 .. z^5`.
const COS: [f64; 6] = [
    0.041666666666666664,
    -0.0013888888888887398,
    2.480158729876569e-05,
    -2.7557317271729793e-07,
    2.08761462684032e-09,
    -1.1382632425521717e-11,
];
/// `pi/2` in four parts of 33 significant bits (the last one the rest): `k * PIO2_1..3` are
/// exact for `|k| < 2^20`, so the reduced argument carries no cancellation error.
const PIO2_1: f64 = 1.5707963267341256;
const PIO2_2: f64 = 6.077100506303966e-11;
const PIO2_3: f64 = 2.0222662487111665e-21;
const PIO2_4: f64 = 8.4784276603689e-32;
/// Largest `|x|` reduced here (`|k| < 2^17`); beyond, [`sin_cos`] uses the standard library.
pub const SIN_COS_FAST_MAX: f64 = 1e5;
/// `1.5 * 2^52`: adding and subtracting it rounds to the nearest integer (ties to even)
/// for `|v| < 2^51` without a `round` call (which baseline x86-64 lacks as an instruction).
const ROUND_MAGIC: f64 = 6755399441055744.0;

/// `(sin x, cos x)`. Within 2 ulp of glibc's (tested), including near multiples of `pi/2`.
///
/// `k = round(x 2/pi)`, `r = x - k pi/2` (Cody-Waite in four parts), `sin r = r + r z S(z)`,
/// `cos r = 1 - z/2 + z^2 C(z)` with the rounding error of `1 - z/2` carried, then the
/// quadrant `k mod 4` swaps and negates.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !(x.abs() <= SIN_COS_FAST_MAX) {
        return (x.sin(), x.cos());
    }
    let (sin_r, cos_r, q) = sin_cos_octant(x);
    // one argument: a branch on the quadrant is cheaper than selects (same values)
    match q & 3 {
        0 => (sin_r, cos_r),
        1 => (cos_r, -sin_r),
        2 => (-sin_r, -cos_r),
        _ => (-cos_r, sin_r),
    }
}

/// [`sin_cos`] of four arguments at once (the four steering angles): the same operations
/// lane by lane, so the same results bit for bit, branch-free when all four are in the
/// fast range so that the compiler vectorizes them.
#[inline(always)]
pub fn sin_cos4(x: [f64; 4]) -> ([f64; 4], [f64; 4]) {
    let fast = |v: f64| v.abs() <= SIN_COS_FAST_MAX;
    if fast(x[0]) & fast(x[1]) & fast(x[2]) & fast(x[3]) {
        let mut s = [0.0; 4];
        let mut c = [0.0; 4];
        for i in 0..4 {
            (s[i], c[i]) = sin_cos_reduced(x[i]);
        }
        (s, c)
    } else {
        let v = x.map(sin_cos);
        (v.map(|p| p.0), v.map(|p| p.1))
    }
}

/// [`sin_cos`] for `|x| <= SIN_COS_FAST_MAX`, without a branch.
#[inline(always)]
fn sin_cos_reduced(x: f64) -> (f64, f64) {
    let (sin_r, cos_r, q) = sin_cos_octant(x);
    // quadrant q = k mod 4: odd swaps sin and cos, then sin is negated in quadrants 2, 3
    // and cos in quadrants 1, 2 (bit operations: 64-bit lanes the compiler vectorizes)
    let swap = 0u64.wrapping_sub(q & 1);
    let (sb, cb) = (sin_r.to_bits(), cos_r.to_bits());
    let s0 = (cb & swap) | (sb & !swap);
    let c0 = (sb & swap) | (cb & !swap);
    (f64::from_bits(s0 ^ ((q & 2) << 62)), f64::from_bits(c0 ^ (((q + 1) & 2) << 62)))
}

/// `(sin r, cos r, q)` with `r = x - k pi/2`, `|r| <= pi/4`, for `|x| <= SIN_COS_FAST_MAX`,
/// and `q = k mod 4` in its two lowest bits.
#[inline(always)]
fn sin_cos_octant(x: f64) -> (f64, f64, u64) {
    let shifted = x * FRAC_2_PI + ROUND_MAGIC;
    // shifted = 1.5 2^52 + k: its significand field holds 2^51 + k, so its lowest bits are
    // those of k (two's complement for negative k)
    let q = shifted.to_bits();
    let k = shifted - ROUND_MAGIC;
    let r = (((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3) - k * PIO2_4;
    let z = r * r;
    let mut ps = SIN[6];
    for &c in SIN[..6].iter().rev() {
        ps = ps * z + c;
    }
    let mut pc = COS[5];
    for &c in COS[..5].iter().rev() {
        pc = pc * z + c;
    }
    // z = 0 (|r| < 1e-162): sin r = r, which also keeps the sign of -0
    let sin_r = select(z == 0.0, r, r + r * (z * ps));
    let half_z = 0.5 * z;
    let w = 1.0 - half_z;
    let cos_r = w + (((1.0 - w) - half_z) + z * (z * pc));
    (sin_r, cos_r, q)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_rng::{next_u64 as next, next_unit as uniform};

    /// Distance in units in the last place, through the ordered integer images of the
    /// values (so across a power of two it counts the representable numbers in between).
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |v: f64| {
            let i = v.to_bits() as i64;
            if i < 0 {
                i64::MIN - i
            } else {
                i
            }
        };
        key(a).abs_diff(key(b))
    }

    /// Same value (both NaN counts), or within `max_ulps`; returns the distance.
    fn check(name: &str, arg: (f64, f64), got: f64, want: f64, max_ulps: u64) -> u64 {
        if want.is_nan() {
            assert!(got.is_nan(), "{name}{arg:?} = {got:e}, glibc NaN");
            return 0;
        }
        let d = ulps(got, want);
        assert!(d <= max_ulps, "{name}{arg:?} = {got:e}, glibc {want:e}: {d} ulp");
        d
    }

    /// A double of random sign, exponent in `[lo, hi]` and significand.
    fn any_magnitude(state: &mut u64, lo: i32, hi: i32) -> f64 {
        let e = lo + (next(state) % (hi - lo + 1) as u64) as i32;
        let m = 1.0 + uniform(state);
        let v = m * 2f64.powi(e);
        if next(state) & 1 == 0 {
            v
        } else {
            -v
        }
    }

    #[test]
    fn atan2_is_within_2_ulp_of_glibc_everywhere() {
        let mut seed = 11u64;
        let mut worst = 0;
        let mut count = 0usize;
        let mut run = |y: f64, x: f64, worst: &mut u64| {
            *worst = (*worst).max(check("atan2", (y, x), atan2(y, x), y.atan2(x), 2));
            count += 1;
        };
        // 1e6 pairs of the same scale (every quadrant and octant, uniform angles) ...
        for _ in 0..1_000_000 {
            let scale = 2f64.powi((next(&mut seed) % 2000) as i32 - 1000);
            let angle = (2.0 * uniform(&mut seed) - 1.0) * core::f64::consts::PI;
            run(scale * angle.sin(), scale * angle.cos(), &mut worst);
        }
        // ... 1e6 of independent magnitudes (|y| >> |x| and |y| << |x|, subnormals, huge)
        for _ in 0..1_000_000 {
            let y = any_magnitude(&mut seed, -1074, 1023);
            let x = any_magnitude(&mut seed, -1074, 1023);
            run(y, x, &mut worst);
        }
        // ... and 2e5 near the octant boundaries |y| = |x| tan(k pi/8) and of nearly equal size
        for _ in 0..200_000 {
            let x = any_magnitude(&mut seed, -20, 20);
            let k = (next(&mut seed) % 3) as f64;
            let t = (k * core::f64::consts::FRAC_PI_8).tan() * (1.0 + 1e-12 * (2.0 * uniform(&mut seed) - 1.0));
            let y = x * t * if next(&mut seed) & 1 == 0 { 1.0 } else { -1.0 };
            run(y, x, &mut worst);
            run(x, y, &mut worst);
        }
        let special = [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            1.0,
            -1.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            f64::MAX,
            -f64::MAX,
            1e300,
            -3e-310,
        ];
        for &y in &special {
            for &x in &special {
                let got = atan2(y, x);
                run(y, x, &mut worst);
                // signed zeros and exact multiples of pi/4 are exact, sign included
                let want = y.atan2(x);
                if want == 0.0 || want.abs() == core::f64::consts::PI || want.abs() == core::f64::consts::FRAC_PI_2 {
                    assert_eq!(got.to_bits(), want.to_bits(), "atan2({y:e}, {x:e})");
                }
            }
        }
        assert!(count > 2_400_000);
        assert!(worst <= 2, "worst {worst} ulp");
        eprintln!("atan2: worst {worst} ulp over {count} arguments");
    }

    #[test]
    fn atan2x4_is_atan2_lane_by_lane() {
        let mut seed = 3u64;
        let special = [0.0, -0.0, f64::INFINITY, -f64::INFINITY, f64::NAN, 1e301, -f64::MAX, 5e-324];
        for n in 0..20_000 {
            let mut y: [f64; 4] = core::array::from_fn(|_| any_magnitude(&mut seed, -30, 30));
            let mut x: [f64; 4] = core::array::from_fn(|_| any_magnitude(&mut seed, -30, 30));
            // some with a special lane (zero, infinite, NaN, huge): the lanes take two paths
            if n % 5 == 0 {
                y[n % 4] = special[(n / 5) % 8];
                x[(n / 3) % 4] = special[(n / 40) % 8];
            }
            let v = atan2x4(y, x);
            for i in 0..4 {
                assert_eq!(v[i].to_bits(), atan2(y[i], x[i]).to_bits(), "atan2({}, {})", y[i], x[i]);
            }
        }
    }

    #[test]
    fn sin_cos4_is_sin_cos_lane_by_lane() {
        let mut seed = 9u64;
        for n in 0..20_000 {
            let mut x: [f64; 4] = core::array::from_fn(|_| any_magnitude(&mut seed, -40, 10));
            // some with a lane outside the fast range or not finite
            if n % 7 == 0 {
                x[n % 4] = [1e6, -1e200, f64::INFINITY, f64::NAN][(n / 7) % 4];
            }
            let (s, c) = sin_cos4(x);
            for i in 0..4 {
                let (si, ci) = sin_cos(x[i]);
                assert_eq!((s[i].to_bits(), c[i].to_bits()), (si.to_bits(), ci.to_bits()), "{}", x[i]);
            }
        }
    }

    #[test]
    fn sin_cos_is_within_2_ulp_of_glibc() {
        let mut seed = 5u64;
        let mut worst = 0;
        let run = |x: f64, worst: &mut u64| {
            let (s, c) = sin_cos(x);
            *worst = (*worst).max(check("sin", (x, 0.0), s, x.sin(), 2));
            *worst = (*worst).max(check("cos", (x, 0.0), c, x.cos(), 2));
        };
        // 1e6 arguments of every magnitude up to the fast range and beyond
        for _ in 0..1_000_000 {
            run(any_magnitude(&mut seed, -1074, 18), &mut worst);
        }
        // 1e6 uniform in the range a heading or a steering angle takes
        for _ in 0..1_000_000 {
            run(100.0 * (2.0 * uniform(&mut seed) - 1.0), &mut worst);
        }
        // the doubles nearest to k pi/2 and their neighbours: the reduced argument cancels
        // (the hardest case of the reduction)
        for k in -70_000i64..=70_000 {
            let x = k as f64 * core::f64::consts::FRAC_PI_2;
            for v in [x, f64::from_bits(x.to_bits() + 1), f64::from_bits(x.to_bits().wrapping_sub(1))] {
                if v.is_finite() {
                    run(v, &mut worst);
                }
            }
        }
        for x in [
            0.0,
            -0.0,
            5e-324,
            -5e-324,
            f64::MIN_POSITIVE,
            1e-8,
            core::f64::consts::FRAC_PI_4,
            -core::f64::consts::FRAC_PI_4,
            SIN_COS_FAST_MAX,
            -SIN_COS_FAST_MAX,
            f64::from_bits(SIN_COS_FAST_MAX.to_bits() + 1),
            1e300,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ] {
            run(x, &mut worst);
        }
        // sin(+-0) keeps the sign, cos(0) = 1 exactly
        assert_eq!(sin_cos(-0.0).0.to_bits(), (-0.0f64).to_bits());
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert!(worst <= 2, "worst {worst} ulp");
        eprintln!("sin_cos: worst {worst} ulp");
    }
}
