"""nigel_cosim: the nigel-fmi co-simulation master from Python, with fmpy's interface.

- :func:`simulate_fmu` runs one FMU with fmpy's keywords and returns fmpy's structured
  array (``time`` first).
- :func:`simulate_ssp` runs an SSP system (its parameter bindings applied); fields are
  named ``instance.variable`` as ``cosim run`` names its CSV columns.
- :class:`System` loads an FMU or SSP once and runs it many times without unpacking it
  again (its instances are reset between runs, not re-created).
- :func:`run_campaign` runs a campaign description (a ``.toml`` path or a dict) and returns
  its ``results.csv`` as a pandas DataFrame.
- :func:`write_csv` writes a result as fmpy's ``write_csv`` does.

Runs release the GIL (two Python threads run two simulations at once) and stop on Ctrl-C
within a fraction of a second with ``KeyboardInterrupt``, their FMUs freed. Every error is a
:class:`Error` (or one of its subclasses) carrying the master's message.
"""

from __future__ import annotations

import json
import os
import sys
import warnings
from pathlib import Path
from types import FrameType
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from . import _native
from ._native import (
    CampaignError,
    Error,
    ExperimentError,
    LoadError,
    RunTimeoutError,
    SimulationError,
    VariableError,
)

__version__ = _native.__version__

__all__ = [
    "simulate_fmu",
    "simulate_ssp",
    "System",
    "run_campaign",
    "compare",
    "info",
    "write_csv",
    "Error",
    "LoadError",
    "VariableError",
    "SimulationError",
    "ExperimentError",
    "RunTimeoutError",
    "CampaignError",
]

# the column types of the native results, as numpy types (fmpy's for FMI 3.0: Int64 and
# UInt64 as int64 / uint64, every value exact; a String as text)
_DTYPES = {
    "Real": np.float64,
    "Integer": np.int32,
    "Enumeration": np.int32,
    "Boolean": np.bool_,
    "Int64": np.int64,
    "UInt64": np.uint64,
    "String": object,
}

# fmpy's names of the integrators, mapped onto the master's (Model Exchange): CVode is a
# variable-order BDF method, as the master's bdf is; fmpy's Euler (explicit, fixed step) has
# no counterpart here (refused, saying what to use)
_SOLVERS = {None: "bdf", "CVode": "bdf", "bdf": "bdf", "dopri5": "dopri5", "rk4": "rk4", "Euler": None}


def _fmpy_keywords(interface: str, validate, debug_logging, record_events, apply_default_start_values,
                   step_finished, fmi_call_logger, extra: Mapping[str, Any]) -> None:
    """fmpy.simulate_fmu's keywords that users pass out of habit: the ones that mean the same
    here are accepted, the others refused with an :class:`Error` saying what to use instead."""
    if validate is False:
        raise Error("validate=False: nigel_cosim always reads the model description with its own checks "
                    "(it refuses only what would make a run wrong, naming the variable); drop validate=False")
    if debug_logging:
        raise Error("debug_logging=True: nigel_cosim does not switch on the FMU's debug log; the FMU's warnings "
                    "and errors come with the run (System.last_summary['warnings'], or the Error raised); "
                    "for a call-by-call log use fmpy.simulate_fmu(..., debug_logging=True)")
    if record_events is True and interface == "ModelExchange":
        raise Error("record_events=True: nigel_cosim records Model Exchange runs at the output points only, "
                    "not the rows just before and after each event that fmpy adds; pass record_events=False "
                    "(the events are in System.last_summary['events']) or a smaller output_interval")
    if step_finished is not None:
        raise Error("step_finished: there is no per-step callback; step the run from Python instead: "
                    "with nigel_cosim.System(filename) as s: s.initialize(...); then s.step() or "
                    "s.step_until(t), s.get(name), s.set(name, value), s.results()")
    if fmi_call_logger is not None:
        raise Error("fmi_call_logger: nigel_cosim logs no FMI calls; use fmpy.simulate_fmu(..., "
                    "fmi_call_logger=print) for a trace of the calls")
    if extra:
        raise Error(f"simulate_fmu got keywords it does not know: {', '.join(sorted(extra))} "
                    "(fmpy's validate, debug_logging, record_events, apply_default_start_values, "
                    "step_finished, fmi_call_logger and timeout are understood or refused with a reason)")
    # apply_default_start_values: the FMU starts at its model description's start values either
    # way (fmpy sets them explicitly only when asked); the same run, accepted either way
    del apply_default_start_values


