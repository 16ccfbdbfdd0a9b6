"""fmpy cross-checks of the Nigel plant FMU (target/fmu/nigel_plant.fmu).

fmpy (0.3.x, an importer we did not write) loads, validates, simulates and probes the plant
FMU; the numbers are compared with each other (Co-Simulation vs. Model Exchange), with an
independent reference written here in plain Python straight from
docs/vehicle-model.md, and with the interface the plant declares in
fmu-plant/src/lib.rs.

The FMU is taken from $NIGEL_FMU_DIR (default $CARGO_TARGET_DIR/fmu, else <repo>/target/fmu,
where build-fmu puts it); build it with
`cargo run --release -p build-fmu`. Run: `bash scripts/python-env.sh` then
`target/venv/bin/python -m pytest tests/python -q`.

Tolerances, stated once: trajectories are compared on the body states
(x, y, psi, v_x, v_y, yaw_rate: magnitudes 0.01 .. 3 in SI units) and on the state-only
outputs speed and beta, sample by sample on the 1 ms grid, by the largest ABSOLUTE
difference, which must stay <= 1e-6 (TRAJ_TOL). That is about 1e-6 relative to the
states, and at least 50 times below what a one-sample (1 ms) shift of any input
switch changes (asserted in test_reference_is_sensitive_to_input_timing), so a wrong
input-timing convention cannot pass.
"""

import ctypes
import math
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest

import fmpy
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model, FMU2Slave, fmi2Error
from fmpy.validation import validate_fmu
from doc_figures import check as doc_check, check_at_most as doc_check_at_most

REPO = Path(__file__).resolve().parents[2]
TARGET = REPO / os.environ.get("CARGO_TARGET_DIR", "target")  # an absolute CARGO_TARGET_DIR wins
FMU_DIR = Path(os.environ.get("NIGEL_FMU_DIR", TARGET / "fmu"))
FMU = FMU_DIR / "nigel_plant.fmu"

WHEELS = ("fl", "fr", "rl", "rr")
BODY_STATES = ("x", "y", "psi", "v_x", "v_y", "yaw_rate")
SERVO_STATES = tuple(f"servo_angle_{w}" for w in WHEELS)
INPUTS = (
    [f"delta_{w}" for w in WHEELS]
    + [f"tau_{w}" for w in WHEELS]
    + [f"mu_{w}" for w in WHEELS]
    + ["wind_head", "wind_side", "wind_x", "wind_y"]
)

DT = 1e-3  # communication step / output interval / input sample time
STOP = 3.0
TRAJ_TOL = 1e-6  # absolute, on states of order 0.01 .. 3 (see the module docstring)
V0 = 0.35  # start v_x [m/s]

# ---------------------------------------------------------------------------------------
# The scenario: piecewise-constant inputs whose switching times lie on the 1 ms grid.
# Inputs hold BASE, then each change applies from its time on (right-continuous).
# ---------------------------------------------------------------------------------------
BASE = {
    **{f"delta_{w}": 0.0 for w in WHEELS},
    **{f"tau_{w}": 0.002 for w in WHEELS},  # small drive torque: +0.06 N per wheel
    **{f"mu_{w}": 0.4 for w in WHEELS},
    "wind_head": 0.0,
    "wind_side": 0.0,
    "wind_x": 0.0,
    "wind_y": 0.0,
}
CHANGES = [
    (0.5, {"delta_fl": 0.2, "delta_fr": 0.2, "delta_rl": -0.2, "delta_rr": -0.2}),  # steering step
    (1.2, {"mu_rr": 0.15}),  # friction drop at the rear-right wheel
    (2.0, {"wind_head": 0.1, "wind_side": 0.3}),  # wind gust (body frame)
    (2.5, {"wind_x": 0.2, "wind_y": -0.15}),  # world-frame wind, turning with the car
]


def inputs_at_sample(k, changes=CHANGES):
    """Input values on [k DT, (k+1) DT)."""
    u = dict(BASE)
    for t_switch, new in changes:
        if k >= round(t_switch / DT):
            u.update(new)
    return u


def fmpy_input_signal(changes=CHANGES, stop=STOP, base=BASE):
    """fmpy's structured input array: `time` first, one column per input. fmpy
    interpolates linearly between rows and treats a repeated time as a discontinuity
    (left value before, right value from that time on), so a step is two rows with the
    same time."""
    rows = [(0.0, dict(base))]
    u = dict(base)
    for t_switch, new in changes:
        rows.append((t_switch, dict(u)))
        u.update(new)
        rows.append((t_switch, dict(u)))
    rows.append((stop, dict(u)))
    dtype = [("time", np.float64)] + [(n, np.float64) for n in INPUTS]
    return np.array([(t,) + tuple(v[n] for n in INPUTS) for t, v in rows], dtype=dtype)


# ---------------------------------------------------------------------------------------
# Independent reference: docs/vehicle-model.md in plain Python (math on floats), fixed RK4.
# ---------------------------------------------------------------------------------------
TABLE2 = dict(
    m=2.68, I_z=0.01944, l_f=0.06226, l_r=0.07929, track=0.14724, r_wheel=0.0325,
    c=22.4768, g=9.81, v_fade=0.02, delta_max=math.pi / 2, mu=0.4,
    servo_time_constant=0.03, servo_rate_max=5.51, wheel_speed_max=0.442, motor_taper=0.05,
)


