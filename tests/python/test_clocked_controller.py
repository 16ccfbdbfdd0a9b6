"""The controller, whose FMI 3.0 archive declares the sample period as the periodic input
clock `sample_clock`, driven by fmpy's
low-level FMI 3.0 calls as an independent importer: Co-Simulation with Event Mode (the clock
activated at t_k = k T with T read by fmi3GetIntervalDecimal) and Scheduled Execution (the
clock's model partition activated at t_k), and Co-Simulation without Event Mode as fmpy's
simulate_fmu instantiates it (the archive then samples by time itself: alone through
simulate_fmu, and in the closed loop with the FMI 3.0 plant and test bench), each against the
FMI 2.0 archives of the same build stepped by fmpy on the same grid with the same inputs.

The archives are those the test command (scripts/test.sh) builds into target/fmu
(NIGEL_FMU_DIR names another folder).
"""

import math
import os
import zipfile
from ctypes import c_double, c_int, c_uint32
from pathlib import Path

import numpy as np
import pytest

from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3ScheduledExecution, FMU3Slave
from fmpy.validation import validate_fmu

REPO = Path(__file__).resolve().parents[2]
TARGET = REPO / os.environ.get("CARGO_TARGET_DIR", "target")
CLOCKED = Path(os.environ.get("NIGEL_FMU_DIR", TARGET / "fmu"))
FMU3 = CLOCKED / "fmi3" / "nigel_controller.fmu"
FMU2 = CLOCKED / "nigel_controller.fmu"

WHEELS = ["fl", "fr", "rl", "rr"]
HELD = ["delta_fl", "delta_fr", "delta_rl", "delta_rr", "tau_fl", "tau_fr", "tau_rl", "tau_rr", "drive_force"]
INPUTS = ["beta", "yaw_rate", "speed", "beta_ref", "yaw_rate_ref", "speed_ref", "delta_ff_fl", "delta_ff_fr"]
# fmi3IntervalChanged: a fixed interval is new to the importer in Initialization Mode
INTERVAL_CHANGED = 2


@pytest.fixture(scope="module")
def archives():
    missing = [str(p) for p in (FMU3, FMU2) if not p.exists()]
    assert not missing, f"not built: {missing} (see this file's docstring for the build command)"
    return FMU3, FMU2


def inputs(k):
    """The inputs of sample k: slow sweeps of the measured and reference signals."""
    t = k * 1e-3
    s = math.sin(7.0 * t)
    return [0.02 * s, 0.3 * math.cos(3.0 * t), 0.2 + 0.5 * t, 0.0, 0.1 * s, 0.9, 0.05 * s, 0.05 * s]


def test_the_clocked_archive_validates_and_declares_its_clock(archives):
    fmu3, fmu2 = archives
    assert validate_fmu(fmu3) == []
    md = read_model_description(fmu3)
    clocks = [v for v in md.modelVariables if v.type == "Clock"]
    assert [(c.name, c.causality, c.intervalVariability) for c in clocks] == [("sample_clock", "input", "fixed")]
    # docs/fmus.md: value reference 60, after the 59 variables (time at 0, row r at r + 1)
    assert clocks[0].valueReference == 60 == len(md.modelVariables) - 1
    clocked = sorted(v.name for v in md.modelVariables if v.clocks)
    assert clocked == sorted(HELD)
    assert md.coSimulation.hasEventMode
    # the model partition of Scheduled Execution, priority 0 (fmpy does not read priority)
    assert md.scheduledExecution is not None
    with zipfile.ZipFile(fmu3) as z:
        xml = z.read("modelDescription.xml").decode()
    assert '<Clock name="sample_clock" valueReference="60"' in xml and 'priority="0"' in xml
    # the FMI 2.0 archive of the same build has no clock
    assert all(v.type != "Clock" for v in read_model_description(fmu2).modelVariables)


