//! Bad input is refused with a clear message, never a panic or a bogus gain.

use nigel_synthesis::{
    min_h2, min_hinf, pareto_sweep, pole_placement_baseline, weighted, Architecture, PlantError, PlantSpec, PoleRegion,
    Region, SweepOptions, SynthesisError, SynthesisOptions,
};

fn spec() -> PlantSpec {
    PlantSpec::paper(Architecture::FourWheelSteering)
}

/// The paper's spec after `change` is refused, the message naming `needle`.
fn refused(change: impl FnOnce(&mut PlantSpec), needle: &str) {
    let mut s = spec();
    change(&mut s);
    let e = s.polytope().expect_err("must be refused");
    let msg = e.to_string();
    assert!(msg.contains(needle), "message '{msg}' should name '{needle}'");
}

#[test]
fn nan_and_negative_plant_parameters_are_refused() {
    refused(|s| s.params.m = f64::NAN, "m = NaN");
    refused(|s| s.params.i_z = -0.01944, "I_z");
    refused(|s| s.params.c[2] = -1.0, "c_rl");
    refused(|s| s.params.c = [0.0; 4], "cornering");
    refused(|s| s.speed = -0.35, "speed = -0.35");
    refused(|s| s.speed = f64::INFINITY, "speed");
    refused(|s| s.mu_min = -0.1, "mu_min = -0.1");
    refused(|s| s.mu_min = f64::NAN, "mu_min");
    refused(|s| s.mu_max = 0.05, "mu_max");
    let e = {
        let mut s = spec();
        s.params.l_r = f64::NAN;
        s.validate().unwrap_err()
    };
    assert!(matches!(e, PlantError::Params(_)));
}

#[test]
fn problems_refuse_a_bad_spec_even_with_a_prebuilt_polytope() {
    let mut poly = spec().polytope().unwrap();
    poly.spec.speed = f64::NAN;
    let opts = SynthesisOptions::default();
    let r = PoleRegion::paper();
    assert!(matches!(min_hinf(&poly, &r, &opts), Err(SynthesisError::Plant(_))));
    assert!(matches!(min_h2(&poly, &r, None, &opts), Err(SynthesisError::Plant(_))));
    assert!(matches!(weighted(&poly, &r, 1.0, 1.0, &opts), Err(SynthesisError::Plant(_))));
    assert!(matches!(pole_placement_baseline(&poly, 0.4, -2.0, &opts), Err(SynthesisError::Plant(_))));
}

#[test]
fn bad_regions_bounds_weights_and_margins_are_refused() {
    let poly = spec().polytope().unwrap();
    let opts = SynthesisOptions::default();
    for region in [
        PoleRegion::paper().and(Region::half_plane(f64::NAN)),
        PoleRegion::paper().and(Region::sector_inner_angle_deg(180.0)),
        PoleRegion::paper().and(Region::sector_inner_angle_deg(-10.0)),
        PoleRegion::paper().and(Region::disk(0.0, -5.0)),
        PoleRegion::paper().and(Region::disk(f64::INFINITY, 5.0)),
    ] {
        let e = min_hinf(&poly, &region, &opts).unwrap_err();
        assert!(matches!(e, SynthesisError::Region(_)), "{e:?}");
        assert!(e.to_string().contains("invalid pole region"), "{e}");
    }
    let r = PoleRegion::paper();
    for g in [f64::NAN, -0.2, 0.0] {
        let e = min_h2(&poly, &r, Some(g), &opts).unwrap_err();
        assert!(matches!(e, SynthesisError::Invalid(_)) && e.to_string().contains("H-inf bound"), "{e}");
    }
    assert!(matches!(weighted(&poly, &r, -1.0, 1.0, &opts), Err(SynthesisError::Invalid(_))));
    assert!(matches!(weighted(&poly, &r, 0.0, 0.0, &opts), Err(SynthesisError::Invalid(_))));
    assert!(matches!(weighted(&poly, &r, 1.0, f64::NAN, &opts), Err(SynthesisError::Invalid(_))));
    let bad = SynthesisOptions { margin: f64::NAN, ..SynthesisOptions::default() };
    assert!(matches!(min_hinf(&poly, &r, &bad), Err(SynthesisError::Invalid(_))));
    let bad_sweep = SweepOptions { step: 0.0, ..SweepOptions::default() };
    assert!(matches!(pareto_sweep(&poly, &r, &bad_sweep, &opts, None), Err(SynthesisError::Invalid(_))));
    assert!(matches!(pole_placement_baseline(&poly, f64::NAN, -2.0, &opts), Err(SynthesisError::Invalid(_))));
}

#[test]
fn an_h_inf_bound_below_gamma_star_is_infeasible() {
    let poly = spec().polytope().unwrap();
    let e = min_h2(&poly, &PoleRegion::paper(), Some(0.1), &SynthesisOptions::default()).unwrap_err();
    assert!(e.is_infeasible(), "{e:?}");
}