class Reference:
    """The right-hand side of docs/vehicle-model.md ("paper" fidelity, plus the three "real"
    options for the derivative spot checks). State: X, Y, psi, v_x, v_y, r, then the four
    servo angles (used only with the servo on)."""

    def __init__(self, friction_circle=False, steering_servo=False, motor_speed_limit=False, **over):
        p = dict(TABLE2, **over)
        self.p = p
        self.fc, self.servo, self.motor = friction_circle, steering_servo, motor_speed_limit
        h = p["track"] / 2
        self.pos = [(p["l_f"], h), (p["l_f"], -h), (-p["l_r"], h), (-p["l_r"], -h)]
        ell = p["l_f"] + p["l_r"]
        nf = p["m"] * p["g"] * p["l_r"] / (2 * ell)
        nr = p["m"] * p["g"] * p["l_f"] / (2 * ell)
        self.normal = [nf, nf, nr, nr]
        self.x_c = (p["l_f"] - p["l_r"]) / 2

    def rhs(self, s, u):
        p = self.p
        X, Y, psi, vx, vy, r = s[:6]
        d = [0.0] * len(s)
        fx_sum = fy_sum = mz = 0.0
        for i, w in enumerate(WHEELS):
            xi, yi = self.pos[i]
            cmd = min(max(u[f"delta_{w}"], -p["delta_max"]), p["delta_max"])
            if self.servo:
                delta = s[6 + i]
                rate = (cmd - delta) / p["servo_time_constant"]
                d[6 + i] = min(max(rate, -p["servo_rate_max"]), p["servo_rate_max"])
            else:
                delta = cmd
            cd, sd = math.cos(delta), math.sin(delta)
            ui = vx - r * yi  # wheel-centre velocity, body frame
            wi = vy + r * xi
            v_lon = ui * cd + wi * sd  # wheel frame
            v_lat = -ui * sd + wi * cd
            alpha = -math.atan2(v_lat, abs(v_lon))
            fade = min(1.0, math.hypot(ui, wi) / p["v_fade"])
            mu = u[f"mu_{w}"]
            f_lat = mu * p["c"] * alpha * fade
            cap = mu * self.normal[i]
            f_drive = min(max(u[f"tau_{w}"] / p["r_wheel"], -cap), cap)
            if self.motor and f_drive > 0:
                # the motor limits the drive force it can deliver; the tire saturates after
                f_drive *= min(max((p["wheel_speed_max"] - v_lon) / p["motor_taper"], 0.0), 1.0)
            if self.fc:
                hyp = math.hypot(f_drive, f_lat)
                if hyp > cap and hyp > 0:
                    f_drive, f_lat = f_drive * cap / hyp, f_lat * cap / hyp
            fx = f_drive * cd - f_lat * sd  # body frame
            fy = f_drive * sd + f_lat * cd
            fx_sum += fx
            fy_sum += fy
            mz += xi * fy - yi * fx
        # world-frame wind in body axes at this stage's heading (docs/benchmark.md)
        wx, wy = u.get("wind_x", 0.0), u.get("wind_y", 0.0)
        head = u["wind_head"] - (wx * math.cos(psi) + wy * math.sin(psi))
        side = u["wind_side"] + (wy * math.cos(psi) - wx * math.sin(psi))
        mz += self.x_c * side
        d[0] = vx * math.cos(psi) - vy * math.sin(psi)
        d[1] = vx * math.sin(psi) + vy * math.cos(psi)
        d[2] = r
        d[3] = (fx_sum - head) / p["m"] + r * vy
        d[4] = (fy_sum + side) / p["m"] - r * vx
        d[5] = mz / p["I_z"]
        return d

    def simulate(self, s0, changes=CHANGES, stop=STOP, h=1e-4):
        """Classical RK4 with step h, inputs held per DT sample. Returns the states on the
        DT grid, shape (n+1, len(s0))."""
        n = int(round(stop / DT))
        sub = int(round(DT / h))
        s = list(s0)
        out = [list(s)]
        f = self.rhs
        for k in range(n):
            u = inputs_at_sample(k, changes)
            for _ in range(sub):
                k1 = f(s, u)
                k2 = f([a + 0.5 * h * b for a, b in zip(s, k1)], u)
                k3 = f([a + 0.5 * h * b for a, b in zip(s, k2)], u)
                k4 = f([a + h * b for a, b in zip(s, k3)], u)
                s = [a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(s, k1, k2, k3, k4)]
            out.append(list(s))
        return np.array(out)


def reference_table(states):
    """Reference states as a dict of columns, plus the state-only outputs."""
    cols = {n: states[:, i] for i, n in enumerate(BODY_STATES)}
    cols["speed"] = np.hypot(cols["v_x"], cols["v_y"])
    cols["beta"] = np.arctan2(cols["v_y"], cols["v_x"])
    return cols


COMPARED = BODY_STATES + ("speed", "beta")


def max_abs_diff(a, b, names=COMPARED):
    """{name: max |a - b|} over the samples."""
    return {n: float(np.max(np.abs(np.asarray(a[n]) - np.asarray(b[n])))) for n in names}


# ---------------------------------------------------------------------------------------
# Fixtures
# ---------------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def fmu_path():
    if not FMU.is_file():
        pytest.fail(f"{FMU} not found: build it with `cargo run --release -p build-fmu` (or set NIGEL_FMU_DIR)")
    return str(FMU)


@pytest.fixture(scope="session")
def md(fmu_path):
    return read_model_description(fmu_path)


@pytest.fixture(scope="session")
def vr(md):
    """name -> value reference, as fmpy reads them."""
    return {v.name: v.valueReference for v in md.modelVariables}


@pytest.fixture(scope="session")
def unzipdir(fmu_path, tmp_path_factory):
    return str(extract(fmu_path, unzipdir=tmp_path_factory.mktemp("nigel_plant_fmu")))


