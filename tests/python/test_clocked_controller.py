"""The controller built with the option `controller-sample-clock` (its FMI 3.0 archive
declares the sample period as the periodic input clock `sample_clock`), driven by fmpy's
low-level FMI 3.0 calls as an independent importer: Co-Simulation with Event Mode (the clock
activated at t_k = k T with T read by fmi3GetIntervalDecimal) and Scheduled Execution (the
clock's model partition activated at t_k), against the FMI 2.0 archive of the same build
stepped by fmpy's FMU2Slave on the same grid with the same inputs.

The archives are built by the test command (scripts/test.sh) into target/fmu-clocked/fmu:
`cargo run --release -p build-fmu --features controller-sample-clock -- --platforms linux64
target/fmu-clocked/fmu` (NIGEL_CLOCKED_FMU_DIR names another folder).
"""

import math
import os
import zipfile
from ctypes import c_double, c_int, c_uint32
from pathlib import Path

import pytest

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3ScheduledExecution, FMU3Slave
from fmpy.validation import validate_fmu

REPO = Path(__file__).resolve().parents[2]
TARGET = REPO / os.environ.get("CARGO_TARGET_DIR", "target")
CLOCKED = Path(os.environ.get("NIGEL_CLOCKED_FMU_DIR", TARGET / "fmu-clocked" / "fmu"))
FMU3 = CLOCKED / "fmi3" / "nigel_controller.fmu"
FMU2 = CLOCKED / "nigel_controller.fmu"

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


def test_fmpy_cannot_use_the_clocked_archive_without_event_mode(archives):
    fmu3, _ = archives
    md3 = read_model_description(fmu3)
    s3 = FMU3Slave(guid=md3.instantiationToken, unzipDirectory=extract(fmu3),
                   modelIdentifier="nigel_controller", instanceName="no_event_mode")
    with pytest.raises(Exception):
        s3.instantiate(eventModeUsed=False)


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
