"""nigel_cosim, the wheel as a user installs it, against fmpy, the `cosim` and `campaign`
command lines, and itself in threads and under Ctrl-C.

Run by scripts/test-python-package.sh in a fresh venv holding only the wheel and the
test's own dependencies (fmpy, pandas, pytest)."""

import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
from pathlib import Path

import fmpy
import numpy as np
import pandas
import pytest

import nigel_cosim

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
if not TARGET.is_absolute():
    TARGET = REPO / TARGET
FMU = TARGET / "fmu"
SSP = TARGET / "ssp" / "nigel_closed_loop.ssp"
BIN = Path(os.environ.get("NIGEL_BIN_DIR", TARGET / "release"))
COSIM = BIN / "cosim"
CAMPAIGN = BIN / "campaign"


def read_cli_csv(path):
    """The CLI's CSV (fmpy's format: quoted names, shortest round-trip floats)."""
    return np.genfromtxt(path, delimiter=",", names=True, deletechars="", dtype=np.float64)


@pytest.mark.parametrize("name", ["nigel_plant", "nigel_controller", "nigel_maneuver"])
def test_simulate_fmu_is_fmpy_bit_for_bit_in_co_simulation(name):
    # fmpy's defaults (stop time, output interval from the DefaultExperiment) and ours agree
    ours = nigel_cosim.simulate_fmu(FMU / f"{name}.fmu")
    theirs = fmpy.simulate_fmu(str(FMU / f"{name}.fmu"))
    assert ours.dtype.names == theirs.dtype.names
    assert len(ours) == len(theirs) > 100
    for field in theirs.dtype.names:
        assert ours.dtype[field] == theirs.dtype[field], field
        assert np.array_equal(ours[field], theirs[field]), field


def test_simulate_fmu_start_values_output_and_step_as_fmpy():
    kwargs = dict(stop_time=3.0, output_interval=2e-3, start_values={"m": 2.6, "v_x_start": 1.5}, output=["x", "v_x", "yaw_rate"])
    ours = nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", **kwargs)
    theirs = fmpy.simulate_fmu(str(FMU / "nigel_plant.fmu"), **kwargs)
    assert ours.dtype.names == ("time", "x", "v_x", "yaw_rate") == theirs.dtype.names
    assert len(ours) == 1501
    for field in theirs.dtype.names:
        assert np.array_equal(ours[field], theirs[field]), field
    # and the start value changed the run (not a run at the defaults)
    default = nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", stop_time=3.0, output_interval=2e-3, output=["v_x"])
    assert not np.array_equal(default["v_x"], ours["v_x"])


def test_simulate_fmu_input_as_fmpy():
    # fmpy's input: a structured array, time first; a step of the steering input at 1 s
    signals = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 0.2), (3.0, 0.2)], dtype=[("time", float), ("delta_fl", float)])
    kwargs = dict(stop_time=3.0, input=signals, output=["yaw_rate"], start_values={"v_x_start": 1.5})
    ours = nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", **kwargs)
    theirs = fmpy.simulate_fmu(str(FMU / "nigel_plant.fmu"), **kwargs)
    assert np.max(np.abs(theirs["yaw_rate"])) > 0.1  # the input acted
    assert np.array_equal(ours["yaw_rate"], theirs["yaw_rate"])


def test_simulate_ssp_is_the_command_line_bit_for_bit(tmp_path):
    csv = tmp_path / "cli.csv"
    subprocess.run(
        [COSIM, "run", SSP, "--stop-time", "5", "--step", "1e-3", "--algorithm", "ordered", "--output", csv],
        check=True,
        capture_output=True,
    )
    cli = read_cli_csv(csv)
    ours = nigel_cosim.simulate_ssp(SSP, stop_time=5.0, step_size=1e-3, algorithm="ordered")
    assert ours.dtype.names == cli.dtype.names
    assert "plant.x" in ours.dtype.names and len(ours) == 5001
    for field in cli.dtype.names:
        assert np.array_equal(ours[field].astype(np.float64), cli[field]), field


