//! Counter-based draws: every random value of sample `s` in column `name` is a pure function
//! of `(seed, name, s)`, built on the test bench's SplitMix64 finaliser
//! ([`nigel_benchmark::noise::mix`]), so no generator state is carried between runs.

use nigel_benchmark::noise::{mix, GOLDEN};

use crate::scalar::Scalar;

/// How a random column is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum Distribution {
    /// Uniform on `[low, high)`.
    Uniform(f64, f64),
    /// Normal with mean and standard deviation, optionally truncated to `[min, max]`
    /// (rejection: the draw is repeated with the next counter until it falls inside; at least
    /// 1 % of the distribution must lie inside).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        std: f64,
        /// Lower bound, if any.
        min: Option<f64>,
        /// Upper bound, if any.
        max: Option<f64>,
    },
    /// Integers `low ..= high`, each equally likely.
    Integers(i64, i64),
    /// One of the listed values, each equally likely.
    Choice(Vec<Scalar>),
}

/// FNV-1a of the column name: columns draw from independent streams, and adding a column
/// leaves the others' draws unchanged.
fn name_key(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// Uniform on `[0, 1)` with 53 random bits, the `k`-th of run `run` in column `name`:
/// `mix(key + (run * 2^16 + k + 1) G)` with `key = mix(seed ^ mix(fnv1a(name)))`.
pub fn uniform01(seed: u64, name: &str, run: u64, k: u64) -> f64 {
    let key = mix(seed ^ mix(name_key(name)));
    let counter = (run << 16).wrapping_add(k).wrapping_add(1);
    (mix(key.wrapping_add(counter.wrapping_mul(GOLDEN))) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The value of `dist` for sample `run` (the run's sample index) in column `name`.
pub fn draw(dist: &Distribution, seed: u64, name: &str, run: u64) -> Scalar {
    let u = |k: u64| uniform01(seed, name, run, k);
    match dist {
        Distribution::Uniform(a, b) => Scalar::Real(a + (b - a) * u(0)),
        Distribution::Integers(a, b) => {
            let span = (b - a) as u64 + 1;
            Scalar::Integer(a + ((u(0) * span as f64) as u64).min(span - 1) as i64)
        }
        Distribution::Choice(values) => {
            let n = values.len() as u64;
            values[((u(0) * n as f64) as u64).min(n - 1) as usize].clone()
        }
        Distribution::Normal { mean, std, min, max } => {
            // Box-Muller on pairs of the stream, until inside [min, max]: the description's
            // check makes sure at least 1 % of the mass is inside, so 2^14 pairs all outside
            // have probability below 0.99^16384 = 1e-71 (the clamp is never reached)
            let mut k = 0;
            loop {
                let g = (-2.0 * (1.0 - u(k)).ln()).sqrt() * (2.0 * std::f64::consts::PI * u(k + 1)).cos();
                let x = mean + std * g;
                if min.map_or(true, |m| x >= m) && max.map_or(true, |m| x <= m) || k > 1 << 15 {
                    return Scalar::Real(x.clamp(min.unwrap_or(f64::NEG_INFINITY), max.unwrap_or(f64::INFINITY)));
                }
                k += 2;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_moments_and_independence_of_columns() {
        let n = 100_000u64;
        let (mut s, mut s2, mut cross) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let a = uniform01(3, "plant.m", i, 0);
            let b = uniform01(3, "plant.c", i, 0);
            assert!((0.0..1.0).contains(&a));
            s += a;
            s2 += a * a;
            cross += (a - 0.5) * (b - 0.5);
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        // standard error of the mean: sqrt(1/12 / 1e5) = 9.1e-4; 4.4 sigma bounds
        assert!((mean - 0.5).abs() < 4e-3, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 3e-3, "{var}");
        // covariance of independent uniforms: standard error 1/12 / sqrt(1e5) = 2.6e-4
        assert!((cross / n as f64).abs() < 1.2e-3);
    }

    #[test]
    fn truncated_normal_stays_inside_and_integers_cover_their_range() {
        let d = Distribution::Normal { mean: 0.0, std: 1.0, min: Some(-0.5), max: Some(2.0) };
        let mut counts = [0u32; 5];
        for i in 0..20_000 {
            let Scalar::Real(x) = draw(&d, 1, "x", i) else { panic!() };
            assert!((-0.5..=2.0).contains(&x));
            let Scalar::Integer(k) = draw(&Distribution::Integers(-2, 2), 1, "k", i) else { panic!() };
            counts[(k + 2) as usize] += 1;
        }
        // 4000 expected each, binomial standard deviation 57: 5 sigma
        assert!(counts.iter().all(|c| (c.abs_diff(4000)) < 285), "{counts:?}");
    }
}
