"""The FMI 3.0 archives (target/fmu/fmi3/*.fmu, the manifest's entries with fmi_version 3.0,
and the own-controller example's target/fmu/fmi3/own_controller.fmu) in fmpy, against the FMI
2.0 archive of the same model (the same library file, the same declaration):

- fmpy's validate_fmu finds no problem;
- read_model_description gives the same variables (names, causalities, variabilities,
  initial, units, ranges, start values, descriptions) with the FMI 3.0 types and value
  references (time at 0, declaration row r at r + 1), instantiationToken = the FMI 2.0 GUID;
- simulate_fmu Co-Simulation gives the FMI 2.0 results bit for bit (the same model code
  stepped on the same grid with the same inputs, only the C API differs);
- simulate_fmu Model Exchange with CVode gives the FMI 2.0 results to rounding (see
  ME_TOLERANCE);
- the test bench ends the run at its duration in both generations.
"""

import json
import os
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from test_fmpy import BODY_STATES, DT, STOP, V0, WHEELS, fmpy_input_signal

REPO = Path(__file__).resolve().parents[2]
TARGET = REPO / os.environ.get("CARGO_TARGET_DIR", "target")
FMU_DIR = Path(os.environ.get("NIGEL_FMU_DIR", TARGET / "fmu"))
MANIFEST = json.loads((FMU_DIR / "manifest.json").read_text())
FMI3 = [e for e in MANIFEST if e["fmi_version"] == "3.0"]
FMI2 = {e["model_identifier"]: e for e in MANIFEST if e["fmi_version"] == "2.0"}
IDS = [e["model_identifier"] for e in FMI3]

# FMI 2.0 type -> FMI 3.0 type of the same declaration (docs/fmi-notes.md)
TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String",
         "Enumeration": "Enumeration"}


@pytest.fixture(scope="session")
def own_controller():
    """The own-controller example's two archives, as its binary writes them (linux64 with this
    machine's toolchain): the example's claim is that a model crate gets its FMI 3.0 archive
    without writing anything for it."""
    subprocess.run(["cargo", "run", "--release", "--quiet", "-p", "own-controller", "--bin", "own-controller"],
                   cwd=REPO, check=True, capture_output=True)
    return FMU_DIR / "own_controller.fmu", FMU_DIR / "fmi3" / "own_controller.fmu"


def pair(model_identifier):
    """(FMI 2.0 archive, FMI 3.0 archive) of a model of the manifest."""
    e3 = next(e for e in FMI3 if e["model_identifier"] == model_identifier)
    return FMU_DIR / FMI2[model_identifier]["fmu"], FMU_DIR / e3["fmu"]


def test_manifest_lists_an_fmi3_archive_beside_each_fmi2_one():
    assert sorted(IDS) == sorted(FMI2) and "nigel_plant" in IDS
    for e in FMI3:
        assert e["fmu"] == f"fmi3/{e['model_identifier']}.fmu"
        assert (FMU_DIR / e["fmu"]).is_file(), e
        assert e["instantiation_token"] == FMI2[e["model_identifier"]]["guid"]
        assert e["interfaces"] == FMI2[e["model_identifier"]]["interfaces"]


@pytest.mark.parametrize("model_identifier", IDS)
def test_validate_fmu_reports_no_problems(model_identifier):
    _, fmi3 = pair(model_identifier)
    assert validate_fmu(str(fmi3)) == []


def fmi3_part(folder3, library):
    """What FMI 3.0 folder `folder3` carries of the FMI 2.0 archive's `library`: the library,
    or for a Mac folder the slice of its architecture in the universal library (the fat
    header of <mach-o/fat.h>: magic, count, then cputype, cpusubtype, offset, size, align,
    32-bit big-endian)."""
    cpu = {"x86_64-darwin": 0x01000007, "aarch64-darwin": 0x0100000C}.get(folder3)
    if cpu is None:
        return library
    magic, count = struct.unpack(">II", library[:8])
    assert magic == 0xCAFEBABE, f"darwin64 library is not universal: {magic:#x}"
    for k in range(count):
        cputype, _, offset, size, _ = struct.unpack(">IIIII", library[8 + 20 * k:28 + 20 * k])
        if cputype == cpu:
            return library[offset:offset + size]
    raise AssertionError(f"no slice of CPU type {cpu:#x} for {folder3}")


