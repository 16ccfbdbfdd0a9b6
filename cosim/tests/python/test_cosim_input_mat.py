"""`cosim run --input FILE.csv` against fmpy's `simulate_fmu(input=...)` on the plant, and
`--output x.mat` read back by the MAT v4 format's definition."""
import subprocess

import numpy as np
from fmpy import simulate_fmu


def test_input_signals_equal_fmpy(cosim, plant_fmu, tmp_path):
    # rows off the 1 ms grid, so that most steps interpolate between two rows; strictly
    # increasing times and continuous inputs only: no input events, the same grid in both
    t = np.array([0.0, 0.1234, 0.5, 0.77, 1.3, 2.0])
    signals = np.zeros(t.size, dtype=[("time", float), ("delta_fl", float), ("delta_fr", float), ("tau_rl", float)])
    signals["time"] = t
    signals["delta_fl"] = [0.0, 0.2, -0.1, 0.3, 0.05, 0.0]
    signals["delta_fr"] = [0.0, 0.1, 0.1, -0.2, 0.0, 0.1]
    signals["tau_rl"] = [0.0, 0.02, 0.01, 0.0, 0.03, 0.01]
    csv = tmp_path / "input.csv"
    with open(csv, "w") as f:
        f.write('"time","delta_fl","delta_fr","tau_rl"\n')
        for row in signals:
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    out = tmp_path / "ours.csv"
    stop, h = 2.5, 1e-3  # beyond the last row: held
    subprocess.run([str(cosim), "run", str(plant_fmu), "--input", str(csv), "--set", "v_x_start=0.35",
                    "--stop-time", str(stop), "--step", str(h), "--output", str(out)], check=True)
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    ref = simulate_fmu(str(plant_fmu), fmi_type="CoSimulation", stop_time=stop, output_interval=h,
                       start_values={"v_x_start": 0.35}, input=signals)
    assert len(ours) == len(ref) == 2501
    assert np.array_equal(ours["time"], ref["time"])
    names = [n for n in ref.dtype.names if n != "time"]
    assert len(names) >= 20
    # the same FMU given the same input values before the same steps: the same bits
    worst = max(float(np.max(np.abs(ours[n] - ref[n]))) for n in names)
    assert worst == 0.0, f"largest difference {worst}"
    assert abs(ours["psi"][-1]) > 1e-3  # the steering input turned the car
    # an unknown column is named, with the closest names
    bad = tmp_path / "bad.csv"
    bad.write_text('"time","delta_fll"\n0,0\n1,0.1\n')
    r = subprocess.run([str(cosim), "run", str(plant_fmu), "--input", str(bad)], capture_output=True, text=True)
    assert r.returncode != 0 and 'no variable "delta_fll"; did you mean "delta_fl"' in r.stderr, r.stderr
    # an output cannot be driven
    bad.write_text('"time","x"\n0,0\n1,0.1\n')
    r = subprocess.run([str(cosim), "run", str(plant_fmu), "--input", str(bad)], capture_output=True, text=True)
    assert r.returncode != 0 and "cannot be driven over time" in r.stderr, r.stderr


def write_input_csv(path, signals):
    with open(path, "w") as f:
        f.write(",".join(f'"{n}"' for n in signals.dtype.names) + "\n")
        for row in signals:
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def jump_signals(t_jump):
    """Steering that jumps at t_jump (two rows at that time) and again at 1 s, constant
    between the jumps: with ramps, fmpy's CVode (not restarted at communication points)
    integrates past each point with the input held from the one before, an approximation
    of fmpy's own (1.8e-5 m in x here), not the input's."""
    t = np.array([0.0, t_jump, t_jump, 1.0, 1.0, 2.0])
    signals = np.zeros(t.size, dtype=[("time", float), ("delta_fl", float), ("delta_fr", float)])
    signals["time"] = t
    signals["delta_fl"] = [0.0, 0.0, 0.2, 0.2, -0.1, -0.1]
    signals["delta_fr"] = [0.0, 0.0, 0.15, 0.15, -0.1, -0.1]
    return signals


