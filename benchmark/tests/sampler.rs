//! The test bench's sample-by-sample view ([`BenchSampler`]: the shared reference and the
//! per-seed disturbance table) against [`Benchmark::sample`] (the per-sample formulas), and
//! the process cache of references when threads ask for the same one at once.

use std::sync::Arc;

use nigel_benchmark::{figure8_switches, BenchSampler, Benchmark, Fidelity, Maneuver, Scenario};

fn sample_bits(s: &nigel_benchmark::BenchSample) -> Vec<u64> {
    let mut v: Vec<f64> = s.delta_ff.to_vec();
    v.extend([s.beta_ref, s.yaw_rate_ref, s.speed_ref, s.x_ref, s.y_ref, s.psi_ref]);
    v.extend(s.mu);
    v.extend([s.wind_x, s.wind_y, s.beta_meas, s.yaw_rate_meas]);
    v.into_iter().map(f64::to_bits).collect()
}

#[test]
fn sampler_is_benchmark_sample_bit_for_bit() {
    let n = 16_000;
    let mut cases = vec![
        Scenario { seed: 5, n_samples: n, ..Scenario::new(Maneuver::Figure8, Fidelity::Real) },
        Scenario { seed: 0, n_samples: n, ..Scenario::new(Maneuver::Slalom, Fidelity::Paper) },
        Scenario { seed: 9, n_samples: n, ..Scenario::new(Maneuver::LaneChange, Fidelity::Real) }.undisturbed(),
    ];
    cases.push(Scenario { wind: false, ..cases[0] });
    for scenario in cases {
        let bench = Benchmark::prepare(scenario).unwrap();
        let sampler = BenchSampler::prepare(scenario).unwrap();
        assert_eq!(sampler.scenario(), &scenario);
        assert_eq!(sampler.reference(), &bench.reference);
        assert_eq!(sampler.horizon(), n);
        for k in 0..=n {
            // an input that changes with k, as the plant's would
            let (beta, yaw_rate) = (1e-4 * k as f64 - 0.3, (k as f64 * 1e-3).sin());
            let (a, b) = (sampler.sample(k, beta, yaw_rate).unwrap(), bench.sample(k, beta, yaw_rate).unwrap());
            assert_eq!(sample_bits(&a), sample_bits(&b), "{scenario:?} k {k}");
        }
        assert!(sampler.sample(n + 1, 0.0, 0.0).is_none());
        assert!(bench.sample(n + 1, 0.0, 0.0).is_none());
    }
    let bad = Scenario { steer_amplitude: f64::NAN, ..Scenario::new(Maneuver::Skidpad, Fidelity::Paper) };
    assert_eq!(BenchSampler::prepare(bad).unwrap_err().name, "steer_amplitude");
}

/// The real-fidelity figure-8 needs the paper one's switching table: asked first (and by
/// two threads at once), it computes the paper reference once, through the cache, and the
/// table is the one of `figure8_switches`.
#[test]
fn real_figure8_first_computes_the_paper_reference_once() {
    let n = 12_000;
    let real = Scenario { n_samples: n, ..Scenario::new(Maneuver::Figure8, Fidelity::Real) };
    let paper = Scenario { fidelity: Fidelity::Paper, ..real };
    let (a, b) = std::thread::scope(|t| {
        let h = t.spawn(|| Benchmark::shared_reference(real).unwrap());
        (Benchmark::shared_reference(real).unwrap(), h.join().unwrap())
    });
    assert!(Arc::ptr_eq(&a, &b), "two threads, one reference");
    let switches = figure8_switches(real.steer_amplitude, real.speed_ref, n).unwrap();
    assert_eq!(&switches[..3], &[3144, 6267, 9390]);
    assert_eq!(a.program.switches, switches);
    // the paper reference was kept on the way: the same allocation, equal to a fresh one
    let p = Benchmark::shared_reference(paper).unwrap();
    assert!(Arc::ptr_eq(&p, &Benchmark::shared_reference(paper).unwrap()));
    assert_eq!(p.program.switches, switches);
    assert_eq!(*p, Benchmark::prepare_with_switches(paper, switches.clone()).unwrap().reference);
    assert_eq!(*a, Benchmark::prepare_with_switches(real, switches).unwrap().reference);
}