def new_slave(md, unzipdir, name="plant", guid=None):
    fmu = FMU2Slave(
        guid=md.guid if guid is None else guid,
        unzipDirectory=unzipdir,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    fmu.instantiate()
    return fmu


def initialized_slave(md, unzipdir, vr, name="plant", start=None, switches=()):
    fmu = new_slave(md, unzipdir, name)
    fmu.setupExperiment(startTime=0.0)
    for k, v in (start or {}).items():
        fmu.setReal([vr[k]], [v])
    for k in switches:
        fmu.setBoolean([vr[k]], [True])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


@pytest.fixture(scope="session")
def runs(fmu_path):
    """The scenario through fmpy Co-Simulation, fmpy Model Exchange (CVode) and the
    reference.

    Input conventions of fmpy 0.3.32 (simulation.py), which make all three see the same
    piecewise-constant inputs: CS sets the inputs at each communication point t_k, before
    fmi2DoStep, with the value right after t_k (after_event=True), and holds them over the
    step (the FMU has no input derivatives); a CS row at t_k is sampled after the step, i.e.
    with the inputs of [t_(k-1), t_k). ME makes every repeated time of the input table a time
    event: CVode stops exactly there, fmpy records the row (left values), enters event mode,
    sets the right values, records again, and re-initializes CVode (CVodeReInit). The
    reference holds sample k's value over [t_k, t_(k+1)). Every switch is on the 1 ms grid."""
    signal = fmpy_input_signal()
    out = list(BODY_STATES) + ["speed", "beta", "lateral_accel", "der(yaw_rate)"]
    out += [f"force_lat_{w}" for w in WHEELS] + [f"delta_applied_{w}" for w in WHEELS]
    cs = simulate_fmu(
        fmu_path, fmi_type="CoSimulation", start_time=0.0, stop_time=STOP, step_size=DT,
        output_interval=DT, start_values={"v_x_start": V0}, input=signal, output=out,
    )
    me = simulate_fmu(
        fmu_path, fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-10,
        start_time=0.0, stop_time=STOP, output_interval=DT, record_events=True,
        start_values={"v_x_start": V0}, input=signal, output=out,
    )
    ref = Reference().simulate([0.0, 0.0, 0.0, V0, 0.0, 0.0])
    return cs, me, reference_table(ref)


def me_on_grid(me):
    """ME rows on the output grid: at an event time fmpy records two rows (before and after
    the event); keep the first (the left limit, which is what a CS row at a communication
    point holds: the outputs evaluated with the inputs of the step that ended there)."""
    _, first = np.unique(me["time"], return_index=True)
    return me[np.sort(first)]


# ---------------------------------------------------------------------------------------
# Tests
# ---------------------------------------------------------------------------------------
def test_fmpy_version():
    assert fmpy.__version__.startswith("0.3."), fmpy.__version__


def test_validate_fmu_reports_no_problems(fmu_path):
    problems = validate_fmu(fmu_path)
    for p in problems:
        print("fmpy validate:", p)
    assert problems == [], f"fmpy found {len(problems)} problem(s): {problems}"


def test_model_description_matches_the_declaration(md, unzipdir, vr):
    """Every variable fmpy reads has the causality, unit and start value of the declaration
    in fmu-plant/src/lib.rs (restated here by hand, from the spec) and the value reference
    pinned in fmu-plant/value_references.txt, and the binary's own defaults agree with the
    XML start values."""
    expected = {}  # name -> (type, causality, unit, start)
    for i, w in enumerate(WHEELS):
        expected[f"delta_{w}"] = ("Real", "input", "rad", 0.0)
        expected[f"tau_{w}"] = ("Real", "input", "N.m", 0.0)
        expected[f"mu_{w}"] = ("Real", "input", None, 0.4)
    expected["wind_head"] = ("Real", "input", "N", 0.0)
    expected["wind_side"] = ("Real", "input", "N", 0.0)
    expected["wind_x"] = ("Real", "input", "N", 0.0)
    expected["wind_y"] = ("Real", "input", "N", 0.0)
    units = ["m", "m", "rad", "m/s", "m/s", "rad/s", "rad", "rad", "rad", "rad"]
    der_units = ["m/s", "m/s", "rad/s", "m/s2", "m/s2", "rad/s2", "rad/s", "rad/s", "rad/s", "rad/s"]
    for i, name in enumerate(BODY_STATES + SERVO_STATES):
        # the body states are calculated from the parameters *_start (no start value of their own)
        expected[name] = ("Real", "output" if i < 6 else "local", units[i], None if i < 6 else 0.0)
        expected[f"der({name})"] = ("Real", "local", der_units[i], None)
    for i, name in enumerate(BODY_STATES):
        expected[f"{name}_start"] = ("Real", "parameter", units[i], 0.0)
    expected["beta"] = ("Real", "output", "rad", None)
    expected["speed"] = ("Real", "output", "m/s", None)
    expected["lateral_accel"] = ("Real", "output", "m/s2", None)
    for stem, unit in [("slip_angle", "rad"), ("force_lat", "N"), ("force_drive", "N"), ("delta_applied", "rad")]:
        for i, w in enumerate(WHEELS):
            expected[f"{stem}_{w}"] = ("Real", "output", unit, None)
    params = [
        ("m", "kg", 2.68), ("I_z", "kg.m2", 0.01944), ("l_f", "m", 0.06226), ("l_r", "m", 0.07929),
        ("track", "m", 0.14724), ("r_wheel", "m", 0.0325),
        ("c_fl", "N/rad", 22.4768), ("c_fr", "N/rad", 22.4768), ("c_rl", "N/rad", 22.4768), ("c_rr", "N/rad", 22.4768),
        ("g", "m/s2", 9.81), ("v_fade", "m/s", 0.02), ("delta_max", "rad", math.pi / 2),
        ("servo_time_constant", "s", 0.03), ("servo_rate_max", "rad/s", 5.51),
        ("wheel_speed_max", "m/s", 0.442), ("motor_taper", "m/s", 0.05), ("cs_substep_max", "s", 5e-4),
    ]
    for name, unit, start in params:
        expected[name] = ("Real", "parameter", unit, start)
    for name in ["friction_circle", "steering_servo", "motor_speed_limit"]:
        expected[name] = ("Boolean", "parameter", None, False)

    got = {v.name: v for v in md.modelVariables}
    assert sorted(got) == sorted(expected), (set(got) ^ set(expected))
    declared_units = {u.name: u for u in md.unitDefinitions}
    # name, FMI 2.0 value reference, FMI 3.0 value reference
    rows = [line.split() for line in (REPO / "fmu-plant/value_references.txt").read_text().splitlines()]
    pinned = {name: fmi2 for name, fmi2, _fmi3 in rows}
    assert sorted(pinned) == sorted(expected)
    for name, (typ, causality, unit, start) in expected.items():
        v = got[name]
        assert (v.valueReference, v.type, v.causality, v.unit) == (int(pinned[name]), typ, causality, unit), name
        if start is None:
            assert v.start is None, name
        elif typ == "Boolean":
            assert v.start in ("false", False), (name, v.start)
        else:
            assert float(v.start) == pytest.approx(start, rel=1e-15), (name, v.start)
        if unit is not None:
            assert unit in declared_units, f"{name}: unit {unit} not in UnitDefinitions"
    assert got["mu_fl"].min is not None and float(got["mu_fl"].min) == 0.0
    assert got["mu_fl"].max is not None and float(got["mu_fl"].max) == 3.0, "a physical maximum of friction"
    for i, name in enumerate(BODY_STATES + SERVO_STATES):
        assert got[f"der({name})"].derivative is got[name]
        assert got[name].initial == ("calculated" if i < 6 else "exact"), name
    assert [d.variable.name for d in md.derivatives] == [f"der({n})" for n in BODY_STATES + SERVO_STATES]
    assert [o.variable.name for o in md.outputs] == [n for n, e in expected.items() if e[1] == "output"]
    assert md.numberOfContinuousStates == 10 and md.numberOfEventIndicators == 0
    # SI base-unit exponents (kg, m, s, rad) of the units the plant uses
    dims = {"m": (0, 1, 0, 0), "rad": (0, 0, 0, 1), "s": (0, 0, 1, 0), "kg": (1, 0, 0, 0),
            "m/s": (0, 1, -1, 0), "m/s2": (0, 1, -2, 0), "rad/s": (0, 0, -1, 1), "rad/s2": (0, 0, -2, 1),
            "N": (1, 1, -2, 0), "N.m": (1, 2, -2, 0), "kg.m2": (1, 2, 0, 0), "N/rad": (1, 1, -2, -1)}
    for name, (kg, m, s, rad) in dims.items():
        bu = declared_units[name].baseUnit
        assert (bu.kg, bu.m, bu.s, bu.rad, bu.factor, bu.offset) == (kg, m, s, rad, 1.0, 0.0), name

    # what the binary holds at start equals the XML's start values
    fmu = initialized_slave(md, unzipdir, vr, "defaults")
    try:
        reals = [n for n, e in expected.items() if e[0] == "Real" and e[3] is not None]
        values = fmu.getReal([vr[n] for n in reals])
        for n, x in zip(reals, values):
            assert x == pytest.approx(expected[n][3], rel=1e-15, abs=0.0), n
        switches = ["friction_circle", "steering_servo", "motor_speed_limit"]
        assert list(fmu.getBoolean([vr[n] for n in switches])) == [False, False, False]
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_reference_reproduces_the_spec_linearization():
    """The reference RHS itself against the spec's worked numbers (Eq. 2.2 at v = 0.35):
    guards the reference before it judges the FMU."""
    ref = Reference()
    v = 0.35
    u0 = dict(BASE, **{f"tau_{w}": 0.0 for w in WHEELS})
    s0 = [0.0, 0.0, 0.0, v, 0.0, 0.0]

    def f_beta_r(beta, r, u):
        s = [0.0, 0.0, 0.0, v * math.cos(beta), v * math.sin(beta), r]
        d = ref.rhs(s, u)
        vx, vy = s[3], s[4]
        dbeta = (vx * d[4] - vy * d[3]) / (vx * vx + vy * vy)
        return np.array([dbeta, d[5]])

    e = 1e-6
    A = np.column_stack([(f_beta_r(e, 0, u0) - f_beta_r(-e, 0, u0)) / (2 * e),
                         (f_beta_r(0, e, u0) - f_beta_r(0, -e, u0)) / (2 * e)])
    np.testing.assert_allclose(A, [[-38.3400, -0.06724], [15.7523, -26.8591]], rtol=2e-4)
    b2 = []
    for w in WHEELS:
        up, um = dict(u0), dict(u0)
        up[f"delta_{w}"], um[f"delta_{w}"] = e, -e
        b2.append((f_beta_r(0, 0, up) - f_beta_r(0, 0, um))[1] / (2 * e))
    np.testing.assert_allclose(b2, [28.794, 28.794, -36.670, -36.670], rtol=2e-4)
    up, um = dict(u0, wind_side=e), dict(u0, wind_side=-e)
    d = (f_beta_r(0, 0, up) - f_beta_r(0, 0, um)) / (2 * e)
    np.testing.assert_allclose(d, [1.0661, -0.43801], rtol=2e-4)
    # the same numbers at the digits docs/vehicle-model.md prints (central differences of a
    # smooth RHS with e = 1e-6: about 1e-9 relative, far below the 4th decimal printed)
    doc_check("docs/vehicle-model.md", "`A = [[{}, {}], [{}, {}]]`, `B` row 2 `= [{}, {}, {}, {}]`, `d = [{}, {}]`",
              *A.ravel(), *b2, *d)
    assert ref.rhs(s0, u0) == [v, 0.0, 0.0, 0.0, 0.0, 0.0]


def test_reference_is_sensitive_to_input_timing():
    """What TRAJ_TOL can see: moving any input switch of the scenario by one sample (1 ms)
    changes the trajectory by far more (> 50x) than 1e-6, so a CS/ME/reference input-timing mismatch
    cannot hide under the tolerance; and the friction drop and the wind matter."""
    ref = Reference()
    s0 = [0.0, 0.0, 0.0, V0, 0.0, 0.0]
    base = reference_table(ref.simulate(s0))
    for j, (t_switch, new) in enumerate(CHANGES):
        late = list(CHANGES)
        late[j] = (t_switch + DT, new)
        shifted = reference_table(ref.simulate(s0, changes=late))
        worst = max(max_abs_diff(base, shifted).values())
        print(f"switch at {t_switch} s moved by 1 ms: max state change {worst:.3e}")
        assert worst > 50 * TRAJ_TOL, (t_switch, worst)


def test_cs_and_me_agree(runs):
    """fmpy CS (the FMU's internal RK4, 1 ms communication steps) vs. fmpy ME (fmpy's CVode,
    rtol 1e-10): two integrators, one model."""
    cs, me, _ = runs
    me_grid = me_on_grid(me)
    assert len(cs) == len(me_grid) == int(round(STOP / DT)) + 1
    np.testing.assert_allclose(cs["time"], me_grid["time"], rtol=0, atol=1e-12)
    diff = max_abs_diff(cs, me_grid)
    print("max |CS - ME|:", {k: f"{x:.2e}" for k, x in diff.items()})
    assert max(diff.values()) <= TRAJ_TOL, diff
    doc_check("docs/testing.md", "Co-Simulation vs Model Exchange (CVode, rtol 1e-10) differ by at most {},", max(diff.values()))
    # the outputs that depend directly on the inputs agree too (both rows are left limits)
    names = ["lateral_accel", "der(yaw_rate)"] + [f"force_lat_{w}" for w in WHEELS]
    diff_out = max_abs_diff(cs, me_grid, names)
    print("max |CS - ME| (input-dependent outputs):", {k: f"{x:.2e}" for k, x in diff_out.items()})
    assert max(diff_out.values()) <= 1e-5, diff_out  # these are derivatives/forces of order 1..30
    # the scenario does something: turning, friction drop, wind
    assert abs(cs["psi"][-1]) > 1.0 and abs(cs["yaw_rate"][-1]) > 0.5 and abs(cs["y"][-1]) > 0.3


def test_cs_and_me_agree_with_the_reference(runs):
    cs, me, ref = runs
    me_grid = me_on_grid(me)
    d_cs = max_abs_diff(cs, ref)
    d_me = max_abs_diff(me_grid, ref)
    print("max |CS - reference|:", {k: f"{x:.2e}" for k, x in d_cs.items()})
    print("max |ME - reference|:", {k: f"{x:.2e}" for k, x in d_me.items()})
    assert max(d_cs.values()) <= TRAJ_TOL, d_cs
    # the same RK4 in two implementations: rounding, printed as a bound
    doc_check_at_most("docs/testing.md", "Co-Simulation vs an independent Python RK4 reference by {};", max(d_cs.values()))
    assert max(d_me.values()) <= TRAJ_TOL, d_me


def test_me_handles_the_input_discontinuities_as_events(runs):
    """fmpy ME stops the integrator at each repeated time of the input table, enters event
    mode, applies the right-hand values and restarts CVode; with record_events it records
    the left and the right limit. Check that those two rows are what the model says."""
    _, me, _ = runs
    t = me["time"]
    for t_switch, _ in CHANGES:
        rows = np.flatnonzero(np.isclose(t, t_switch, rtol=0, atol=1e-12))
        assert len(rows) == 2, (t_switch, t[rows])
        pre, post = me[rows[0]], me[rows[1]]
        for n in BODY_STATES:  # states are continuous through an input event
            assert pre[n] == post[n], (t_switch, n)
    assert len(me) == int(round(STOP / DT)) + 1 + len(CHANGES)
    # steering step at 0.5 s: the applied angle and the front tire force jump
    pre, post = me[np.isclose(t, 0.5, rtol=0, atol=1e-12)]
    assert (pre["delta_applied_fl"], post["delta_applied_fl"]) == (0.0, 0.2)
    assert (pre["delta_applied_rr"], post["delta_applied_rr"]) == (0.0, -0.2)
    assert abs(pre["force_lat_fl"]) < 1e-12 and post["force_lat_fl"] > 1.0
    assert abs(pre["der(yaw_rate)"]) < 1e-9 and post["der(yaw_rate)"] > 10.0
    # friction drop at 1.2 s: the linear tire force scales with mu (slip angle continuous)
    pre, post = me[np.isclose(t, 1.2, rtol=0, atol=1e-12)]
    assert post["force_lat_rr"] / pre["force_lat_rr"] == pytest.approx(0.15 / 0.4, rel=1e-12)
    assert post["force_lat_rl"] == pre["force_lat_rl"]


def test_fmu_state_get_set_and_serialize(md, unzipdir, vr):
    """getFMUstate, N steps, setFMUstate, the same N steps: bit-identical; the state carries
    the inputs too. serializeFMUstate -> bytes -> deSerializeFMUstate in a fresh instance
    -> bit-identical continuation. A truncated byte string is refused."""
    watch = [vr[v.name] for v in md.modelVariables if v.causality == "output" or v.name in SERVO_STATES]
    steer = [vr[f"delta_{w}"] for w in WHEELS]

    def run(fmu, k0, n, change_at=None):
        rows = []
        for k in range(k0, k0 + n):
            if k == change_at:
                fmu.setReal([vr["mu_rr"], vr["tau_fl"]], [0.15, 0.01])  # an input change inside the window
            fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
            rows.append(fmu.getReal(watch))
        return np.array(rows)

    # the steering servo on in "a" only: parameters must travel in the state as well
    a = initialized_slave(md, unzipdir, vr, "a", start={"v_x_start": V0}, switches=["steering_servo"])
    b = None
    try:
        a.setReal(steer, [0.2, 0.2, -0.2, -0.2])
        run(a, 0, 100)
        state = a.getFMUstate()
        saved = a.getReal(watch)
        first = run(a, 100, 200, change_at=150)
        assert a.getReal([vr["mu_rr"]]) == [0.15]
        a.setFMUstate(state)
        assert a.getReal([vr["mu_rr"], vr["tau_fl"]]) == [0.4, 0.0]  # inputs restored too
        assert a.getReal(watch) == saved
        again = run(a, 100, 200, change_at=150)
        assert np.array_equal(first, again)
        assert np.ptp(first[:, BODY_STATES.index("yaw_rate")]) > 0.01  # it moved
        assert 0.19 < first[0, 6] < first[-1, 6] < 0.2  # and the servo (servo_angle_fl) is still turning

        blob = a.serializeFMUstate(state)
        assert isinstance(blob, bytes) and len(blob) > 8 * 30
        assert a.serializeFMUstate(state) == blob
        a.freeFMUstate(state)

        b = initialized_slave(md, unzipdir, vr, "b")  # defaults: standing still, paper fidelity
        restored = b.deSerializeFMUstate(blob)
        b.setFMUstate(restored)
        b.freeFMUstate(restored)
        assert b.getReal(watch) == saved
        assert list(b.getBoolean([vr["steering_servo"]])) == [True]
        continued = run(b, 100, 200, change_at=150)
        assert np.array_equal(first, continued)

        with pytest.raises(FMICallException) as e:
            b.deSerializeFMUstate(blob[:-8])
        assert e.value.status == fmi2Error
    finally:
        a.terminate()
        a.freeInstance()
        if b is not None:
            b.freeInstance()


# The points of the directional-derivative checks: moving, steered, yawing; every input nonzero.
JAC_STATE = [0.3, -0.2, 0.7, 0.41, 0.03, 0.4, 0.25, -0.05, -0.08, -0.02]
JAC_INPUTS = {
    "delta_fl": 0.2, "delta_fr": 0.18, "delta_rl": -0.1, "delta_rr": -0.12,
    "tau_fl": 0.094, "tau_fr": 0.004, "tau_rl": -0.01, "tau_rr": 0.015,
    "mu_fl": 0.4, "mu_fr": 0.35, "mu_rl": 0.3, "mu_rr": 0.25,
    "wind_head": 0.05, "wind_side": -0.03, "wind_x": 0.04, "wind_y": -0.06,
}


@pytest.mark.parametrize("real_fidelity", [False, True], ids=["paper", "real"])
def test_directional_derivatives_match_finite_differences(md, unzipdir, vr, real_fidelity):
    """fmi2GetDirectionalDerivative (the FMU's forward-mode AD) of all derivatives and
    outputs w.r.t. all states and inputs, through fmpy's FMU2Model in continuous-time mode,
    against central differences of fmi2GetDerivatives / fmi2GetReal."""
    m = FMU2Model(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.modelExchange.modelIdentifier,
                  instanceName="jacobian")
    m.instantiate()
    try:
        m.setupExperiment(startTime=0.0)
        if real_fidelity:
            m.setBoolean([vr["friction_circle"], vr["steering_servo"], vr["motor_speed_limit"]], [True] * 3)
        m.enterInitializationMode()
        m.exitInitializationMode()
        while m.newDiscreteStates()[0]:
            pass
        m.enterContinuousTimeMode()
        nx = md.numberOfContinuousStates
        state_vrs = [d.variable.derivative.valueReference for d in md.derivatives]
        assert state_vrs == [vr[n] for n in BODY_STATES + SERVO_STATES]
        der_vrs = [d.variable.valueReference for d in md.derivatives]
        outputs = ["beta", "speed", "lateral_accel"] + [
            f"{stem}_{w}" for stem in ["slip_angle", "force_lat", "force_drive", "delta_applied"] for w in WHEELS
        ]
        out_vrs = [vr[n] for n in outputs]
        input_vrs = [vr[n] for n in INPUTS]

        x = np.array(JAC_STATE, dtype=np.float64)
        xbuf = (ctypes.c_double * nx)()
        dxbuf = (ctypes.c_double * nx)()

        def set_x(v):
            xbuf[:] = list(v)
            m.setContinuousStates(xbuf, nx)

        def f():
            m.getDerivatives(dxbuf, nx)
            return np.array(list(dxbuf) + list(m.getReal(out_vrs)))

        u = np.array([JAC_INPUTS[n] for n in INPUTS])
        set_x(x)
        m.setReal(input_vrs, list(u))
        f0 = f()

        # the FMU's derivatives equal the reference RHS at this point (and the point is not trivial)
        ref = Reference(friction_circle=real_fidelity, steering_servo=real_fidelity, motor_speed_limit=real_fidelity)
        np.testing.assert_allclose(f0[:nx], ref.rhs(list(x), JAC_INPUTS), rtol=1e-12, atol=1e-12)
        if real_fidelity:
            p = TABLE2
            drive = f0[nx + 11:nx + 15]  # force_drive_*
            lat = f0[nx + 7:nx + 11]  # force_lat_*
            normal = ref.normal
            mus = [JAC_INPUTS[f"mu_{w}"] for w in WHEELS]
            on_circle = [abs(math.hypot(drive[i], lat[i]) - mus[i] * normal[i]) < 1e-12 for i in range(4)]
            assert on_circle == [True, False, False, False], on_circle  # FL's tire saturated
            taper = drive[1] / (JAC_INPUTS["tau_fr"] / p["r_wheel"])
            assert 0.05 < taper < 0.95, taper  # FR inside the motor's taper
            servo_rates = f0[6:10]
            assert abs(servo_rates[1]) == p["servo_rate_max"]  # FR's servo rate-limited
            assert all(0 < abs(servo_rates[i]) < p["servo_rate_max"] for i in (0, 2, 3)), servo_rates

        # AD: one call per known, all unknowns at once
        unknowns = der_vrs + out_vrs
        knowns = state_vrs + input_vrs
        ad = np.column_stack([m.getDirectionalDerivative(unknowns, [k], [1.0]) for k in knowns])

        # central differences
        fd = np.zeros_like(ad)
        for j in range(nx):
            h = 1e-6 * max(1.0, abs(x[j]))
            xp, xm = x.copy(), x.copy()
            xp[j] += h
            xm[j] -= h
            set_x(xp)
            fp = f()
            set_x(xm)
            fm = f()
            fd[:, j] = (fp - fm) / (2 * h)
        set_x(x)
        for j, vref in enumerate(input_vrs):
            h = 1e-6 * max(1.0, abs(u[j]))
            m.setReal([vref], [u[j] + h])
            fp = f()
            m.setReal([vref], [u[j] - h])
            fm = f()
            m.setReal([vref], [u[j]])
            fd[:, nx + j] = (fp - fm) / (2 * h)
        np.testing.assert_array_equal(f(), f0)  # back at the point

        err = np.abs(ad - fd)
        scale = np.maximum(np.abs(fd), 1.0)
        worst = np.unravel_index(np.argmax(err / scale), err.shape)
        print(f"{'real' if real_fidelity else 'paper'}: max |AD - FD| / max(|FD|, 1) = {np.max(err / scale):.2e} "
              f"at unknown vr {unknowns[worst[0]]}, known vr {knowns[worst[1]]}; |J|max = {np.max(np.abs(ad)):.1f}")
        assert np.all(err <= 1e-6 * scale), np.max(err / scale)
        if not real_fidelity:
            doc_check("docs/testing.md", "directional derivatives vs central differences {} relative;", np.max(err / scale))
        assert np.count_nonzero(np.abs(ad) > 1e-3) > 100  # a dense, non-trivial Jacobian

        # the sparsity agrees with the ModelStructure: a nonzero partial derivative is declared
        # as a dependency (fmpy: Unknown.dependencies, None = "depends on everything")
        structure = {u.variable.valueReference: u for u in list(md.derivatives) + list(md.outputs)}
        for i, unknown in enumerate(unknowns):
            deps = structure[unknown].dependencies
            assert deps is not None, unknown  # the plant declares every dependency list
            declared = {v.valueReference for v in deps if v.type == "Real"}
            used = {knowns[j] for j in np.flatnonzero(ad[i] != 0.0)}
            assert used <= declared, (unknown, sorted(used - declared))

        # several knowns at once: the FMU sums the seeds (J v)
        seed = np.linspace(-1.0, 1.0, len(knowns))
        jv = m.getDirectionalDerivative(unknowns, knowns, list(seed))
        np.testing.assert_allclose(jv, ad @ seed, rtol=1e-12, atol=1e-10)
        m.terminate()
    finally:
        m.freeInstance()


def test_wrong_guid_is_refused(md, unzipdir, capsys):
    """fmi2Instantiate with a GUID that differs in one digit: the FMU logs why and returns
    NULL, which fmpy turns into an exception. (The FMU's messages reach fmpy's default
    logger, which prints them: fmpy's variadic-logger proxy keeps ONE global Python logger
    for all instances, so a test must not install its own short-lived one.)"""
    wrong = md.guid[:-2] + ("0" if md.guid[-2] != "0" else "1") + md.guid[-1]
    assert wrong != md.guid
    capsys.readouterr()
    with pytest.raises(Exception, match="Failed to instantiate"):
        new_slave(md, unzipdir, "wrong_guid", guid=wrong)
    log = capsys.readouterr().out
    print(log)
    assert "[ERROR]" in log and "guid" in log.lower(), log
    # the right GUID: accepted (so the refusal above was the GUID's)
    fmu = new_slave(md, unzipdir, "right_guid")
    fmu.freeInstance()


def test_do_step_after_terminate_is_refused(md, unzipdir, vr):
    fmu = initialized_slave(md, unzipdir, vr, "terminated", start={"v_x_start": V0})
    try:
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=DT)
        fmu.terminate()
        with pytest.raises(FMICallException) as e:
            fmu.doStep(currentCommunicationPoint=DT, communicationStepSize=DT)
        assert e.value.status == fmi2Error and e.value.function == "fmi2DoStep"
    finally:
        fmu.freeInstance()


