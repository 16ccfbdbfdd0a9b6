"""`cosim run --interface me --solver bdf` on van der Pol (cosim/tests/cfmu/vdp.c) against
a reference independent of the master: SciPy's Radau (an implicit Runge-Kutta method) on
the equations written in stiff_reference.py, at rtol 1e-10. mu = 1e3, 1e4, 1e5 from t = 0 to
mu: the slow branch from x0 = 2 and the first fast transition (near 0.81 mu), 500 rows."""
import subprocess

import numpy as np
import pytest

from stiff_reference import (TRANSITION_RESOLUTION, build_cfmu, relative_error, transition_errors,
                             vdp_reference, vdp_transition_reference)


_references = {}


def reference(mu):
    """The 501 rows of the Radau reference at mu (computed once per mu)."""
    if mu not in _references:
        _references[mu] = vdp_reference(mu, np.arange(501) * (mu / 500))
    return _references[mu]


@pytest.fixture(scope="module")
def vdp_fmu(tmp_path_factory):
    return build_cfmu("vdp", tmp_path_factory.mktemp("vdp"))


def run_bdf(cosim, fmu, mu, rtol, out):
    args = [str(cosim), "run", str(fmu), "--interface", "me", "--solver", "bdf", "--rtol", repr(rtol),
            "--set", f"mu={mu!r}", "--stop-time", repr(mu), "--step", repr(mu / 500), "--output", str(out),
            "--record", "x0", "--record", "x1"]
    done = subprocess.run(args, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    r = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    return r["time"], np.column_stack([r["x0"], r["x1"]])


@pytest.mark.parametrize("mu", [1e3, 1e4, 1e5])
def test_bdf_on_van_der_pol_matches_an_independent_radau_reference(cosim, vdp_fmu, tmp_path, mu):
    times = np.arange(501) * (mu / 500)
    ref = reference(mu)
    # the reference itself: the transition of x0 through 0 (half a period of the relaxation
    # oscillation, (3/2 - ln 2) mu + O(mu^(-1/3)) for large mu: 0.807 mu)
    crossing = times[np.argmax(ref[:, 0] < 0.0)]
    assert 0.79 * mu < crossing < 0.82 * mu, crossing
    errors = {}
    for rtol in (1e-6, 1e-8):
        t, x = run_bdf(cosim, vdp_fmu, mu, rtol, tmp_path / "out.csv")
        np.testing.assert_allclose(t, times, rtol=1e-12)
        errors[rtol] = relative_error(x, ref)
    print(f"mu {mu:.0e}: errors {errors}")
    # The error is the largest over the rows of |x - x_ref| / max(1, |x_ref|). On the slow
    # branch an error of x0 is neither damped nor amplified (x0 moves along the branch), so
    # the local errors of the steps (each below rtol, weights atol + rtol |x|) add up: the
    # run takes 600 .. 900 steps at rtol 1e-6 .. 1e-8, about 1e3 rtol at most (measured:
    # 420 .. 750 rtol at 1e-6, 580 .. 1400 rtol at 1e-8). 5e3 rtol bounds it with a margin of
    # 3.7 or more. A transition late or early by more than the spacing of the rows to it (x0
    # on the other branch at a row, an error near 3) fails it at either rtol.
    for rtol, e in errors.items():
        assert e < 5e3 * rtol, f"mu {mu:.0e}, rtol {rtol:.0e}: error {e:.2e} ({errors})"


@pytest.mark.parametrize("mu", [1e3, 1e4, 1e5])
@pytest.mark.parametrize("rtol", [1e-4, 1e-5])
def test_bdf_puts_the_transition_of_van_der_pol_where_radau_does_within_100_rtol(cosim, vdp_fmu, tmp_path, mu, rtol):
    """The phase of the relaxation oscillation at loose tolerances: the first transition's time
    against Radau's (stiff_reference.vdp_transition_reference), found on rows 1/20,000 of mu
    apart. Along the slow branch an error of x0 is neither damped nor amplified, so the local
    errors of the steps (each below rtol in the weighted norm) add up into a shift of the
    transition, a multiple of rtol. Measured: 12 .. 25 rtol at rtol 1e-4, 21 .. 43 rtol at
    1e-5 (fmpy's CVode: 2.6 .. 8.7 and 29 .. 50; docs/performance.md, "The phase of van der Pol
    at loose tolerances"). 100 rtol bounds it with a margin of 2.3 or more: a change that
    doubles the phase error fails here."""
    ref = vdp_transition_reference(mu)
    # the reference itself against the asymptotics of the relaxation oscillation: the slow
    # branch from x0 = 2 to the fold at x0 = 1 takes (3/2 - ln 2) mu, the passage of the fold
    # alpha mu^(-1/3) more (alpha = 2.33811, the first zero of Ai(-z)), the jump to x0 = 0
    # O(1/mu): the rest is 1.9e-3 s at mu = 1e3 and smaller above; 1e-2 s bounds it
    expansion = (1.5 - np.log(2.0)) * mu + 2.33811 * mu ** (-1.0 / 3.0)
    assert abs(ref - expansion) < 1e-2, (ref, expansion)
    (shift, _), _ = transition_errors(cosim, vdp_fmu, mu, rtol, tmp_path, with_cvode=False)
    print(f"mu {mu:.0e}, rtol {rtol:.0e}: transition at {ref * (1.0 + shift):.3f} s, Radau {ref:.3f} s, "
          f"shift {shift:.2e} ({abs(shift) / rtol:.1f} rtol)")
    assert abs(shift) < 100.0 * rtol + TRANSITION_RESOLUTION, f"mu {mu:.0e}, rtol {rtol:.0e}: shift {shift:.2e}"