def _closed_loop_with_mapping_connector_and_start(tmp_path):
    """The closed loop with a system parameter connector `mass` feeding plant.m, bound
    through a parameter mapping from a value in grams (`vehicle_mass_g` 2700 g, the set's
    Units: g = 0.001 kg), and a DefaultExperiment from 1 s to 3 s."""
    import re
    import zipfile

    out = tmp_path / "mapped_closed_loop.ssp"
    with zipfile.ZipFile(SSP) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == "SystemStructure.ssd":
                ssd = data.decode()
                ssd = re.sub(
                    r'(<ssd:System name="[^"]*">)',
                    r"""\1
    <ssd:Connectors><ssd:Connector name="mass" kind="parameter"><ssc:Real/></ssd:Connector></ssd:Connectors>
    <ssd:ParameterBindings><ssd:ParameterBinding source="resources/mass.ssv">
      <ssd:ParameterMapping><ssm:ParameterMapping xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" version="1.0">
        <ssm:MappingEntry source="vehicle_mass_g" target="mass"/>
        <ssm:MappingEntry source="vehicle_mass_g" target="trailer.m"/>
      </ssm:ParameterMapping></ssd:ParameterMapping>
    </ssd:ParameterBinding></ssd:ParameterBindings>""",
                    ssd,
                    count=1,
                )
                ssd = ssd.replace(
                    "</ssd:Connections>",
                    '<ssd:Connection startElement="plant" startConnector="m" endElement="" endConnector="mass"/></ssd:Connections>',
                )
                ssd = re.sub(r"<ssd:DefaultExperiment[^>]*/>", '<ssd:DefaultExperiment startTime="1" stopTime="3"/>', ssd)
                data = ssd.encode()
            dst.writestr(item, data)
        dst.writestr(
            "resources/mass.ssv",
            """<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0" name="m">
  <ssv:Parameters><ssv:Parameter name="vehicle_mass_g"><ssv:Real value="2700" unit="g"/></ssv:Parameter></ssv:Parameters>
  <ssv:Units><ssc:Unit name="g"><ssc:BaseUnit kg="1" factor="0.001"/></ssc:Unit></ssv:Units>
</ssv:ParameterSet>""",
        )
    return out


def test_simulate_ssp_applies_mappings_connector_values_and_start_as_the_command_line(tmp_path):
    ssp = _closed_loop_with_mapping_connector_and_start(tmp_path)
    csv = tmp_path / "cli.csv"
    done = subprocess.run(
        [COSIM, "run", ssp, "--step", "1e-3", "--output", csv, "--record", "plant.y", "--record", "plant.v_x"],
        check=True,
        capture_output=True,
    )
    cli = read_cli_csv(csv)
    # trailer.m names no variable: ignored as SSP 1.0 says, and warned
    with pytest.warns(UserWarning, match="trailer.m"):
        ours = nigel_cosim.simulate_ssp(ssp, step_size=1e-3, output=["plant.y", "plant.v_x"])
    # from the SSD's 1 s to its 3 s, every value the same bit for bit
    assert ours["time"][0] == 1.0 and ours["time"][-1] == 3.0 and len(ours) == 2001
    for field in cli.dtype.names:
        assert np.array_equal(ours[field].astype(np.float64), cli[field]), field
    # plant.m = 2700 g = 2.7 kg through the mapping and the connector: the run equals one
    # with plant.m set to 2.7 directly, and differs from one at the SSP's own mass
    with nigel_cosim.System(ssp) as system:
        assert len(system.notes) == 1 and "trailer.m" in system.notes[0] and "ignored" in system.notes[0], system.notes
        direct = system.simulate(step_size=1e-3, start_values={"plant.m": 2.7}, output=["plant.y", "plant.v_x"])
    assert np.array_equal(direct["plant.y"], ours["plant.y"])
    # the closed loop as built (plant.m its FMU's 2.68 kg), over the same span
    own = nigel_cosim.simulate_ssp(SSP, start_time=1.0, stop_time=3.0, step_size=1e-3, output=["plant.y"])
    assert not np.array_equal(own["plant.y"], ours["plant.y"])
    info = subprocess.run([COSIM, "info", ssp], check=True, capture_output=True, text=True).stdout
    assert "plant.m = 2.7 (from 2700 g)" in info, info
    # nigel_cosim.info is the same function as `cosim info` (nigel_cosim::info::describe)
    assert nigel_cosim.info(ssp) == info
    assert b"cosim: note: " in done.stderr and b"trailer.m" in done.stderr, done.stderr