def assert_same_bits(ours, ref):
    """Every column of fmpy's `ref` but time equals ours, bit for bit."""
    names = [n for n in ref.dtype.names if n != "time"]
    worst = max(float(np.max(np.abs(ours[n] - ref[n]))) for n in names)
    assert worst == 0.0, f"Co-Simulation: largest difference {worst}"


def model_exchange_against_cvode(cosim, plant_fmu, csv, signals, stop, tmp_path, rows):
    """The plant (v_x_start 0.35) with the input file `csv` (`signals`) to `stop` in Model
    Exchange: our dopri5 against fmpy's CVode, both to rtol 1e-10, inputs held over each
    10 ms step in both (fmpy applies them at communication points); `rows` rows each, every
    state within 1e-7 of its scale. Each integrator's global error is near 1e-10 of the
    state's scale, so 1e-7 of the scale is a thousandfold margin that no libm or BLAS
    difference approaches, while a jump applied one step (10 ms) late moves psi by 4e-3 rad
    and x by 3e-4 m. Gives (ours, fmpy's)."""
    h = 1e-2
    out = tmp_path / "me.csv"
    subprocess.run([str(cosim), "run", str(plant_fmu), "--interface", "me", "--solver", "dopri5", "--rtol", "1e-10",
                    "--input", str(csv), "--set", "v_x_start=0.35", "--stop-time", str(stop), "--step", str(h),
                    "--output", str(out)], check=True)
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    ref = simulate_fmu(str(plant_fmu), fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-10,
                       stop_time=stop, output_interval=h, start_values={"v_x_start": 0.35}, input=signals,
                       record_events=False)
    assert len(ours) == len(ref) == rows
    for name in ["x", "y", "psi", "v_x", "v_y", "yaw_rate"]:
        scale = max(1.0, float(np.max(np.abs(ref[name]))))
        diff = float(np.max(np.abs(ours[name] - ref[name])))
        assert diff <= 1e-7 * scale, f"Model Exchange {name}: {diff}"
    return ours, ref


def test_input_jumps_equal_fmpy_in_both_interfaces(cosim, plant_fmu, tmp_path):
    # jumps on communication points: fmpy applies the later row from the jump on, in
    # Co-Simulation before the step from it, in Model Exchange as a time event there
    signals = jump_signals(0.5)
    csv = tmp_path / "jump.csv"
    write_input_csv(csv, signals)
    start = {"v_x_start": 0.35}
    stop = 2.0
    out = tmp_path / "cs.csv"
    subprocess.run([str(cosim), "run", str(plant_fmu), "--input", str(csv), "--set", "v_x_start=0.35",
                    "--stop-time", str(stop), "--step", "1e-3", "--output", str(out)], check=True)
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    ref = simulate_fmu(str(plant_fmu), fmi_type="CoSimulation", stop_time=stop, output_interval=1e-3,
                       start_values=start, input=signals)
    assert len(ours) == len(ref) == 2001 and np.array_equal(ours["time"], ref["time"])
    # the same FMU given the same input values before the same steps: the same bits
    assert_same_bits(ours, ref)
    # Model Exchange: CVode restarted at each jump (fmpy's time event) against our dopri5
    ours, ref = model_exchange_against_cvode(cosim, plant_fmu, csv, signals, stop, tmp_path, 201)
    assert np.allclose(ours["time"], ref["time"], rtol=0, atol=1e-12)
    assert abs(ours["psi"][-1]) > 1e-3


