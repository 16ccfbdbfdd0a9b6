//! Counter-based SplitMix64 noise (docs/benchmark.md, "Noise"): every sample of every stream is a
//! pure function of `(seed, stream, k)`, so any implementation, in any order, on any number
//! of threads, draws the same numbers.

use core::f64::consts::PI;

/// The SplitMix64 increment (golden ratio), `G = 0x9E3779B97F4A7C15`.
pub const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// Stream of the friction noise of wheel `i` (FL, FR, RL, RR = 0..3).
pub const STREAM_FRICTION: [u8; 4] = [0, 1, 2, 3];
/// Stream of the wind noise `chi`.
pub const STREAM_WIND: u8 = 4;
/// Stream of the measurement noise of `beta`.
pub const STREAM_BETA: u8 = 5;
/// Stream of the measurement noise of the yaw rate.
pub const STREAM_YAW_RATE: u8 = 6;

/// The SplitMix64 finaliser (wrapping 64-bit arithmetic).
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z ^= z >> 30;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 27;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform on `[0, 1)` with 53 random bits:
/// `u = (mix(((seed << 8) | stream) + (k + 1) G) >> 11) * 2^-53`.
#[inline]
pub fn u(seed: u64, stream: u8, k: u64) -> f64 {
    let key = (seed << 8) | stream as u64;
    let z = key.wrapping_add(k.wrapping_add(1).wrapping_mul(GOLDEN));
    (mix(z) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Standard normal by Box-Muller from two uniforms of the same stream:
/// `g_k = sqrt(-2 ln(1 - u(2k))) cos(2 pi u(2k + 1))` (`1 - u` is in `(0, 1]`, so the log is finite).
#[inline]
pub fn g(seed: u64, stream: u8, k: u64) -> f64 {
    let u1 = u(seed, stream, 2 * k);
    let u2 = u(seed, stream, 2 * k + 1);
    (-2.0 * (1.0 - u1).ln()).sqrt() * (2.0 * PI * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vectors from an independent implementation of docs/benchmark.md (bit-exact).
    #[test]
    fn uniform_vectors() {
        assert_eq!(u(0, 0, 0), 0.8833108082136426);
        assert_eq!(u(0, 0, 1), 0.43152799704850997);
        assert_eq!(u(0, 0, 2), 0.026433771592597743);
        assert_eq!(u(7, 4, 29999), 0.6463711253706377);
    }

    /// The same vectors as far as the platform's libm allows: `g` calls `ln` and `cos`, which
    /// IEEE 754 does not require to be correctly rounded (glibc, musl and the MSVC runtime are
    /// within 1 ulp of it), while `sqrt`, `*` and `-` are exact to the rounding. The vectors
    /// are glibc's; another libm may move `g` by 1 ulp of `ln` (half an ulp after the square
    /// root) plus 1 ulp of `cos`, under 2 ulp of `g`: 1e-15 relative (4.5 ulp) holds that on any
    /// machine and is still far below the 2^-53 steps of the uniforms that feed `g`.
    #[test]
    fn gaussian_vectors() {
        for (got, want) in
            [(g(0, 5, 0), 0.014334745996352224), (g(0, 5, 1), 0.5906209568869251), (g(3, 6, 100), -0.5936807237213725)]
        {
            assert!((got - want).abs() <= 1e-15 * want.abs(), "{got:e} vs {want:e}");
        }
    }

    /// The sample mean and (biased) variance of `sample(0)` .. `sample(n - 1)`.
    fn mean_and_variance(n: u64, sample: impl Fn(u64) -> f64) -> (f64, f64) {
        let (mut s, mut s2) = (0.0, 0.0);
        for k in 0..n {
            let x = sample(k);
            s += x;
            s2 += x * x;
        }
        let mean = s / n as f64;
        (mean, s2 / n as f64 - mean * mean)
    }

    #[test]
    fn uniform_moments_and_range() {
        let (mean, var) = mean_and_variance(200_000, |k| {
            let x = u(11, 2, k);
            assert!((0.0..1.0).contains(&x));
            x
        });
        // standard error of the mean 0.29 / sqrt(2e5) = 6.5e-4
        assert!((mean - 0.5).abs() < 3e-3, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 2e-3, "{var}");
    }

    #[test]
    fn gaussian_moments() {
        let (mean, var) = mean_and_variance(100_000, |k| {
            let x = g(1, 5, k);
            assert!(x.is_finite());
            x
        });
        assert!(mean.abs() < 0.015, "{mean}");
        assert!((var - 1.0).abs() < 0.02, "{var}");
    }

    #[test]
    fn streams_and_seeds_differ() {
        assert_ne!(u(0, 0, 5), u(0, 1, 5));
        assert_ne!(u(0, 0, 5), u(1, 0, 5));
        // seeds are shifted by 8 bits: seed 1 stream 0 is not seed 0 stream 1... nor 256
        assert_ne!(u(1, 0, 0), u(0, 1, 0));
    }
}
