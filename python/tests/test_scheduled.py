"""nigel_cosim.simulate_fmu with fmi_type="ScheduledExecution": the Reference FMUs' Clocks of
the third-party corpus (``$NIGEL_CORPUS``, else ``../shared/corpus`` beside the repository;
skipped without it) runs the scenario its model.c documents, with the same rows as
``cosim run --interface se`` (cosim/tests/fmi3_scheduled.rs checks the command line)."""

import os
from pathlib import Path

import numpy as np
import pytest

import nigel_cosim

REPO = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("NIGEL_CORPUS", REPO.parent / "shared" / "corpus"))
CLOCKS = CORPUS / "fmi3" / "cs" / "ReferenceFMUs-0.0.41-src" / "Clocks" / "Clocks.fmu"


@pytest.mark.skipif(not CLOCKS.is_file(), reason="no third-party corpus beside the repository")
def test_the_reference_clocks_fmu_in_scheduled_execution():
    # inClock2 ticks where its column is nonzero: 0, 1, 8 and 9 s
    inputs = np.array([(0.0, 1.0), (1.0, 1.0), (2.0, 0.0), (8.0, 1.0), (9.0, 1.0)],
                      dtype=[("time", "f8"), ("inClock2", "f8")])
    r = nigel_cosim.simulate_fmu(CLOCKS, fmi_type="ScheduledExecution", stop_time=10, input=inputs)
    assert list(r["time"]) == [float(t) for t in range(11)]
    last_tick = r[r["time"] == 9.0][0]
    # the counts model.c documents: inClock1 every second (10), inClock2 4 times, inClock3
    # once (counted down from inClock1's partition at 4 s), 15 in all
    assert [int(last_tick[n]) for n in ("inClock1Ticks", "inClock2Ticks", "inClock3Ticks", "totalInClockTicks")] \
        == [10, 4, 1, 15]
    assert list(r["time"][r["inClock3"] == 1.0]) == [4.0]