def test_fmpy_activating_the_clock_gets_the_fmi2_outputs_bit_for_bit(archives):
    fmu3, fmu2 = archives
    md3, md2 = read_model_description(fmu3), read_model_description(fmu2)
    vr3 = {v.name: v.valueReference for v in md3.modelVariables}
    vr2 = {v.name: v.valueReference for v in md2.modelVariables}
    clock = vr3["sample_clock"]
    s3 = FMU3Slave(guid=md3.instantiationToken, unzipDirectory=extract(fmu3),
                   modelIdentifier="nigel_controller", instanceName="clocked")
    s2 = FMU2Slave(guid=md2.guid, unzipDirectory=extract(fmu2), modelIdentifier="nigel_controller",
                   instanceName="sampled")
    s3.instantiate(eventModeUsed=True)
    s3.enterInitializationMode(startTime=0.0)
    interval, qualifier = (c_double * 1)(), (c_int * 1)()
    s3.getIntervalDecimal((c_uint32 * 1)(clock), interval, qualifier)
    # the start value of sample_period (the interval depends on it: intervalVariability fixed)
    assert (interval[0], qualifier[0]) == (1e-3, INTERVAL_CHANGED)
    period = interval[0]
    s3.exitInitializationMode()
    s2.instantiate()
    s2.setupExperiment(startTime=0.0)
    s2.enterInitializationMode()
    s2.exitInitializationMode()
    samples = 500
    for k in range(samples):
        t = k * period  # t_k = start + k T, the activation times by hand
        if k > 0:
            s3.enterEventMode()
        x = inputs(k)
        s3.setFloat64([vr3[n] for n in INPUTS], x)
        s2.setReal([vr2[n] for n in INPUTS], x)
        s3.setClock([clock], [True])
        held3 = s3.getFloat64([vr3[n] for n in HELD + ["speed_integral"]])
        held2 = s2.getReal([vr2[n] for n in HELD + ["speed_integral"]])
        assert [y.hex() for y in held3] == [y.hex() for y in held2], f"sample {k} at t = {t} s"
        s3.updateDiscreteStates()
        s3.enterStepMode()
        s3.doStep(currentCommunicationPoint=t, communicationStepSize=period)
        s2.doStep(currentCommunicationPoint=t, communicationStepSize=period)
    # between activations (Step Mode) a clocked output holds the last activation's value
    assert s3.getFloat64([vr3[n] for n in HELD]) == held3[:-1]
    s3.freeInstance()
    s2.terminate()
    s2.freeInstance()


def input_table(samples, period):
    """The inputs of `inputs(k)` at t_k = k period as fmpy's structured input array."""
    rows = [(k * period, *inputs(k)) for k in range(samples)]
    return np.array(rows, dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])


def same_bits(a, b, names):
    for name in names:
        x, y = np.asarray(a[name], np.float64), np.asarray(b[name], np.float64)
        assert np.array_equal(x.view(np.uint64), y.view(np.uint64)), (name, np.max(np.abs(x - y)))


def test_fmpy_simulate_fmu_runs_the_clocked_archive_as_the_fmi2_one_bit_for_bit(archives):
    """simulate_fmu instantiates FMI 3.0 Co-Simulation with eventModeUsed = false: the
    clocked archive then samples by time itself (docs/fmus.md), so its rows are the FMI 2.0
    archive's to the bit with the same inputs on the same 1 ms grid (0.5 s: 501 rows)."""
    fmu3, fmu2 = archives
    period = 1e-3
    kwargs = dict(stop_time=0.5, step_size=period, output_interval=period, input=input_table(501, period),
                  output=HELD + ["speed_integral"], fmi_type="CoSimulation")
    r3, r2 = simulate_fmu(str(fmu3), **kwargs), simulate_fmu(str(fmu2), **kwargs)
    assert len(r3) == len(r2) == 501
    same_bits(r3, r2, ["time"] + HELD + ["speed_integral"])
    # the steering follows the swept inputs (the drive force saturates at 20 N here, so the
    # torques and the frozen integrator stay put)
    assert np.ptp(r3["delta_fl"]) > 0.05 and np.ptp(r3["delta_rl"]) > 0.05, "the steering moved"


class Generation:
    """One archive stepped as fmpy's simulate_fmu steps Co-Simulation: FMU2Slave, or FMU3Slave
    instantiated with eventModeUsed = false; Real/Float64 access by name."""

    def __init__(self, path, name):
        md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmi3 = md.fmiVersion.startswith("3")
        cls, token = (FMU3Slave, md.instantiationToken) if self.fmi3 else (FMU2Slave, md.guid)
        self.s = cls(guid=token, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                     instanceName=name)
        if self.fmi3:
            self.s.instantiate(eventModeUsed=False)
            self.s.enterInitializationMode(startTime=0.0)
        else:
            self.s.instantiate()
            self.s.setupExperiment(startTime=0.0)
            self.s.enterInitializationMode()

    def get(self, *names):
        vrs = [self.vr[n] for n in names]
        return self.s.getFloat64(vrs) if self.fmi3 else self.s.getReal(vrs)

    def set(self, names, values):
        vrs = [self.vr[n] for n in names]
        (self.s.setFloat64 if self.fmi3 else self.s.setReal)(vrs, values)