@pytest.mark.parametrize("name", ["nigel_plant", "nigel_controller"])
def test_info_is_what_cosim_info_prints(name):
    """`nigel_cosim.info` and `cosim info` share one library function: the same text, a
    line per variable; a file that is no FMU raises LoadError naming it."""
    fmu = FMU / f"{name}.fmu"
    text = nigel_cosim.info(fmu)
    assert text == subprocess.run([COSIM, "info", fmu], check=True, capture_output=True, text=True).stdout
    with nigel_cosim.System(fmu) as system:
        names = [v["name"] for v in system.variables()]
    assert text.startswith("model "), text[:80]
    # one line per variable, in the order of the modelDescription, each starting with its name
    lines = text.splitlines()
    rows = lines[lines.index(next(line for line in lines if line.startswith("name "))) + 1:]
    assert [row.split()[0] for row in rows[:len(names)]] == names
    with pytest.raises(nigel_cosim.LoadError, match="missing.fmu"):
        nigel_cosim.info(FMU / "missing.fmu")


def test_a_system_runs_many_times_from_one_load_as_separate_runs():
    masses = [2.4, 2.7, 3.0]
    with nigel_cosim.System(SSP) as system:
        reused = [
            system.simulate(stop_time=2.0, step_size=1e-3, start_values={"plant.m": m}, output=["plant.y"])["plant.y"]
            for m in masses
        ]
    assert system.closed
    with pytest.raises(nigel_cosim.Error, match="closed"):
        system.simulate(stop_time=1.0)
    for m, y in zip(masses, reused):
        fresh = nigel_cosim.simulate_ssp(SSP, stop_time=2.0, step_size=1e-3, start_values={"plant.m": m}, output=["plant.y"])
        assert np.array_equal(fresh["plant.y"], y)
    assert not np.array_equal(reused[0], reused[2])


def test_errors_carry_the_masters_messages():
    with pytest.raises(nigel_cosim.VariableError, match='did you mean "m"'):
        nigel_cosim.simulate_ssp(SSP, stop_time=0.1, start_values={"plant.mm": 3.0})
    with pytest.raises(nigel_cosim.LoadError, match="no_such.fmu"):
        nigel_cosim.simulate_fmu("no_such.fmu")
    with pytest.raises(nigel_cosim.SimulationError, match="m = -1 refused: below its minimum"):
        nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", stop_time=0.1, start_values={"m": -1.0})
    with pytest.raises(nigel_cosim.ExperimentError):
        nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", stop_time=0.1, solver="Euler", fmi_type="ModelExchange")
    assert issubclass(nigel_cosim.LoadError, nigel_cosim.Error)
    assert issubclass(nigel_cosim.Error, Exception)


def test_a_run_that_can_record_none_of_the_outputs_is_refused(tmp_path):
    # cosim's FMI 3.0 counter (cosim/tests/cfmu/fmi3_counter.c) described with one output, an
    # array of 200,000 elements that the master leaves out of its view: a result of the time
    # column alone is not what simulate_fmu was asked for (every output), so it raises, as
    # `cosim run` exits 1 (cosim/tests/fmi3.rs a_run_that_can_record_none_of_the_outputs_fails)
    fmu = _fmi3_c_fmu(tmp_path, "fmi3_counter", "fmi3_counter_no_output.xml", "no_output.fmu")
    with pytest.raises(nigel_cosim.ExperimentError, match=r"no output of the system can be recorded: model\.big .*output"):
        nigel_cosim.simulate_fmu(fmu, stop_time=0.1, step_size=0.05)


def test_a_single_fmus_names_are_those_of_cosim_run_and_its_fmi_type_the_xml_names():
    # as `cosim run --set`: a single FMU's variable bare or as `model.<name>`
    plant = FMU / "nigel_plant.fmu"
    run = lambda values: nigel_cosim.simulate_fmu(plant, stop_time=0.1, start_values=values, output=["x"])["x"]
    bare, qualified, still = run({"v_x_start": 1.0}), run({"model.v_x_start": 1.0}), run({})
    assert np.array_equal(bare, qualified)
    # at 1 m/s without torque or steering the plant rolls straight on: x = 1 m/s * 0.1 s (to
    # the integrator's rounding, 1e-9); at rest it stays at 0
    assert bare[-1] == pytest.approx(0.1, abs=1e-9) and not still.any()
    with pytest.raises(ValueError, match="fmi_type must be 'CoSimulation', 'ModelExchange' or 'ScheduledExecution', not \"cs\""):
        nigel_cosim.System(plant, fmi_type="cs")


