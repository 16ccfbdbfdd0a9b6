//! Bad input is refused with a clear message, never a panic or a bogus gain.

use nigel_synthesis::{
    min_h2, min_hinf, pareto_sweep, pole_placement_baseline, weighted, Architecture, PlantError, PlantSpec, PoleRegion,
    Region, SweepOptions, SynthesisError, SynthesisOptions,
};

fn spec() -> PlantSpec {
    PlantSpec::paper(Architecture::FourWheelSteering)
}

fn refused(s: PlantSpec, needle: &str) {
    let e = s.polytope().expect_err("must be refused");
    let msg = e.to_string();
    assert!(msg.contains(needle), "message '{msg}' should name '{needle}'");
}

#[test]
fn nan_and_negative_plant_parameters_are_refused() {
    let mut s = spec();
    s.params.m = f64::NAN;
    refused(s, "m = NaN");
    let mut s = spec();
    s.params.i_z = -0.01944;
    refused(s, "I_z");
    let mut s = spec();
    s.params.c[2] = -1.0;
    refused(s, "c_rl");
    let mut s = spec();
    s.params.c = [0.0; 4];
    refused(s, "cornering");
    let mut s = spec();
    s.speed = -0.35;
    refused(s, "speed = -0.35");
    let mut s = spec();
    s.speed = f64::INFINITY;
    refused(s, "speed");
    let mut s = spec();
    s.mu_min = -0.1;
    refused(s, "mu_min = -0.1");
    let mut s = spec();
    s.mu_min = f64::NAN;
    refused(s, "mu_min");
    let mut s = spec();
    s.mu_max = 0.05;
    refused(s, "mu_max");
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