def _warn_sample_periods(system: "System", args: dict) -> None:
    """`cosim run`'s warning about a communication step longer than an FMU's declared sample
    period, as a Python warning (the run goes on: it is what was asked for)."""
    # the warning points at the user's line: the first frame outside this file
    level = 1
    frame: FrameType | None = sys._getframe(0)
    while frame is not None and frame.f_code.co_filename == __file__:
        frame, level = frame.f_back, level + 1
    for message in system._native.sample_period_warnings(_Args(args)):
        warnings.warn(message, UserWarning, stacklevel=level)


def _float(value: Any) -> float | None:
    """A time or tolerance as fmpy takes it (a number or its text), None left as it is."""
    return None if value is None else float(value)


def _text(value: Any) -> str:
    """A start value as the master parses it (repr round-trips a float exactly)."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return str(value)


def _input_table(signals: np.ndarray | None):
    """fmpy's input (a structured array, time first) as (names, time, columns)."""
    if signals is None:
        return None
    names = signals.dtype.names
    if not names or len(names) < 2:
        raise ExperimentError("input: a structured array with a time field first and one field per input")
    return (
        list(names[1:]),
        [float(t) for t in signals[names[0]]],
        [[float(v) for v in signals[n]] for n in names[1:]],
    )


def _structured(names: Sequence[str], types: Sequence[str], values: np.ndarray,
                exact: Sequence[tuple[int, Sequence[str]]] = ()) -> np.ndarray:
    """fmpy's structured array from the native rows (float64, time first): a view of the
    rows as float64 fields, cast field by field where a column is Integer or Boolean; the
    columns an f64 does not hold (``exact``: column and the text of every row) from their
    text: 64-bit integers exactly (int64 / uint64), Strings as str (object dtype)."""
    rows = np.ascontiguousarray(values, dtype=np.float64)
    fields = ["time", *names]
    as_float = np.dtype([(n, np.float64) for n in fields])
    result = rows.view(as_float).reshape(rows.shape[0])
    wanted = np.dtype([("time", np.float64)] + [(n, _DTYPES.get(t, np.float64)) for n, t in zip(names, types)])
    texts = {names[column]: text for column, text in exact if _DTYPES.get(types[column]) in (np.int64, np.uint64, object)}
    if not texts:
        return result if wanted == as_float else result.astype(wanted)
    out = np.empty(rows.shape[0], dtype=wanted)
    for name in fields:
        if name in texts:
            kind = wanted[name]
            out[name] = np.array([int(v) for v in texts[name]] if kind != object else texts[name], dtype=kind)
        else:
            out[name] = result[name]
    return out