def closed_loop(folder, fmi3, seconds):
    """Plant, test bench and controller of `folder` (fmi3: its fmi3/ archives) in one loop of 1 ms
    steps, ordered plant -> bench -> controller -> plant at each point as
    tests/python/test_controller_maneuver.py's closed loop; the rows of the plant's pose and
    the controller's outputs at every point."""
    sub = folder / "fmi3" if fmi3 else folder
    p, b, c = (Generation(sub / f"nigel_{m}.fmu", m) for m in ("plant", "maneuver", "controller"))
    p.set(["v_x_start"], [0.35])
    for g in (p, b, c):
        g.s.exitInitializationMode()
    ff = [f"delta_ff_{w}" for w in WHEELS]
    pose = ["x", "y", "psi"]
    rows = []
    try:
        for k in range(round(seconds / 1e-3) + 1):
            beta, yaw_rate, speed, *xyz = p.get("beta", "yaw_rate", "speed", *pose)
            b.set(["beta", "yaw_rate"], [beta, yaw_rate])
            o = b.get(*ff, "beta_ref", "yaw_rate_ref", "speed_ref", "beta_meas", "yaw_rate_meas",
                      "x_ref", "y_ref", "psi_ref", *[f"mu_{w}" for w in WHEELS], "wind_x", "wind_y")
            # the controller measures beta and yaw_rate through the bench (its noise), speed directly
            c.set(ff + ["beta_ref", "yaw_rate_ref", "speed_ref", "beta", "yaw_rate", "speed"], o[0:9] + [speed])
            c.set(pose + ["x_ref", "y_ref", "psi_ref"], xyz + o[9:12])
            u = c.get(*HELD[:8])
            rows.append(xyz + u)
            p.set([f"delta_{w}" for w in WHEELS] + [f"tau_{w}" for w in WHEELS]
                  + [f"mu_{w}" for w in WHEELS] + ["wind_x", "wind_y"], u + o[12:18])
            for g in (p, b, c):
                g.s.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
    finally:
        for g in (p, b, c):
            g.s.freeInstance()
    return np.array(rows)


def test_fmpy_closed_loop_of_the_fmi3_archives_is_the_fmi2_one_bit_for_bit(archives):
    """The closed loop of the clocked build's three FMI 3.0 archives, each instantiated as
    simulate_fmu does (eventModeUsed = false, so the controller samples by time itself), gives
    the FMI 2.0 archives' loop to the bit over 2 s (2001 points; the pose moves)."""
    folder = archives[1].parent
    a, b = closed_loop(folder, True, 2.0), closed_loop(folder, False, 2.0)
    assert a.shape == b.shape == (2001, 11)
    assert np.array_equal(a.view(np.uint64), b.view(np.uint64)), np.max(np.abs(a - b))
    assert np.ptp(a[:, 0]) > 0.5, "the vehicle drove"


def test_fmpy_activating_the_partition_gets_the_fmi2_outputs_bit_for_bit(archives):
    fmu3, fmu2 = archives
    md3, md2 = read_model_description(fmu3), read_model_description(fmu2)
    vr3 = {v.name: v.valueReference for v in md3.modelVariables}
    vr2 = {v.name: v.valueReference for v in md2.modelVariables}
    se = FMU3ScheduledExecution(guid=md3.instantiationToken, unzipDirectory=extract(fmu3),
                                modelIdentifier="nigel_controller", instanceName="scheduled")
    s2 = FMU2Slave(guid=md2.guid, unzipDirectory=extract(fmu2), modelIdentifier="nigel_controller",
                   instanceName="sampled")
    se.instantiate()
    se.enterInitializationMode(startTime=0.0)
    se.exitInitializationMode()
    s2.instantiate()
    s2.setupExperiment(startTime=0.0)
    s2.enterInitializationMode()
    s2.exitInitializationMode()
    period = 1e-3
    for k in range(300):
        t = k * period  # the activation times by hand: t_k = start + k T
        x = inputs(k)
        se.setFloat64([vr3[n] for n in INPUTS], x)
        s2.setReal([vr2[n] for n in INPUTS], x)
        se.activateModelPartition(vr3["sample_clock"], t)
        held3 = se.getFloat64([vr3[n] for n in HELD + ["speed_integral"]])
        held2 = s2.getReal([vr2[n] for n in HELD + ["speed_integral"]])
        assert [y.hex() for y in held3] == [y.hex() for y in held2], f"sample {k} at t = {t} s"
        s2.doStep(currentCommunicationPoint=t, communicationStepSize=period)
    # an activation off the clock's grid is refused
    with pytest.raises(Exception, match="status 3"):
        se.activateModelPartition(vr3["sample_clock"], 300.5 * period)
    se.freeInstance()
    s2.terminate()
    s2.freeInstance()
