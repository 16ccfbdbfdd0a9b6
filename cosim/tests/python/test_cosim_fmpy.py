"""The master against fmpy 0.3.32 on our plant FMU: same values at every output point."""
import subprocess

import numpy as np
from fmpy import simulate_fmu

START = {"v_x_start": 0.35, "delta_fl": 0.2, "delta_fr": 0.2, "mu_rl": 0.3, "wind_side": 0.05, "tau_rl": 0.01}


def run_cosim(cosim, fmu, out, *extra):
    args = [str(cosim), "run", str(fmu), "--output", str(out), *extra]
    subprocess.run(args, check=True, capture_output=True, text=True)
    return np.genfromtxt(out, delimiter=",", names=True, deletechars="")


def test_single_fmu_co_simulation_equals_fmpy(cosim, plant_fmu, tmp_path):
    stop, h = 3.0, 1e-3
    sets = [a for k, v in START.items() for a in ("--set", f"{k}={v}")]
    ours = run_cosim(cosim, plant_fmu, tmp_path / "ours.csv", "--stop-time", str(stop), "--step", str(h), *sets)
    ref = simulate_fmu(str(plant_fmu), fmi_type="CoSimulation", stop_time=stop, output_interval=h,
                       start_values=START)
    assert len(ours) == len(ref) == 3001
    assert np.array_equal(ours["time"], ref["time"])
    names = [n for n in ref.dtype.names if n != "time"]
    assert len(names) >= 20 and set(names) <= set(ours.dtype.names)
    worst = max(float(np.max(np.abs(ours[n] - ref[n]))) for n in names)
    # same FMU, same calls, same step sizes: the same bits
    assert worst == 0.0, f"largest difference {worst}"
    assert abs(ours["psi"][-1]) > 1e-3  # the car really turned


def test_ordered_equals_jacobi_for_one_fmu_and_csv_format(cosim, plant_fmu, tmp_path):
    a = run_cosim(cosim, plant_fmu, tmp_path / "a.csv", "--stop-time", "0.1", "--step", "1e-3",
                  "--algorithm", "ordered", "--set", "v_x_start=0.3", "--record", "v_x", "--record", "x",
                  "--output-interval", "0.01")
    b = run_cosim(cosim, plant_fmu, tmp_path / "b.csv", "--stop-time", "0.1", "--step", "1e-3",
                  "--algorithm", "jacobi", "--set", "v_x_start=0.3", "--record", "v_x", "--record", "x",
                  "--output-interval", "0.01")
    assert a.dtype.names == ("time", "v_x", "x")
    assert len(a) == 11
    assert np.allclose(a["time"], np.linspace(0, 0.1, 11), rtol=0, atol=1e-15)
    assert np.array_equal(np.asarray(a.tolist()), np.asarray(b.tolist()))
    header = (tmp_path / "a.csv").read_text().splitlines()[0]
    assert header == '"time","v_x","x"'


def test_bad_input_gives_a_clear_message(cosim, plant_fmu, tmp_path):
    r = subprocess.run([str(cosim), "run", str(plant_fmu), "--stop-time", "1", "--step", "0.1",
                        "--output-interval", "0.15"], capture_output=True, text=True)
    assert r.returncode != 0 and "whole multiple of the step" in r.stderr
    # the plant handles variable steps: a shorter last step ends at the stop time, as in fmpy
    out = tmp_path / "short.csv"
    subprocess.run([str(cosim), "run", str(plant_fmu), "--stop-time", "1", "--step", "0.3", "--output", str(out)],
                   check=True)
    t = np.genfromtxt(out, delimiter=",", names=True, deletechars="")["time"]
    assert t[-1] == 1.0 and len(t) == 5
    r = subprocess.run([str(cosim), "run", str(plant_fmu), "--set", "m=-1"], capture_output=True, text=True)
    assert r.returncode != 0 and "fmi2" in r.stderr, r.stderr
    r = subprocess.run([str(cosim), "run", str(tmp_path / "missing.fmu")], capture_output=True, text=True)
    assert r.returncode != 0 and "missing.fmu" in r.stderr
    r = subprocess.run([str(cosim), "info", str(plant_fmu)], capture_output=True, text=True, check=True)
    assert "delta_fl" in r.stdout and "rad" in r.stdout and "input" in r.stdout


def test_model_exchange_dopri5_agrees_with_fmpy_cvode(cosim, plant_fmu, tmp_path):
    # constant inputs (start values), so fmpy's CVode is not restarted at input changes
    stop, h = 2.0, 1e-2
    sets = [a for k, v in START.items() for a in ("--set", f"{k}={v}")]
    ours = run_cosim(cosim, plant_fmu, tmp_path / "me.csv", "--interface", "me", "--solver", "dopri5",
                     "--rtol", "1e-10", "--stop-time", str(stop), "--step", str(h), *sets)
    ref = simulate_fmu(str(plant_fmu), fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-10,
                       stop_time=stop, output_interval=h, start_values=START)
    assert len(ours) == len(ref) == 201
    for name in ["x", "y", "psi", "v_x", "v_y", "yaw_rate", "lateral_accel"]:
        scale = max(1.0, float(np.max(np.abs(ref[name]))))
        diff = float(np.max(np.abs(ours[name] - ref[name])))
        assert diff <= 1e-7 * scale, f"{name}: {diff}"
    # and our ME RK4 at the CS sub-step equals the FMU's own CS RK4 (the Rust test shows
    # 2e-15); here against fmpy's CS run of the same FMU
    rk4 = run_cosim(cosim, plant_fmu, tmp_path / "rk4.csv", "--interface", "me", "--max-step", "5e-4",
                    "--stop-time", str(stop), "--step", "1e-3", "--output-interval", str(h), *sets)
    cs = simulate_fmu(str(plant_fmu), fmi_type="CoSimulation", stop_time=stop, output_interval=1e-3,
                      start_values=START)[::10]
    assert len(rk4) == len(cs) == 201
    assert max(float(np.max(np.abs(rk4[n] - cs[n]))) for n in ["x", "y", "psi", "v_x", "v_y"]) < 1e-12
