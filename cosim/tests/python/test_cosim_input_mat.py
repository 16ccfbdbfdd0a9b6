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