def test_nan_input_is_refused(md, unzipdir, vr):
    fmu = initialized_slave(md, unzipdir, vr, "nan", start={"v_x_start": V0})
    try:
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=DT)
        fmu.setReal([vr["delta_fl"]], [0.1])
        with pytest.raises(FMICallException) as e:
            fmu.setReal([vr["delta_fl"]], [float("nan")])
        assert e.value.status == fmi2Error and e.value.function == "fmi2SetReal"
        assert fmu.getReal([vr["delta_fl"]]) == [0.1]  # the NaN did not get in
        with pytest.raises(FMICallException):  # after fmi2Error: only reset/free (and get)
            fmu.doStep(currentCommunicationPoint=DT, communicationStepSize=DT)
        fmu.reset()  # ... and reset brings it back
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=DT)
        assert fmu.getReal([vr["delta_fl"], vr["v_x"]]) == [0.0, 0.0]
        fmu.terminate()
    finally:
        fmu.freeInstance()


SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="nigel_plant_only"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="root">
    <ssd:Connectors>
      <ssd:Connector name="steer_front" kind="input"><ssc:Real unit="rad"/></ssd:Connector>
      <ssd:Connector name="steer_rear" kind="input"><ssc:Real unit="rad"/></ssd:Connector>
    </ssd:Connectors>
    <ssd:ParameterBindings>
      <ssd:ParameterBinding>
        <ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="start">
            <ssv:Parameters>
              <ssv:Parameter name="plant.v_x_start"><ssv:Real value="0.35"/></ssv:Parameter>
              <ssv:Parameter name="plant.mu_rr"><ssv:Real value="0.3"/></ssv:Parameter>
              <ssv:Parameter name="plant.I_z"><ssv:Real value="0.025"/></ssv:Parameter>
            </ssv:Parameters>
          </ssv:ParameterSet>
        </ssd:ParameterValues>
      </ssd:ParameterBinding>
    </ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="plant" type="application/x-fmu-sharedlibrary" source="resources/nigel_plant.fmu">
        <ssd:Connectors>
{component_connectors}
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startConnector="steer_front" endElement="plant" endConnector="delta_fl"/>
      <ssd:Connection startConnector="steer_front" endElement="plant" endConnector="delta_fr"/>
      <ssd:Connection startConnector="steer_rear" endElement="plant" endConnector="delta_rl"/>
      <ssd:Connection startConnector="steer_rear" endElement="plant" endConnector="delta_rr"/>
    </ssd:Connections>
  </ssd:System>