class System:
    """An FMU (one instance named ``model``) or an SSP system, loaded and unpacked once.

    Use it as a context manager, or call :meth:`close`, to free its FMUs and remove their
    unpacked folders::

        with nigel_cosim.System("target/ssp/nigel_closed_loop.ssp") as system:
            for m in (2.4, 2.7, 3.0):
                result = system.simulate(stop_time=30.0, step_size=1e-3, start_values={"plant.m": m})
    """

    def __init__(self, filename: str | os.PathLike, fmi_type: str | None = None,
                 use_event_mode: bool | None = None):
        self._native = _native.NativeSystem(os.fspath(filename), fmi_type, use_event_mode)
        self._filename = os.fspath(filename)
        self._start_values: dict[str, Any] = {}
        self._run: _native.NativeRun | None = None
        self._step = 1e-3
        self._output_interval = None
        self.last_summary: dict | None = None

    # -- context manager ---------------------------------------------------------------
    def __enter__(self) -> "System":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Ends a stepped run, frees the FMUs and removes their unpacked folders."""
        self.terminate()
        self._run = None
        self._native.close()

    @property
    def closed(self) -> bool:
        return self._native.closed

    # -- what it is ----------------------------------------------------------------------
    @property
    def interfaces(self) -> list[str]:
        """The interfaces of a single FMU (``CoSimulation``, ``ModelExchange``,
        ``ScheduledExecution``)."""
        return list(self._native.interfaces)

    @property
    def notes(self) -> list[str]:
        """What reading an SSP noted (the lines ``cosim run`` prints as notes): parameter
        values whose names match nothing (ignored, as SSP 1.0 says), units taken as
        written, an SSD of the SSP 2.0 draft."""
        return list(self._native.notes)

    @property
    def default_experiment(self) -> dict[str, float | None]:
        start, stop, step, tolerance = self._native.default_experiment
        return {"start_time": start, "stop_time": stop, "step_size": step, "tolerance": tolerance}

    def variables(self) -> list[dict[str, Any]]:
        """Every variable: name, type, causality, variability, start (text), unit, description."""
        keys = ("name", "type", "causality", "variability", "start", "unit", "description")
        return [dict(zip(keys, v)) for v in self._native.variables()]

    # -- values ----------------------------------------------------------------------------
    def set(self, name: str, value: Any) -> None:
        """Before :meth:`initialize` (or between runs): a start value or parameter for the
        following runs, checked at the next run. During a stepped run: an input or tunable
        parameter, checked now and applied from the next communication step on."""
        if self._run is not None and not self._run.finished:
            self._run.set(name, _text(value))
        else:
            self._start_values[name] = value

    def get(self, name: str) -> Any:
        """During a stepped run: the recorded value at the current time. Otherwise the start
        value set with :meth:`set`, else the model description's (as text)."""
        if self._run is not None:
            return self._run.get(name)
        if name in self._start_values:
            return self._start_values[name]
        for v in self._native.variables():
            if v[0] == name:
                return v[4]
        raise VariableError(f"no variable {name!r}")

    # -- a run stepped from here -------------------------------------------------------------
    def initialize(
        self,
        start_time: float | None = None,
        stop_time: float | None = None,
        step_size: float | None = None,
        output_interval: float | None = None,
        algorithm: str = "jacobi",
        start_values: Mapping[str, Any] | None = None,
        input: np.ndarray | None = None,
        output: Iterable[str] | None = None,
        solver: str | None = None,
        relative_tolerance: float | None = None,
    ) -> float:
        """Instantiates and initializes a run to be stepped with :meth:`step` and
        :meth:`step_until` (the same keywords as :meth:`simulate`); returns the start time.
        :meth:`get` reads the recorded variables (``output``, default every output)."""
        self.terminate()
        args = self._args(start_time, stop_time, step_size, output_interval, algorithm, start_values, input, output,
                          solver, relative_tolerance, None, 1)
        _warn_sample_periods(self, args)
        self._step = args["step"]
        self._run = self._native.start(_Args(args))
        return self._run.time

    @property
    def time(self) -> float:
        """The time of the stepped run's last row (``nan`` when there is no run)."""
        return self._run.time if self._run is not None else float("nan")

    def step(self) -> float:
        """One communication step (one output interval); returns the time reached."""
        return self.step_until(self.time + (self._output_interval or self._step) * 0.5)

    def step_until(self, time: float) -> float:
        """Runs on to the first output point at or after ``time`` (at most the stop time);
        returns the time reached. Ctrl-C stops the run with ``KeyboardInterrupt``."""
        if self._run is None:
            raise Error("no run: call initialize first")
        return self._run.step_until(float(time))

    def results(self) -> np.ndarray:
        """The stepped run's rows so far (a structured array, ``time`` first)."""
        if self._run is None:
            raise Error("no run: call initialize first")
        return _structured(*self._run.results())

    def terminate(self) -> dict | None:
        """Ends the stepped run (its instances terminated and freed); its summary, or None
        when it ended before its stop time."""
        if self._run is None:
            return None
        summary = self._run.terminate()
        self.last_summary = json.loads(summary) if summary else None
        return self.last_summary

    # -- runs ------------------------------------------------------------------------------
    def simulate(
        self,
        start_time: float | None = None,
        stop_time: float | None = None,
        step_size: float | None = None,
        output_interval: float | None = None,
        algorithm: str = "jacobi",
        start_values: Mapping[str, Any] | None = None,
        input: np.ndarray | None = None,
        output: Iterable[str] | None = None,
        solver: str | None = None,
        relative_tolerance: float | None = None,
        timeout: float | None = None,
        threads: int = 1,
    ) -> np.ndarray:
        """One run with the master's semantics: communication step ``step_size`` (default
        the DefaultExperiment's, else 1 ms), every step recorded unless ``output_interval``
        (a whole multiple of it) is given; returns a structured array, ``time`` first."""
        args = self._args(start_time, stop_time, step_size, output_interval, algorithm, start_values, input, output,
                          solver, relative_tolerance, timeout, threads)
        _warn_sample_periods(self, args)
        return self._simulate(args)

    def _args(self, start_time, stop_time, step_size, output_interval, algorithm, start_values, input, output, solver,
              relative_tolerance, timeout, threads):
        # the master's defaults (nigel_cosim::defaults::RunTimes::master)
        start, stop, step, tolerance = self._native.run_times(_float(start_time), _float(stop_time), _float(step_size),
                                                              relative_tolerance)
        self._output_interval = output_interval
        return self._arguments(start, stop, step, output_interval, algorithm, start_values, input, output, solver,
                               tolerance, timeout, threads)

    def _arguments(self, start, stop, step, output_interval, algorithm, start_values, input, output, solver, tolerance,
                   timeout, threads, max_step=None):
        if solver not in _SOLVERS:
            raise ExperimentError(f"unknown solver {solver!r} (CVode, bdf, dopri5, rk4)")
        if _SOLVERS[solver] is None:
            raise ExperimentError(
                f"solver {solver!r}: fmpy's explicit Euler method (fixed steps of step_size) is not offered; "
                "use solver='rk4' with the same step_size (fixed steps of step_size, fourth order, so not "
                "Euler's numbers), or 'CVode' (the master's BDF method here) or 'dopri5' (variable step)")
        values = dict(self._start_values)
        values.update(start_values or {})
        return {
            "start_time": start,
            "stop_time": stop,
            "step": step,
            "output_interval": output_interval,
            "algorithm": algorithm,
            "start_values": [(k, _text(v)) for k, v in values.items()],
            "input": _input_table(input),
            "output": list(output) if output is not None else None,
            "solver": _SOLVERS[solver],
            "max_step": max_step,
            "relative_tolerance": tolerance,
            "timeout": timeout,
            "threads": threads,
        }

    def _simulate(self, args: dict) -> np.ndarray:
        names, types, array, summary, exact = self._native.simulate(_Args(args))
        self.last_summary = json.loads(summary) if summary else None
        return _structured(names, types, array, exact)


