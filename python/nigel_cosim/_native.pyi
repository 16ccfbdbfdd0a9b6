"""Type stubs of the Rust half of nigel_cosim (users call the functions of nigel_cosim)."""

import os
from typing import Any, final

import numpy as np
import numpy.typing as npt

# the names the module exports (pyo3 fills its `__all__` as lib.rs registers them)
__all__ = [
    "CampaignError",
    "Error",
    "ExperimentError",
    "LoadError",
    "NativeRun",
    "NativeSystem",
    "RunTimeoutError",
    "SimulationError",
    "VariableError",
    "__version__",
    "compare",
    "info",
    "run_campaign",
]

__version__: str

class Error(Exception): ...
class LoadError(Error): ...
class VariableError(Error): ...
class SimulationError(Error): ...
class ExperimentError(Error): ...
class RunTimeoutError(Error): ...
class CampaignError(Error): ...

@final
class NativeSystem:
    def __new__(
        cls, filename: str | os.PathLike[str], fmi_type: str | None = None, use_event_mode: bool | None = None
    ) -> NativeSystem: ...
    @property
    def default_experiment(self) -> tuple[float | None, float | None, float | None, float | None]: ...
    @property
    def interfaces(self) -> list[str]: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def closed(self) -> bool: ...
    def run_times(
        self,
        start_time: float | None,
        stop_time: float | None,
        step_size: float | None,
        relative_tolerance: float | None,
    ) -> tuple[float, float, float, float | None]: ...
    def fmpy_times(
        self,
        co_simulation: bool,
        start_time: float | None,
        stop_time: float | None,
        step_size: float | None,
        output_interval: float | None,
        relative_tolerance: float | None,
    ) -> tuple[float, float, float, float | None]: ...
    def variables(
        self,
    ) -> list[tuple[str, str, str, str, str | None, str | None, str | None]]: ...
    def simulate(
        self, args: Any
    ) -> tuple[list[str], list[str], npt.NDArray[np.float64], str, list[tuple[int, list[str]]]]: ...
    def sample_period_warnings(self, args: Any) -> list[str]: ...
    def start(self, args: Any) -> NativeRun: ...
    def close(self) -> None: ...

@final
class NativeRun:
    @property
    def time(self) -> float: ...
    @property
    def finished(self) -> bool: ...
    def step_until(self, time: float) -> float: ...
    def get(self, name: str) -> float: ...
    def set(self, name: str, value: str) -> None: ...
    def results(self) -> tuple[list[str], list[str], npt.NDArray[np.float64], list[tuple[int, list[str]]]]: ...
    def terminate(self) -> str | None: ...

def run_campaign(
    spec: str | None,
    spec_text: str | None,
    out: str,
    threads: int | None = None,
    shard: tuple[int, int] | None = None,
    progress: bool = False,
) -> tuple[str, int, int]: ...

def info(filename: str | os.PathLike[str]) -> str: ...
def compare(
    result: str,
    baseline: str,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    time_tol: float = 0.0,
    signals: list[str] | None = None,
    plot: str | None = None,
) -> dict[str, Any]: ...