</ssd:SystemStructureDescription>
"""


def test_ssp_with_the_plant_matches_the_direct_cs_run(fmu_path, tmp_path):
    """A one-component SSP (the plant as a CS FMU; two steering signals from system inputs;
    a parameter of the initial state (v_x_start), an input start (mu_rr) and a parameter (I_z) from the SSD's
    ParameterValues) through
    fmpy.ssp.simulation.simulate_ssp, against simulate_fmu on the same FMU.

    How fmpy 0.3.32's simulate_ssp works (read from its source, checked here):
    - it parses ParameterBindings but does not apply them itself: the caller passes a
      ParameterSet (names "<component>.<variable>") as parameter_set; we pass the one the
      SSD carries, so the SSD's values are the ones used;
    - every connector starts at 0.0 and a component's inputs are set, before each step,
      from the connections propagated AFTER the previous step (a Jacobi master), so the
      plant sees a system input sampled at t_(k-1) during [t_k, t_(k+1)) and 0.0 in the
      first step: a one-step delay;
    - the row labelled t_k holds the outputs after the step, i.e. at t_(k+1).
    """
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import read_ssd

    outputs = list(BODY_STATES) + ["speed"]
    lines = [f'          <ssd:Connector name="delta_{w}" kind="input"><ssc:Real unit="rad"/></ssd:Connector>' for w in WHEELS]
    lines += [f'          <ssd:Connector name="{n}" kind="output"><ssc:Real/></ssd:Connector>' for n in outputs]
    ssp = tmp_path / "nigel_plant_only.ssp"
    with zipfile.ZipFile(ssp, "w") as z:
        z.writestr("SystemStructure.ssd", SSD.replace("{component_connectors}", "\n".join(lines)))
        z.write(fmu_path, "resources/nigel_plant.fmu")

    ssd = read_ssd(str(ssp))  # validates against the SSP 1.0 schema fmpy ships
    (binding,) = ssd.system.parameterBindings
    (parameter_set,) = binding.parameterValues
    assert [(p.name, float(p.value)) for p in parameter_set.parameters] == [
        ("plant.v_x_start", 0.35), ("plant.mu_rr", 0.3), ("plant.I_z", 0.025)]

    t_on = 0.5  # the system input switches at 0.5 s (threshold half a step early: fmpy sums time += step)
    stop = 1.0
    result = simulate_ssp(
        str(ssp), start_time=0.0, stop_time=stop, step_size=DT, parameter_set=parameter_set,
        input={"steer_front": lambda t: 0.2 if t > t_on - DT / 2 else 0.0,
               "steer_rear": lambda t: -0.2 if t > t_on - DT / 2 else 0.0},
    )
    n = len(result)
    assert n in (1000, 1001), n
    np.testing.assert_allclose(result["time"], np.arange(n) * DT, rtol=0, atol=1e-12)

    # the same through simulate_fmu, with the one-step delay of the SSP master
    steer = {"delta_fl": 0.2, "delta_fr": 0.2, "delta_rl": -0.2, "delta_rr": -0.2}
    fmu_defaults = dict(BASE, **{f"tau_{w}": 0.0 for w in WHEELS})  # the SSP leaves tau, wind at their starts
    fmu_defaults["mu_rr"] = 0.3  # from the ParameterValues

    def direct_run(t_switch):
        return simulate_fmu(
            fmu_path, fmi_type="CoSimulation", start_time=0.0, stop_time=stop + 2 * DT, step_size=DT,
            output_interval=DT, start_values={"v_x_start": 0.35, "I_z": 0.025},
            input=fmpy_input_signal([(t_switch, steer)], stop + 2 * DT, base=fmu_defaults), output=outputs,
        )

    direct = direct_run(t_on + DT)
    ssp_cols = {name: result[f"plant.{name}"] for name in outputs}
    direct_next = {name: direct[name][1:n + 1] for name in outputs}  # row k of the SSP = t_(k+1)
    diff = max_abs_diff(ssp_cols, direct_next, outputs)
    print("max |SSP - direct CS|:", {k: f"{x:.2e}" for k, x in diff.items()})
    # not bit-identical: fmpy's CS step sizes are differences of k*DT (ulps off 1 ms), which
    # can change the FMU's number of internal RK4 sub-steps; the effect is ~1e-12
    assert max(diff.values()) <= 1e-9, diff
    # the same FMU stepped by two loops: rounding, printed as a bound
    doc_check_at_most("docs/testing.md", "`simulate_ssp` vs direct Co-Simulation {}.", max(diff.values()))
    assert abs(ssp_cols["yaw_rate"][-1]) > 0.3  # the steering went through the connections
    assert abs(ssp_cols["v_x"][0] - 0.35) < 1e-3  # v_x_start = 0.35 from the ParameterValues
    # mu_rr and I_z from the ParameterValues matter: the run with the FMU's defaults differs
    plain = simulate_fmu(
        fmu_path, fmi_type="CoSimulation", start_time=0.0, stop_time=stop + 2 * DT, step_size=DT,
        output_interval=DT, start_values={"v_x_start": 0.35},
        input=fmpy_input_signal([(t_on + DT, steer)], stop + 2 * DT, base=dict(fmu_defaults, mu_rr=0.4)),
        output=outputs,
    )
    assert max(max_abs_diff(ssp_cols, {k: plain[k][1:n + 1] for k in outputs}, outputs).values()) > 1e-4
    # a check that the delay model above is what discriminates: without it the rows differ
    naive_direct = direct_run(t_on)
    naive = {name: naive_direct[name][1:n + 1] for name in outputs}
    assert max(max_abs_diff(ssp_cols, naive, outputs).values()) > 1e-5