class _Args:
    """The attribute view of the run's arguments the native half extracts."""

    def __init__(self, values: dict):
        self.__dict__.update(values)


def simulate_fmu(
    filename: str | os.PathLike,
    validate: bool = True,
    start_time: float | None = None,
    stop_time: float | None = None,
    solver: str | None = None,
    step_size: float | None = None,
    relative_tolerance: float | None = None,
    output_interval: float | None = None,
    record_events: bool | None = None,
    fmi_type: str | None = None,
    start_values: Mapping[str, Any] = {},
    apply_default_start_values: bool = False,
    input: np.ndarray | None = None,
    output: Iterable[str] | None = None,
    timeout: float | None = None,
    debug_logging: bool = False,
    fmi_call_logger: Any = None,
    step_finished: Any = None,
    use_event_mode: bool | None = None,
    **fmpy_keywords: Any,
) -> np.ndarray:
    """Simulates an FMU as ``fmpy.simulate_fmu`` does and returns its structured array.

    The keywords mean what they mean in fmpy: ``stop_time`` defaults to the
    DefaultExperiment's (else start + 1 s); Co-Simulation steps by ``output_interval``
    (default: the DefaultExperiment's step size, doubled until at most 1000 steps, else
    fmpy's automatic interval); Model Exchange integrates between output points
    (``solver='CVode'``, fmpy's default, is this master's variable-order BDF method with
    ``relative_tolerance``, default 1e-5, and the FMU's Jacobian; ``'dopri5'`` its explicit
    Dormand-Prince method; ``'rk4'`` fixed steps of ``step_size``, or of the output interval
    when ``step_size`` is not given).

    fmpy's other keywords, in fmpy's order: ``validate=True`` (the model description is
    always checked), ``apply_default_start_values`` (the FMU starts at its start values
    either way) and ``record_events=False`` are accepted with fmpy's meaning;
    ``record_events=True`` means nothing in Co-Simulation, as in fmpy, and is refused for
    Model Exchange, where this master records output points only (left out, fmpy's default
    True, the output points are recorded: fmpy's rows less the ones it adds at events); ``timeout``
    (seconds of wall time) raises :class:`RunTimeoutError` where fmpy returns the rows so far.
    ``validate=False``, ``debug_logging=True``, ``step_finished`` and ``fmi_call_logger`` are
    refused with an :class:`Error` that says what to use instead. An ``.ssp`` is refused:
    use :func:`simulate_ssp`.

    ``use_event_mode`` (fmpy's name) chooses FMI 3.0 Co-Simulation Event Mode
    (``eventModeUsed``): ``None`` (default) only for an FMU with clocks, which needs it (an
    FMU without clocks handles its events inside its step, as fmpy's default
    ``use_event_mode=False`` runs it); ``True`` for every such FMU (one without
    ``hasEventMode`` is refused); ``False`` never (an FMU with clocks is refused, naming them).
    """
    if Path(os.fspath(filename)).suffix.lower() in (".ssp", ".ssd"):
        raise LoadError(f"{os.fspath(filename)}: an SSP system, not an FMU: use nigel_cosim.simulate_ssp "
                        "(or nigel_cosim.System for many runs)")
    with System(filename, fmi_type, use_event_mode) as system:
        interface = fmi_type or system.interfaces[0]
        _fmpy_keywords(interface, validate, debug_logging, record_events, apply_default_start_values, step_finished,
                       fmi_call_logger, fmpy_keywords)
        # fmpy.simulate_fmu's defaults (nigel_cosim::defaults::RunTimes::fmpy)
        start, stop, output_interval, tolerance = system._native.fmpy_times(
            interface == "CoSimulation", _float(start_time), _float(stop_time), _float(step_size),
            _float(output_interval), relative_tolerance)
        # fmpy's Model Exchange with a fixed-step solver integrates with steps of step_size
        # between the output points; rk4 here likewise (its largest step)
        max_step = _float(step_size) if interface == "ModelExchange" and solver == "rk4" else None
        args = system._arguments(start, stop, output_interval, None, "jacobi", start_values, input, output,
                                 solver, tolerance, timeout, 1, max_step)
        _warn_sample_periods(system, args)
        return system._simulate(args)


