"""fmpy's keywords that users pass out of habit (issue 40): each is accepted with fmpy's
meaning (then the run is checked against fmpy's own, or against the same run without the
keyword, which fmpy's meaning makes equal) or refused with a `nigel_cosim.Error` that says
what to use instead; an SSP given to `simulate_fmu` names `simulate_ssp`; a communication
step longer than an FMU's sample period warns as `cosim run` does.

Run by scripts/test-python-package.sh in the venv of README.md's install line."""

import subprocess
import warnings

import fmpy
import numpy as np
import pytest

import nigel_cosim
from test_package import COSIM, FMU, SSP

PLANT = FMU / "nigel_plant.fmu"
RUN = dict(stop_time=0.2, start_values={"v_x_start": 0.35, "delta_fl": 0.2, "delta_fr": 0.2})


def same(a, b):
    assert a.dtype.names == b.dtype.names
    for field in a.dtype.names:
        assert np.array_equal(a[field], b[field]), field


# --- accepted with fmpy's meaning -----------------------------------------------------------

@pytest.mark.parametrize("kwargs", [dict(validate=True), dict(apply_default_start_values=True),
                                    dict(apply_default_start_values=False), dict(debug_logging=False),
                                    dict(record_events=True), dict(record_events=False), dict(timeout=600.0)])
def test_accepted_keywords_give_fmpys_run_in_co_simulation(kwargs):
    # fmpy's Co-Simulation of the plant is ours bit for bit (test_package.py); with each
    # keyword both tools give the same run again (record_events means nothing in
    # Co-Simulation, in fmpy as here; the start values are the FMU's own either way)
    ours = nigel_cosim.simulate_fmu(PLANT, **RUN, **kwargs)
    theirs = fmpy.simulate_fmu(str(PLANT), **RUN, **kwargs)
    same(ours, theirs)


def test_output_interval_with_step_size_is_fmpys_in_co_simulation():
    # fmpy steps a Co-Simulation FMU by output_interval; step_size only picks a default interval
    kwargs = dict(**RUN, step_size=1e-3, output_interval=4e-3)
    ours = nigel_cosim.simulate_fmu(PLANT, **kwargs)
    theirs = fmpy.simulate_fmu(str(PLANT), **kwargs)
    assert len(ours) == 51
    same(ours, theirs)


def test_record_events_false_and_rk4_step_size_in_model_exchange():
    me = dict(**RUN, fmi_type="ModelExchange", solver="rk4")
    by_output = nigel_cosim.simulate_fmu(PLANT, **me, output_interval=1e-3)
    # record_events=False: the output points only, which is what this master records
    same(nigel_cosim.simulate_fmu(PLANT, **me, output_interval=1e-3, record_events=False), by_output)
    # step_size with output_interval: fixed steps of step_size between the output points (as
    # fmpy's fixed-step solver); 1 ms steps recorded every 4 ms are the 1 ms run's every 4th
    # row up to rounding in the step's time (t0 + n h against sums of h): 1e-12 m here, where
    # 4 ms steps differ from 1 ms steps by the method's error (1e-9 m or more, asserted)
    coarse_output = nigel_cosim.simulate_fmu(PLANT, **me, step_size=1e-3, output_interval=4e-3)
    coarse_steps = nigel_cosim.simulate_fmu(PLANT, **me, output_interval=4e-3)
    assert len(coarse_output) == 51
    assert np.array_equal(coarse_output["time"], by_output["time"][::4])
    for q in ("x", "y", "psi"):
        assert np.max(np.abs(coarse_output[q] - by_output[q][::4])) < 1e-12, q
    assert max(np.max(np.abs(coarse_steps[q] - by_output[q][::4])) for q in ("x", "y", "psi")) > 1e-9


def test_timeout_raises_where_fmpy_returns_a_short_result():
    with pytest.raises(nigel_cosim.RunTimeoutError):
        nigel_cosim.simulate_fmu(PLANT, stop_time=1000.0, output_interval=1e-3, timeout=1e-3)


# --- refused, saying what to use ------------------------------------------------------------

@pytest.mark.parametrize("kwargs,says", [
    (dict(validate=False), "drop validate=False"),
    (dict(debug_logging=True), "fmpy.simulate_fmu(..., debug_logging=True)"),
    (dict(step_finished=lambda time, recorder: True), "nigel_cosim.System"),
    (dict(fmi_call_logger=print), "fmi_call_logger=print"),
    (dict(solver="Euler", fmi_type="ModelExchange", step_size=1e-3), "use solver='rk4' with the same step_size"),
    (dict(visible=True), "does not know: visible"),
])
def test_refused_keywords_say_what_to_use(kwargs, says):
    with pytest.raises(nigel_cosim.Error) as e:
        nigel_cosim.simulate_fmu(PLANT, **{**RUN, **kwargs})
    assert says in str(e.value), str(e.value)


def test_record_events_true_in_model_exchange_is_refused():
    with pytest.raises(nigel_cosim.Error, match="record_events=False"):
        nigel_cosim.simulate_fmu(PLANT, **RUN, fmi_type="ModelExchange", record_events=True)


def test_simulate_fmu_on_an_ssp_names_simulate_ssp():
    with pytest.raises(nigel_cosim.LoadError, match="use nigel_cosim.simulate_ssp"):
        nigel_cosim.simulate_fmu(SSP)


# --- a step longer than the controller's sample period ----------------------------------------

def test_simulate_ssp_warns_of_a_step_longer_than_the_sample_period_as_the_cli():
    with pytest.warns(UserWarning) as caught:
        loop = nigel_cosim.simulate_ssp(SSP, stop_time=1.0, step_size=0.1, output=["plant.y"])
    messages = [str(w.message) for w in caught]
    # the controller (sample_period 1 ms) and the test bench (its 1 ms samples) both
    assert any(m.startswith("controller (nigel_controller.fmu) runs every 0.001 s") for m in messages), messages
    assert all(m.endswith("(use step_size=0.001)") for m in messages), messages
    assert len(loop) == 11
    # the command line says the same words, with its own option for the step
    r = subprocess.run([str(COSIM), "run", str(SSP), "--stop-time", "1", "--step", "0.1", "--record", "plant.y"],
                       capture_output=True, text=True, check=True)
    cli = [line.removeprefix("cosim: warning: ") for line in r.stderr.splitlines() if line.startswith("cosim: warning: ")]
    assert [m.removesuffix(" (use step_size=0.001)") for m in messages] == \
        [c.removesuffix(" (use --step 0.001)") for c in cli]
    # at the sample period: no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        nigel_cosim.simulate_ssp(SSP, stop_time=0.01, step_size=1e-3, output=["plant.y"])