def test_runs_release_the_gil_two_threads_overlap():
    # each thread notes when its run started and ended; with the GIL held for a whole run
    # the second could not start before the first ended
    spans = {}

    def run(key):
        t0 = time.perf_counter()
        nigel_cosim.simulate_ssp(SSP, stop_time=10.0, step_size=1e-3, output=["plant.x"])
        spans[key] = (t0, time.perf_counter())

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    (a0, a1), (b0, b1) = spans[0], spans[1]
    assert a0 < b1 and b0 < a1, spans


def sigint_latency(script, after, timeout, env=None):
    """Runs the Python `script` (prints "started", then on KeyboardInterrupt "interrupted"
    and its time.monotonic(), exit code 7), sends it SIGINT `after` seconds after it
    started, and gives the seconds from the signal to the interrupt."""
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=env)
    assert p.stdout.readline().strip() == "started"
    time.sleep(after)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=timeout)
    assert p.returncode == 7, out
    return float(out.split()[1]) - sent


def test_ctrl_c_raises_keyboard_interrupt_and_leaves_no_folder(tmp_path):
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    script = textwrap.dedent(
        f"""
        import sys, time, nigel_cosim
        print("started", flush=True)
        try:
            with nigel_cosim.System({str(FMU / "nigel_plant.fmu")!r}) as system:
                system.simulate(stop_time=1e6, step_size=1e-3, output=["x"])
        except KeyboardInterrupt:
            print("interrupted", time.monotonic(), flush=True)
            sys.exit(7)
        """
    )
    # inside the run after 1 s: loading the SSP takes well under this
    latency = sigint_latency(script, 1.0, 60, env=dict(os.environ, TMPDIR=str(scratch)))
    # the run stops at its next step and waits at most 100 ms between signal checks; 5 s
    # only bounds a loaded machine, the latency is printed for the record
    print(f"KeyboardInterrupt {latency:.3f} s after SIGINT")
    assert latency < 5.0
    assert list(scratch.iterdir()) == []


def test_run_campaign_returns_the_command_lines_results(tmp_path):
    spec = {
        "system": str(SSP),
        "stop_time": 2.0,
        "step": 1e-3,
        "algorithm": "ordered",
        "seed": 3,
        "samples": 2,
        "grid": {"maneuver.maneuver": [2, 3]},
        "random": {"plant.m": {"uniform": [2.4, 3.0]}},
        "metrics": {"y_final": "final(plant.y)", "max_delta": "max_abs(controller.delta_fl)"},
    }
    toml = tmp_path / "spec.toml"
    toml.write_text(
        textwrap.dedent(
            f"""
            system = "{SSP}"
            stop_time = 2.0
            step = 1e-3
            algorithm = "ordered"
            seed = 3
            samples = 2
            [grid]
            "maneuver.maneuver" = [2, 3]
            [random]
            "plant.m" = {{ uniform = [2.4, 3.0] }}
            [metrics]
            y_final = "final(plant.y)"
            max_delta = "max_abs(controller.delta_fl)"
            """
        )
    )
    subprocess.run([CAMPAIGN, "run", toml, "--out", tmp_path / "cli", "--in-process"], check=True, capture_output=True)
    cli = pandas.read_csv(tmp_path / "cli" / "results.csv")
    ours = nigel_cosim.run_campaign(spec, out=tmp_path / "py", threads=2)
    assert list(ours.columns) == list(cli.columns)
    assert len(ours) == 4
    pandas.testing.assert_frame_equal(ours.drop(columns=[c for c in ours.columns if "time" in c.lower() and "wall" in c.lower()]),
                                      cli.drop(columns=[c for c in cli.columns if "time" in c.lower() and "wall" in c.lower()]))


def test_write_csv_is_fmpys(tmp_path):
    result = nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", stop_time=0.5, output=["x", "v_x"])
    ours, theirs = tmp_path / "ours.csv", tmp_path / "theirs.csv"
    nigel_cosim.write_csv(ours, result)
    fmpy.util.write_csv(str(theirs), result)
    assert ours.read_text() == theirs.read_text()