def simulate_ssp(
    filename: str | os.PathLike,
    start_time: float | None = None,
    stop_time: float | None = None,
    step_size: float | None = None,
    output_interval: float | None = None,
    algorithm: str = "jacobi",
    start_values: Mapping[str, Any] = {},
    input: np.ndarray | None = None,
    output: Iterable[str] | None = None,
    timeout: float | None = None,
    use_event_mode: bool | None = None,
) -> np.ndarray:
    """Simulates an SSP system as ``cosim run`` does (its parameter bindings, parameter
    mappings and system connector values applied; the SSD's DefaultExperiment start and
    stop time where none is given); fields are named ``instance.variable``; the same
    numbers as the command line. What reading the SSP noted is warned (``UserWarning``).
    ``use_event_mode`` applies to each FMU as :func:`simulate_fmu`'s does."""
    with System(filename, use_event_mode=use_event_mode) as system:
        import warnings

        for note in system.notes:
            warnings.warn(f"{os.fspath(filename)}: {note}", stacklevel=2)
        return system.simulate(
            start_time=start_time,
            stop_time=stop_time,
            step_size=step_size,
            output_interval=output_interval,
            algorithm=algorithm,
            start_values=start_values,
            input=input,
            output=output,
            timeout=timeout,
        )


def run_campaign(
    spec: str | os.PathLike | Mapping[str, Any],
    out: str | os.PathLike | None = None,
    threads: int | None = None,
    shard: tuple[int, int] | None = None,
    progress: bool = False,
):
    """Runs a campaign (``campaign run``'s description: a ``.toml`` path or the same as a
    dict) into the folder ``out`` (default: a temporary folder, removed afterwards) and returns its
    ``results.csv`` as a pandas DataFrame (pandas is an optional dependency; without it,
    a NumPy structured array). ``shard=(i, n)`` runs only block ``i`` of ``n``."""
    import tempfile

    if out is None:
        with tempfile.TemporaryDirectory(prefix="nigel-campaign-") as scratch:
            return run_campaign(spec, Path(scratch) / "out", threads, shard, progress)
    if isinstance(spec, Mapping):
        path, text = None, _toml(spec)
    else:
        path, text = os.fspath(spec), None
    csv, _ran, _failed = _native.run_campaign(path, text, os.fspath(out), threads, shard, progress)
    try:
        import pandas
    except ImportError:
        return np.genfromtxt(csv, delimiter=",", names=True, dtype=None, encoding="utf-8")
    return pandas.read_csv(csv)


