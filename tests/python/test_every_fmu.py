"""fmpy checks over every FMU build-fmu built (target/fmu/manifest.json): validate_fmu
reports no problems, Co-Simulation runs, Model Exchange runs where declared, the outputs
stay finite, and a wrong GUID is refused. A new FMU is covered once it is in build-fmu's
list (the manifest is written from that list)."""

import json
import os
from pathlib import Path

import numpy as np
import pytest

from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

REPO = Path(__file__).resolve().parents[2]
TARGET = REPO / os.environ.get("CARGO_TARGET_DIR", "target")
FMU_DIR = Path(os.environ.get("NIGEL_FMU_DIR", TARGET / "fmu"))
# the FMI 2.0 archives (tests/python/test_fmi3_archives.py checks the FMI 3.0 ones against them)
MANIFEST = [e for e in json.loads((FMU_DIR / "manifest.json").read_text()) if e["fmi_version"] == "2.0"]
IDS = [entry["model_identifier"] for entry in MANIFEST]


def entry_for(model_identifier):
    return next(e for e in MANIFEST if e["model_identifier"] == model_identifier)


def test_manifest_lists_the_plant_and_every_archive_exists():
    assert "nigel_plant" in IDS
    for e in MANIFEST:
        assert (FMU_DIR / e["fmu"]).is_file(), e


@pytest.mark.parametrize("model_identifier", IDS)
def test_validate_fmu_reports_no_problems(model_identifier):
    path = FMU_DIR / entry_for(model_identifier)["fmu"]
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.guid == entry_for(model_identifier)["guid"]
    interfaces = entry_for(model_identifier)["interfaces"]
    assert (md.coSimulation is not None) == ("CoSimulation" in interfaces)
    assert (md.modelExchange is not None) == ("ModelExchange" in interfaces)


@pytest.mark.parametrize(
    "model_identifier,interface",
    [(e["model_identifier"], i) for e in MANIFEST for i in e["interfaces"]],
)
def test_simulation_runs_with_finite_outputs(model_identifier, interface):
    path = str(FMU_DIR / entry_for(model_identifier)["fmu"])
    kwargs = dict(fmi_type=interface, start_time=0.0, stop_time=0.5, output_interval=1e-3)
    if interface == "CoSimulation":
        kwargs["step_size"] = 1e-3
    else:
        kwargs.update(solver="CVode", relative_tolerance=1e-8)
    result = simulate_fmu(path, **kwargs)
    assert len(result) >= 500
    assert result["time"][-1] == pytest.approx(0.5)
    for name in result.dtype.names:
        assert np.all(np.isfinite(result[name].astype(float))), name


@pytest.mark.parametrize("model_identifier", IDS)
def test_wrong_guid_is_refused(model_identifier, tmp_path):
    path = str(FMU_DIR / entry_for(model_identifier)["fmu"])
    md = read_model_description(path)
    unzipdir = extract(path, unzipdir=str(tmp_path / "x"))
    model_identifier_cs = (md.coSimulation or md.modelExchange).modelIdentifier
    slave = FMU2Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=unzipdir,
                      modelIdentifier=model_identifier_cs, instanceName="wrong")
    with pytest.raises(Exception):
        slave.instantiate()


@pytest.mark.parametrize("model_identifier", IDS)
def test_no_enumeration_variables(model_identifier):
    """libcosim and ecos do not see FMI 2.0 Enumeration variables: every switch of our FMUs is
    a plain Integer with declared min/max and its values listed in its description."""
    md = read_model_description(str(FMU_DIR / entry_for(model_identifier)["fmu"]))
    assert md.typeDefinitions == [] or all(t.type != "Enumeration" for t in md.typeDefinitions)
    for v in md.modelVariables:
        assert v.type != "Enumeration", v.name
        if v.type == "Integer" and v.causality == "parameter" and v.name != "seed":
            assert v.min is not None and v.max is not None, v.name
            for k in range(int(v.min), int(v.max) + 1):
                assert f"{k} " in (v.description or ""), f"{v.name}: value {k} not described"


def test_closed_loop_ssp_binds_only_what_every_importer_applies():
    """The bindings of target/ssp/nigel_closed_loop.ssp (written by build-fmu) are what libcosim,
    ecos and our master all apply: parameters or inputs (libcosim drops a binding of anything
    else), of the variable's own type (no Enumeration), in one ParameterSet name shared by every
    component (ecos applies the sets of the one name given to init)."""
    import shutil
    from fmpy.ssp.ssd import find_components, read_ssd

    ssp = TARGET / "ssp" / "nigel_closed_loop.ssp"
    ssd = read_ssd(str(ssp))
    names = set()
    bound = {}
    unzipped = extract(str(ssp))
    try:
        for c in find_components(ssd.system):
            md = read_model_description(os.path.join(unzipped, c.source))
            variables = {v.name: v for v in md.modelVariables}
            for binding in c.parameterBindings:
                for values in binding.parameterValues:
                    names.add(values.name)
                    for p in values.parameters:
                        v = variables[p.name]
                        assert v.causality in ("parameter", "input"), (c.name, p.name, v.causality)
                        assert p.type == v.type, (c.name, p.name, p.type, v.type)
                        bound[f"{c.name}.{p.name}"] = p.value
    finally:
        shutil.rmtree(unzipped, ignore_errors=True)
    assert names == {"initialValues"}
    assert float(bound["plant.v_x_start"]) == 0.35
    assert int(bound["maneuver.maneuver"]) == 2 and int(bound["controller.controller"]) == 3


@pytest.mark.parametrize("model_identifier", IDS)
def test_fmpy_finds_the_library_of_every_platform_the_manifest_lists(model_identifier):
    import zipfile

    from fmpy import supported_platforms

    e = entry_for(model_identifier)
    path = FMU_DIR / e["fmu"]
    with zipfile.ZipFile(path) as z:
        names = set(z.namelist())
    found = set(supported_platforms(str(path)))
    folders = [p["folder"] for p in e["platforms"]]
    assert "linux64" in folders
    for p in e["platforms"]:
        assert p["library"] in names, p
        # fmpy names the FMI 2 platforms; aarch64-linux is FMI 3's folder, which it may not list
        if p["folder"] in ("linux64", "win64", "darwin64"):
            assert p["folder"] in found, (p["folder"], found)