def test_the_example_prints_tables_epsilon_and_writes_its_figure(tmp_path):
    # the same closed loop as examples/closed_loop_fmpy.py prints (fmpy's loop, by hand):
    # the same FMUs, steps and order, so the same numbers to the rounding of the RMSE sums
    # and as table3 computes it (the FMUs in the master's own loop): checked at the printed
    # 10 digits, far coarser than the rounding of 30,000 squared errors summed in another order
    subprocess.run([BIN / "table3", "--quiet", "--maneuver", "lane_change", "--controller", "robust",
                    "--json", tmp_path / "t.json"], check=True, capture_output=True)
    import json
    want = json.loads((tmp_path / "t.json").read_text())["results"]["sim"]["lane_change"]["robust"]["eps"]
    png = tmp_path / "python_cosim.png"
    r = subprocess.run([sys.executable, str(REPO / "examples" / "python_cosim.py"), str(png)],
                       capture_output=True, text=True, check=True, cwd=REPO)
    assert f"epsilon {want:.9e} (RMSE" in r.stdout, (want, r.stdout)
    masses = [float(line.split()[-1]) for line in r.stdout.splitlines() if line.startswith("mass ")]
    assert len(masses) == 3 and masses[0] < masses[1] < masses[2]  # heavier, larger tracking error
    assert "campaign: 8 runs" in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def stair_fmu(tmp_path_factory):
    """A small FMU of our own (cosim/tests/cfmu/stair.c, after the Reference FMU Stair): a
    counter 1 .. 10 stepped every 1 s that ends the run at t = 9 s."""
    import zipfile

    cfmu = REPO / "cosim" / "tests" / "cfmu"
    d = tmp_path_factory.mktemp("stair")
    so = d / "stair.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", str(cfmu / "stair.c"), "-o", str(so)], check=True)
    fmu = d / "stair.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.write(cfmu / "stair.xml", "modelDescription.xml")
        z.write(so, "binaries/linux64/stair.so")
    return fmu


@pytest.mark.parametrize("kwargs", [{}, {"output_interval": 0.1}, {"stop_time": 5.0}])
def test_simulate_fmu_is_fmpy_on_a_small_fmu_that_ends_its_run(stair_fmu, kwargs):
    ours = nigel_cosim.simulate_fmu(stair_fmu, **kwargs)
    theirs = fmpy.simulate_fmu(str(stair_fmu), **kwargs)
    assert ours.dtype == theirs.dtype
    # fmpy computes the points as start + n * h, the master as t0 + n h: the same numbers
    assert np.array_equal(ours["time"], theirs["time"])
    assert np.array_equal(ours["counter"], theirs["counter"])
    # the FMU ended the default run at 9 s (the row at its last successful time), else it
    # ran to the stop time
    assert ours["time"][-1] == kwargs.get("stop_time", 9.0)


def test_a_run_stepped_from_python_is_the_run_with_an_input_table():
    # stepping to 1 s, setting the steering input, stepping on = the input signal's jump at 1 s
    with nigel_cosim.System(FMU / "nigel_plant.fmu") as system:
        t0 = system.initialize(stop_time=3.0, step_size=1e-3, start_values={"v_x_start": 1.5}, output=["yaw_rate", "x"])
        assert t0 == 0.0
        assert system.step() == 1e-3
        assert system.step_until(1.0) == 1.0
        x_at_1 = system.get("x")
        system.set("delta_fl", 0.2)
        with pytest.raises(nigel_cosim.VariableError, match="cannot be set during a run"):
            system.set("m", 3.0)  # a fixed parameter
        assert system.step_until(5.0) == 3.0  # the stop time at most
        stepped = system.results()
        summary = system.terminate()
    assert summary["steps"] == 3000
    signals = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 0.2), (3.0, 0.2)], dtype=[("time", float), ("delta_fl", float)])
    whole = nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", stop_time=3.0, output_interval=1e-3, input=signals,
                                     start_values={"v_x_start": 1.5}, output=["yaw_rate", "x"])
    assert len(stepped) == len(whole) == 3001
    for field in whole.dtype.names:
        assert np.array_equal(stepped[field], whole[field]), field
    assert x_at_1 == whole["x"][1000]
    assert np.max(np.abs(whole["yaw_rate"])) > 0.1