def info(filename: str | os.PathLike) -> str:
    """What the FMU or SSP ``filename`` declares, as ``cosim info`` prints it: the model,
    its interfaces and default experiment and one line per variable (name, causality,
    variability, type, unit, start, range, description); for an SSP its instances, the
    values it applies and its connections. Raises ``LoadError`` for a file it cannot read."""
    return _native.info(os.fspath(filename))


def compare(
    result: str | os.PathLike | np.ndarray,
    baseline: str | os.PathLike | np.ndarray,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    time_tol: float = 0.0,
    signals: Sequence[str] | None = None,
    plot: str | os.PathLike | None = None,
) -> dict[str, Any]:
    """Compares ``result`` with ``baseline`` signal by signal in tolerance tubes, as
    ``cosim compare`` does (docs/ci.md): each a CSV path or a structured array (as
    ``simulate_fmu`` returns, time first). Returns the report: ``passed``, ``tolerance``,
    ``signals`` (per signal ``name``, ``passed``, ``points``, ``violations``, ``worst``,
    ``problem``, ``detail``), ``notes``, ``lines``, ``figures`` (the paths of the PNGs drawn into
    ``plot`` for the failing signals)."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="nigel-compare-") as scratch:
        paths = []
        for what, data in (("result", result), ("baseline", baseline)):
            if isinstance(data, np.ndarray):
                path = Path(scratch) / f"{what}.csv"
                write_csv(path, data)
                paths.append(os.fspath(path))
            else:
                paths.append(os.fspath(data))
        names = list(signals) if signals is not None else None
        folder = os.fspath(plot) if plot is not None else None
        return _native.compare(paths[0], paths[1], rtol, atol, time_tol, names, folder)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if v != v:
            return "nan"
        if v in (float("inf"), float("-inf")):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, (str, os.PathLike)):
        return json.dumps(os.fspath(v))  # a JSON string is a TOML basic string
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{json.dumps(str(k))} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise CampaignError(f"the description: {v!r} has no TOML form")


def _toml(spec: Mapping[str, Any]) -> str:
    """A campaign description (a dict, in the order given) as the TOML ``campaign run``
    reads: scalars and lists first, then one table per dict."""
    lines = [f"{json.dumps(str(k))} = {_toml_value(v)}" for k, v in spec.items() if not isinstance(v, Mapping)]
    for k, table in spec.items():
        if isinstance(table, Mapping):
            lines.append(f"[{json.dumps(str(k))}]")
            lines += [f"{json.dumps(str(n))} = {_toml_value(v)}" for n, v in table.items()]
    return "\n".join(lines) + "\n"


def write_csv(filename: str | os.PathLike, result: np.ndarray, columns: Sequence[str] | None = None) -> None:
    """Writes a structured result as ``fmpy.util.write_csv`` does: quoted names, ``time``
    first, one row per point (floats as Python prints them: they read back exactly)."""
    if columns is not None:
        result = result[["time"] + list(columns)]
    names = result.dtype.names
    if names is None:
        raise TypeError("write_csv: result must be a structured array (a result of simulate_fmu), "
                        f"not an array of {result.dtype}")
    with open(filename, "w") as f:
        f.write(",".join(f'"{n}"' for n in names) + "\n")
        for row in result:
            f.write(",".join(str(row[n]) for n in names) + "\n")