@pytest.mark.parametrize("model_identifier", IDS)
def test_the_archive_carries_the_fmi2_archives_libraries_in_the_fmi3_folders(model_identifier):
    import zipfile

    from fmpy import supported_platforms

    fmi2, fmi3 = pair(model_identifier)
    e3 = next(e for e in FMI3 if e["model_identifier"] == model_identifier)
    folders = {"linux64": ["x86_64-linux"], "win64": ["x86_64-windows"], "aarch64-linux": ["aarch64-linux"],
               "darwin64": ["x86_64-darwin", "aarch64-darwin"]}
    with zipfile.ZipFile(fmi2) as z2, zipfile.ZipFile(fmi3) as z3:
        listed = [p["library"] for p in e3["platforms"]]
        assert sorted(n for n in z3.namelist() if n.startswith("binaries/")) == sorted(listed)
        for p in FMI2[model_identifier]["platforms"]:
            for folder3 in folders[p["folder"]]:
                library3 = p["library"].replace(f"binaries/{p['folder']}/", f"binaries/{folder3}/")
                assert z3.read(library3) == fmi3_part(folder3, z2.read(p["library"])), library3
        doc = z3.read("documentation/index.html").decode()
        assert "The FMI 3.0 archive" in doc and "x86_64-windows" in doc
    # fmpy names FMI 3.0's x86-64 folders by its FMI 2.0 platform names
    assert set(supported_platforms(str(fmi3))) >= {"linux64"}


def test_own_controller_fmi3_archive_validates(own_controller):
    fmi2, fmi3 = own_controller
    assert validate_fmu(str(fmi3)) == []
    same_variables(fmi2, fmi3)


def start_of(v):
    """The start value as a number (or the string of a String variable): the two writers may
    spell a number differently, fmpy returns it as written."""
    if v.start is None:
        return None
    if v.type in ("Real", "Float64"):
        return float(v.start)
    if v.type in ("Integer", "Int32", "Int64", "Enumeration"):
        return int(v.start)
    if v.type == "Boolean":
        return v.start in ("true", "1", True)
    return v.start


def same_variables(fmi2, fmi3):
    md2, md3 = read_model_description(str(fmi2)), read_model_description(str(fmi3))
    assert md2.fmiVersion == "2.0" and md3.fmiVersion == "3.0"
    assert md3.instantiationToken == md2.guid
    assert md3.modelName == md2.modelName
    assert (md3.coSimulation is None) == (md2.coSimulation is None)
    assert (md3.modelExchange is None) == (md2.modelExchange is None)
    time = [v for v in md3.modelVariables if v.causality == "independent"]
    assert [(v.name, v.valueReference, v.type) for v in time] == [("time", 0, "Float64")]
    # the one variable FMI 2.0 has no form of: the controller's sample clock (a periodic input
    # clock, docs/fmus.md), after all the others
    clocks = [(v.name, v.causality, v.valueReference) for v in md3.modelVariables if v.type == "Clock"]
    expected = [("sample_clock", "input", len(md2.modelVariables) + 1)] if md2.modelName == "nigel_controller" else []
    assert clocks == expected
    rest = [v for v in md3.modelVariables if v.causality != "independent" and v.type != "Clock"]
    assert [v.name for v in rest] == [v.name for v in md2.modelVariables]
    for row, (v2, v3) in enumerate(zip(md2.modelVariables, rest)):
        assert v3.valueReference == row + 1, v3.name
        assert v3.type == TYPES[v2.type], v3.name
        for attribute in ("causality", "variability", "initial", "unit", "description"):
            assert getattr(v3, attribute) == getattr(v2, attribute), (v3.name, attribute)
        for attribute in ("min", "max", "nominal"):
            a, b = getattr(v2, attribute), getattr(v3, attribute)
            assert (a is None) == (b is None) and (a is None or float(a) == float(b)), (v3.name, attribute, a, b)
        assert start_of(v3) == start_of(v2), (v3.name, v2.start, v3.start)
    units2 = {u.name for u in md2.unitDefinitions}
    assert {u.name for u in md3.unitDefinitions} == units2
    return md2, md3


@pytest.mark.parametrize("model_identifier", IDS)
def test_model_description_has_the_fmi2_variables(model_identifier):
    fmi2, fmi3 = pair(model_identifier)
    md2, md3 = same_variables(fmi2, fmi3)
    # the outputs and the derivatives of the states are the same variables
    assert sorted(u.variable.name for u in md3.outputs) == sorted(u.variable.name for u in md2.outputs)
    assert sorted(u.variable.name for u in md3.derivatives) == sorted(u.variable.name for u in md2.derivatives)


# The runs: the inputs and parameters of the FMI 2.0 fmpy tests (test_fmpy.py's scenario for
# the plant; test_controller_maneuver.py's for the controller and the test bench).
def plant_run(path, fmi_type):
    out = list(BODY_STATES) + ["speed", "beta", "lateral_accel", "der(yaw_rate)"]
    out += [f"force_lat_{w}" for w in WHEELS] + [f"delta_applied_{w}" for w in WHEELS]
    kwargs = dict(fmi_type=fmi_type, start_time=0.0, stop_time=STOP, output_interval=DT,
                  start_values={"v_x_start": V0}, input=fmpy_input_signal(), output=out)
    if fmi_type == "CoSimulation":
        kwargs["step_size"] = DT
    else:
        kwargs.update(solver="CVode", relative_tolerance=1e-10, record_events=True)
    return simulate_fmu(str(path), **kwargs)