def test_ctrl_c_inside_step_until(tmp_path):
    script = textwrap.dedent(
        f"""
        import sys, time, nigel_cosim
        system = nigel_cosim.System({str(FMU / "nigel_plant.fmu")!r})
        system.initialize(stop_time=1e6, step_size=1e-3, output=["x"])
        print("started", flush=True)
        try:
            system.step_until(1e6)
        except KeyboardInterrupt:
            print("interrupted at", system.time, flush=True)
            system.close()
            sys.exit(7)
        """
    )
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                         env=dict(os.environ, TMPDIR=str(scratch)))
    assert p.stdout.readline().strip() == "started"
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    assert p.returncode == 7, out
    assert 0 < float(out.split()[-1]) < 1e6
    assert list(scratch.iterdir()) == []


def test_simulate_fmu_in_model_exchange_agrees_with_fmpys_cvode():
    # the same output points (fmpy's defaults: 4 ms over 3 s); CVode and the master's BDF
    # method (solver "CVode" here) both hold the local error below rtol 1e-10 relative, so over 3 s their global
    # errors stay near 1e-9 m / rad / m/s (measured 5e-10); 1e-7 leaves two orders for any
    # machine's rounding
    kwargs = dict(fmi_type="ModelExchange", stop_time=3.0, relative_tolerance=1e-10,
                  start_values={"v_x_start": 1.5, "yaw_rate_start": 0.3}, output=["x", "y", "psi", "v_x"])
    ours = nigel_cosim.simulate_fmu(FMU / "nigel_plant.fmu", **kwargs)
    # fmpy's record_events adds rows before and after events: the master records only the
    # output points
    theirs = fmpy.simulate_fmu(str(FMU / "nigel_plant.fmu"), record_events=False, **kwargs)
    assert len(ours) == len(theirs) == 751
    assert np.array_equal(ours["time"], theirs["time"])
    for field in ("x", "y", "psi", "v_x"):
        assert np.max(np.abs(ours[field] - theirs[field])) < 1e-7, field
    assert abs(ours["psi"][-1]) > 0.03  # the vehicle turned (yaw_rate_start): a real trajectory was compared


def test_ctrl_c_during_a_campaign_starts_no_further_run(tmp_path):
    script = textwrap.dedent(
        f"""
        import sys, time, nigel_cosim
        spec = {{"system": {str(SSP)!r}, "stop_time": 2.0, "step": 1e-3, "seed": 1, "samples": 2000,
                 "random": {{"plant.m": {{"uniform": [2.4, 3.0]}}}}, "metrics": {{"y": "final(plant.y)"}}}}
        print("started", flush=True)
        try:
            nigel_cosim.run_campaign(spec, out={str(tmp_path / "out")!r}, threads=2)
        except KeyboardInterrupt:
            print("interrupted", time.monotonic(), flush=True)
            sys.exit(7)
        """
    )
    latency = sigint_latency(script, 1.5, 120)
    print(f"KeyboardInterrupt {latency:.3f} s after SIGINT (the runs in progress finish: 2 s each at most)")
    assert latency < 10.0
    # the rows of the runs that finished are written, far fewer than the 2000 asked for
    rows = pandas.read_csv(tmp_path / "out" / "results.csv")
    assert 0 < len(rows) < 2000


def test_compare_gives_the_report_of_cosim_compare(tmp_path):
    # the committed baseline of the closed loop against itself with one value off by 1 %
    # and one signal left out: as `cosim compare` judges the same files
    baseline = REPO / "cosim" / "tests" / "data" / "closed_loop_30s.csv"
    data = np.genfromtxt(baseline, delimiter=",", names=True, deletechars="", dtype=np.float64)
    b = data["plant.y"][300]
    data["plant.y"][300] *= 1.01
    result = data[["time", "plant.x", "plant.y"]]
    report = nigel_cosim.compare(result, baseline, plot=tmp_path / "plots")
    assert not report["passed"]
    assert [(s["name"], s["passed"]) for s in report["signals"]] == [
        ("plant.x", True),
        ("plant.y", False),
        ("plant.psi", False),
        ("plant.speed", False),
        ("plant.yaw_rate", False),
    ]
    y = report["signals"][1]
    # the default tolerances: the tube at t = 15 s is b +- (1e-6 + 1e-3 |b|)
    w = 1e-6 + 1e-3 * abs(b)
    assert (y["points"], y["violations"]) == (601, 1)
    assert y["worst"]["time"] == 15.0 and y["worst"]["value"] == data["plant.y"][300]
    assert (y["worst"]["lower"], y["worst"]["upper"]) == (b - w, b + w)
    assert report["signals"][2]["problem"] == "missing in the result"
    assert report["figures"] == [tmp_path / "plots" / "plant.y.png"]
    # the same files through the command line: the same lines
    path = tmp_path / "result.csv"
    nigel_cosim.write_csv(path, result)
    p = subprocess.run([COSIM, "compare", path, baseline], capture_output=True, text=True)
    assert p.returncode == 3
    assert p.stdout.splitlines()[1:] == report["lines"]
    assert nigel_cosim.compare(path, baseline, signals=["plant.x"])["passed"]