def test_an_input_jump_between_communication_points_splits_the_step_as_fmpy(cosim, plant_fmu, tmp_path):
    # fmpy makes a jump between two points a communication point of its own (recording a
    # row there); cosim splits the step there too and records the grid only
    signals = jump_signals(0.5004)
    csv = tmp_path / "offgrid.csv"
    write_input_csv(csv, signals)
    start = {"v_x_start": 0.35}
    ref = simulate_fmu(str(plant_fmu), fmi_type="CoSimulation", stop_time=1.5, output_interval=1e-3,
                       start_values=start, input=signals)
    extra = np.isclose(ref["time"], 0.5004, rtol=0, atol=1e-12)
    assert extra.sum() == 1 and len(ref) == 1502
    ref = ref[~extra]
    out = tmp_path / "cs.csv"
    subprocess.run([str(cosim), "run", str(plant_fmu), "--input", str(csv), "--set", "v_x_start=0.35",
                    "--stop-time", "1.5", "--step", "1e-3", "--output", str(out)], check=True)
    ours = np.genfromtxt(out, delimiter=",", names=True, deletechars="")
    assert len(ours) == 1501 and np.array_equal(ours["time"], ref["time"])
    # the same steps (0.5 -> 0.5004 -> 0.501 s) with the same inputs: the same bits
    assert_same_bits(ours, ref)
    # Model Exchange: fmpy's time event at the jump, our integrator stopped there
    model_exchange_against_cvode(cosim, plant_fmu, csv, signals, 1.5, tmp_path, 151)


def read_mat_v4(path):
    """The matrices of a MAT v4 file, by the format's definition (MathWorks, "MAT-File
    Format", Level 4): a header of five int32 (type, rows, columns, imaginary, name
    length), the name with its NUL, the values column by column."""
    data = path.read_bytes()
    at, out = 0, {}
    while at < len(data):
        ty, rows, cols, imag, namelen = np.frombuffer(data, "<i4", 5, at)
        assert imag == 0 and ty // 1000 == 0  # little-endian, real
        name = data[at + 20:at + 20 + namelen - 1].decode()
        dtype = {0: "<f8", 2: "<i4", 5: "u1"}[(ty // 10) % 10]
        at += 20 + namelen
        values = np.frombuffer(data, dtype, rows * cols, at).reshape((cols, rows)).T  # column-major
        at += values.nbytes
        out[name] = (ty % 10, values)
    return out


def test_mat_output_is_dymolas_layout(cosim, plant_fmu, tmp_path):
    mat, csv = tmp_path / "r.mat", tmp_path / "r.csv"
    common = [str(cosim), "run", str(plant_fmu), "--set", "v_x_start=0.35", "--set", "delta_fl=0.2",
              "--stop-time", "0.5", "--step", "1e-3", "--output-interval", "0.01"]
    subprocess.run(common + ["--output", str(mat)], check=True)
    subprocess.run(common + ["--output", str(csv)], check=True)
    ref = np.genfromtxt(csv, delimiter=",", names=True, deletechars="")
    m = read_mat_v4(mat)
    assert list(m) == ["Aclass", "name", "description", "dataInfo", "data_1", "data_2"]
    text = lambda k: ["".join(map(chr, col)).rstrip() for col in m[k][1].T]  # one string per column
    assert m["Aclass"][0] == 1 and ["".join(map(chr, r)).rstrip() for r in m["Aclass"][1]] == \
        ["Atrajectory", "1.1", "", "binTrans"]
    names = text("name")
    assert names == list(ref.dtype.names)  # "time" first, then the outputs as in the CSV
    descriptions = text("description")
    assert descriptions[names.index("x")] == "global position X of the CG"
    info = m["dataInfo"][1]
    assert info.shape == (4, len(names)) and list(info[:, 0]) == [0, 1, 0, -1]
    assert all(list(info[:, j]) == [2, j + 1, 0, -1] for j in range(1, len(names)))
    assert list(m["data_1"][1][:, 0]) == [0.0] and m["data_1"][1].shape == (1, 2)
    data = m["data_2"][1]  # one row per variable, one column per output point
    assert data.shape == (len(names), len(ref))
    for j, n in enumerate(names):
        assert np.array_equal(data[j], ref[n]), n  # the CSV's shortest round-trip text: the same doubles