def controller_run(path, fmi_type):
    kwargs = dict(fmi_type=fmi_type, stop_time=0.05, output_interval=DT, start_values={"speed": 0.3},
                  output=["tau_fl", "speed_integral", "delta_fl", "delta_rl", "drive_force"])
    if fmi_type == "CoSimulation":
        kwargs["step_size"] = DT
    return simulate_fmu(str(path), **kwargs)


def maneuver_run(path, fmi_type):
    kwargs = dict(fmi_type=fmi_type, stop_time=3.0, output_interval=DT,
                  start_values={"maneuver": 3, "duration": 3.0},
                  output=["delta_ff_fl", "delta_ff_rl", "speed_ref", "x_ref", "y_ref", "psi_ref"])
    if fmi_type == "CoSimulation":
        kwargs["step_size"] = DT
    return simulate_fmu(str(path), **kwargs)


RUNS = {"nigel_plant": plant_run, "nigel_controller": controller_run, "nigel_maneuver": maneuver_run}

# Model Exchange: fmpy drives both generations with the same CVode (the same tolerances, the
# same output grid and time events) on the same right-hand side (the fmi2 and fmi3 functions
# reach the same model code), so the runs agree to rounding. 1e-12 relative to each column's
# largest magnitude is far below CVode's own error (relative tolerance 1e-10 on the plant) and
# leaves room for a different order of the few event-iteration calls between fmpy's FMI 2.0
# and FMI 3.0 loops; a bit-for-bit agreement is reported.
ME_TOLERANCE = 1e-12


def columns(result):
    return [n for n in result.dtype.names if n != "time"]


@pytest.mark.parametrize("model_identifier", sorted(RUNS))
def test_co_simulation_equals_the_fmi2_archive_bit_for_bit(model_identifier):
    fmi2, fmi3 = pair(model_identifier)
    a, b = RUNS[model_identifier](fmi2, "CoSimulation"), RUNS[model_identifier](fmi3, "CoSimulation")
    assert len(a) == len(b) and len(a) > 40
    assert columns(a) == columns(b)
    for name in a.dtype.names:
        x, y = a[name].astype(np.float64), b[name].astype(np.float64)
        assert np.array_equal(x.view(np.uint64), y.view(np.uint64)), (name, np.max(np.abs(x - y)))
    # the runs did something: an output moved
    assert any(np.ptp(a[n].astype(np.float64)) > 0 for n in columns(a))


@pytest.mark.parametrize("model_identifier", sorted(RUNS))
def test_model_exchange_with_cvode_equals_the_fmi2_archive_to_rounding(model_identifier):
    fmi2, fmi3 = pair(model_identifier)
    a, b = RUNS[model_identifier](fmi2, "ModelExchange"), RUNS[model_identifier](fmi3, "ModelExchange")
    assert np.array_equal(a["time"], b["time"]), "the same output grid and events"
    identical = True
    for name in columns(a):
        x, y = a[name].astype(np.float64), b[name].astype(np.float64)
        scale = max(np.max(np.abs(x)), 1e-300)
        worst = np.max(np.abs(x - y))
        assert worst <= ME_TOLERANCE * scale, (name, worst, scale)
        identical &= np.array_equal(x.view(np.uint64), y.view(np.uint64))
    print(f"{model_identifier}: Model Exchange FMI 3.0 {'bit for bit' if identical else 'within 1e-12'} FMI 2.0")


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_the_test_bench_ends_the_run_at_its_duration_in_both(fmi_type):
    """duration 1.5 s and fmpy asked for 3 s (without telling the FMU a stop time, which it would
    refuse past its last sample): the test bench ends the run at 1.5 s in both generations
    (Co-Simulation: FMI 2.0's fmi2DoStep past it returns fmi2Discard with fmi2Terminated and
    fmi2LastSuccessfulTime = 1.5 s, FMI 3.0's fmi3DoStep ending there sets terminateSimulation;
    Model Exchange: terminateSimulation of the event update at 1.5 s), with the same rows."""
    fmi2, fmi3 = pair("nigel_maneuver")
    kwargs = dict(fmi_type=fmi_type, stop_time=3.0, output_interval=DT, set_stop_time=False,
                  start_values={"maneuver": 2, "duration": 1.5}, output=["x_ref", "y_ref"])
    if fmi_type == "CoSimulation":
        kwargs["step_size"] = DT
    a, b = simulate_fmu(str(fmi2), **kwargs), simulate_fmu(str(fmi3), **kwargs)
    for r in (a, b):
        assert r["time"][-1] == pytest.approx(1.5, abs=1e-12) and len(r) >= 1500
    # fmpy records FMI 2.0's terminating step twice at 1.5 s (the row after the last
    # successful step, then the one it forces at fmi2LastSuccessfulTime); the first is kept
    first = lambda r: r[np.unique(r["time"], return_index=True)[1]] if fmi_type == "CoSimulation" else r
    a, b = first(a), first(b)
    assert np.array_equal(a["time"], b["time"])
    for name in ("x_ref", "y_ref"):
        assert np.array_equal(a[name].view(np.uint64), b[name].view(np.uint64)), name