@pytest.fixture(scope="module")
def counter3_fmu(tmp_path_factory):
    """The FMI 3.0 test FMU of our own (cosim/tests/cfmu/fmi3_counter.c, built against the
    standard's headers in fmpy's package): i64out = i64in ^ 1 and u64out = u64in ^ 1 (the
    lowest bit flipped, so that a rounding shows), the String parameter label = "abc"."""
    return _fmi3_c_fmu(tmp_path_factory.mktemp("counter3"), "fmi3_counter", "fmi3_counter.xml", "fmi3_counter.fmu")


def _fmi3_c_fmu(folder, id, description, name):
    """`folder / name`: cosim's FMI 3.0 C test FMU cosim/tests/cfmu/`id`.c with fmi3_rest.c
    (every other function answering fmi3Error, as cosim/tests/common/fmi3_c.rs builds it)
    compiled against the standard's headers in fmpy's package, described by
    cosim/tests/cfmu/`description`."""
    import zipfile

    cfmu = REPO / "cosim" / "tests" / "cfmu"
    headers = Path(fmpy.__file__).parent / "c-code"
    so = folder / f"{id}.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-Wno-unused-parameter", "-I", str(headers),
                    str(cfmu / f"{id}.c"), str(cfmu / "fmi3_rest.c"), "-o", str(so)], check=True)
    fmu = folder / name
    with zipfile.ZipFile(fmu, "w") as z:
        z.write(cfmu / description, "modelDescription.xml")
        z.write(so, f"binaries/x86_64-linux/{id}.so")
    return fmu


def test_sixty_four_bit_integers_are_exact_and_strings_text_as_fmpy(counter3_fmu):
    # i64in = 2^62 gives i64out = 2^62 + 1, u64in = 2^63 gives u64out = 2^63 + 1 (above
    # i64::MAX): neither is an f64 (the f64s there are 2^10 and 2^11 apart); fmpy 0.3.32
    # records them as int64 / uint64, exactly
    signals = np.array([(0.0, 2**62, 2**63), (1.0, 2**62, 2**63)],
                       dtype=[("time", np.double), ("i64in", np.int64), ("u64in", np.uint64)])
    kwargs = dict(stop_time=0.2, output_interval=0.1, input=signals, output=["i64out", "u64out", "label"])
    ours = nigel_cosim.simulate_fmu(counter3_fmu, **kwargs)
    theirs = fmpy.simulate_fmu(str(counter3_fmu), **kwargs)
    for name, dtype, value in [("i64out", np.int64, 2**62 + 1), ("u64out", np.uint64, 2**63 + 1)]:
        assert ours.dtype[name] == theirs.dtype[name] == dtype, name
        assert [int(v) for v in ours[name]] == [int(v) for v in theirs[name]] == [value] * 3, name
    # the String parameter as its text (fmpy leaves Strings out of its result)
    assert ours.dtype["label"] == object
    assert list(ours["label"]) == ["abc"] * 3


def test_an_ssp_of_int64_connectors_gives_exact_int64_and_uint64_fields(counter3_fmu, tmp_path):
    # cosim/tests/data/int64_chain.ssd: c1 feeds c2 its Int64 and UInt64 (ssc:Integer
    # connectors); by hand: c1.i64in = 2^62 gives 2^62 + 1 at c2.i64in and 2^62 at
    # c2.i64out; c1.u64in = 2^63 gives 2^63 + 1 at c2.u64in and 2^63 at c2.u64out
    ssd = tmp_path / "int64_chain.ssd"
    ssd.write_bytes((REPO / "cosim" / "tests" / "data" / "int64_chain.ssd").read_bytes())
    (tmp_path / "fmi3_counter.fmu").write_bytes(counter3_fmu.read_bytes())
    signals = np.array([(0.0, 2**62, 2**63), (1.0, 2**62, 2**63)],
                       dtype=[("time", np.double), ("c1.i64in", np.int64), ("c1.u64in", np.uint64)])
    output = ["c2.i64in", "c2.i64out", "c2.u64in", "c2.u64out"]
    whole = nigel_cosim.simulate_ssp(ssd, step_size=0.1, input=signals, output=output, algorithm="ordered")
    with nigel_cosim.System(ssd) as system:
        system.initialize(step_size=0.1, input=signals, output=output)
        system.step_until(0.2)
        stepped = system.results()
        system.terminate()
    for result in (whole, stepped):
        assert [result.dtype[n] for n in output] == [np.int64, np.int64, np.uint64, np.uint64]
        assert [[int(v) for v in result[n]] for n in output] == [[v] * 3 for v in (2**62 + 1, 2**62, 2**63 + 1, 2**63)]


@pytest.fixture(scope="module")
def event_mode_fmu(tmp_path_factory):
    """cosim's FMI 3.0 Co-Simulation test FMU with Event Mode and no clocks
    (cosim/tests/cfmu/fmi3_event_mode.c): x integrates a rate of 1 that becomes 2 at x = 0.55,
    inside the step without Event Mode, at the step's end in Event Mode; event_mode_used says
    how it was instantiated."""
    return _fmi3_c_fmu(tmp_path_factory.mktemp("event_mode"), "fmi3_event_mode", "fmi3_event_mode.xml",
                       "fmi3_event_mode.fmu")


def test_use_event_mode_as_fmpy_names_it(event_mode_fmu):
    # by hand (cosim/tests/event_mode.rs expected_x): without Event Mode the rate changes at
    # t = 0.55 s, x(1) = 0.55 + 2 * 0.45 = 1.45; in Event Mode at the step's end 0.6 s,
    # x(1) = 0.6 + 2 * 0.4 = 1.4; to the rounding of ten summed steps (1e-12)
    kwargs = dict(stop_time=1.0, output_interval=0.1)
    default = nigel_cosim.simulate_fmu(event_mode_fmu, **kwargs)
    on = nigel_cosim.simulate_fmu(event_mode_fmu, use_event_mode=True, **kwargs)
    assert default["x"][-1] == pytest.approx(1.45, abs=1e-12) and not default["event_mode_used"].any()
    assert on["x"][-1] == pytest.approx(1.4, abs=1e-12) and on["event_mode_used"].all()
    # the default is fmpy's default run (no Event Mode), row for row
    theirs = fmpy.simulate_fmu(str(event_mode_fmu), **kwargs)
    assert np.array_equal(default["x"], theirs["x"])
    assert np.array_equal(nigel_cosim.simulate_fmu(event_mode_fmu, use_event_mode=False, **kwargs)["x"], default["x"])
    # FMI 3.0 plant: no hasEventMode, so Event Mode cannot be asked for
    with pytest.raises(nigel_cosim.LoadError, match="declares no hasEventMode"):
        nigel_cosim.simulate_fmu(FMU / "fmi3" / "nigel_plant.fmu", stop_time=0.01, use_event_mode=True)
    # the FMI 3.0 controller declares its sample clock: no Event Mode refused, naming it
    with pytest.raises(nigel_cosim.LoadError, match='declares the clocks "sample_clock"'):
        nigel_cosim.simulate_fmu(FMU / "fmi3" / "nigel_controller.fmu", stop_time=0.01, use_event_mode=False)


def test_a_model_cosim_cannot_run_raises_load_error(tmp_path):
    # the FMI 3.0 controller without hasEventMode: its sample clock cannot run in Co-Simulation
    # without Event Mode, so cosim refuses the model at loading (LoadError), before any run
    import zipfile

    source = FMU / "fmi3" / "nigel_controller.fmu"
    fmu = tmp_path / "no_event_mode.fmu"
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(fmu, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'hasEventMode="true"', b'hasEventMode="false"')
                assert b'hasEventMode="false"' in data
            dst.writestr(item, data)
    with pytest.raises(nigel_cosim.LoadError, match='which cosim does not support') as raised:
        nigel_cosim.simulate_fmu(fmu, stop_time=0.01)
    assert "sample_clock" in str(raised.value) and not isinstance(raised.value, nigel_cosim.SimulationError)
