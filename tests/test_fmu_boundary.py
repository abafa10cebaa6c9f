"""Each FMU carries exactly its model; the runtime imports nothing of the project; builds repeat."""
from __future__ import annotations

import ast
import dataclasses
import zipfile
from pathlib import Path

import pytest

from fmubuild.cbuild import build_c
from fmubuild.packaging import build
from fmubuild.project import FMUS, ROOT, entry_source
from fmukit.manifest import digest_of, read, staleness

PROJECT = {"cosim", "fmubuild", "fmukit", "ship_fmu", "autopilot_fmu"}
ADAPTERS = {2: "pythonfmu07", 3: "pythonfmu3_03"}
"""FMI version: the fmukit adapter its FMUs carry."""
# What each FMU carries of the model packages, beside its slave and fmukit.
MODELS = {
    "ship": {"ship_fmu.data", "ship_fmu.hull", "ship_fmu.steering_gear", "ship_fmu.thrusters",
             "ship_fmu.vessel", "ship_fmu.waves", "ship_fmu.wind"},
    "manoeuvre": {"ship_fmu.manoeuvres"},
    "environment": {"ship_fmu.environment", "ship_fmu.data"},   # current, wind; the scale
    "sensors": {"ship_fmu.sensors"},                  # the instruments, nothing of the ship
    "observer": {"autopilot_fmu.observer"},           # Nomoto's T and K as numbers
    "pd_autopilot": {"autopilot_fmu.pd"},
    # design_model 'ship' linearises the vessel model
    "smc_autopilot": {"autopilot_fmu.design", "autopilot_fmu.smc", "ship_fmu.data",
                      "ship_fmu.hull", "ship_fmu.steering_gear", "ship_fmu.thrusters",
                      "ship_fmu.vessel", "ship_fmu.waves", "ship_fmu.wind"},
    # the circle of acceptance is two ship lengths
    "guidance": {"autopilot_fmu.guidance", "ship_fmu.data"},
    "los_guidance": {"autopilot_fmu.guidance", "autopilot_fmu.guidance_slave", "autopilot_fmu.los",
                     "ship_fmu.data"},                  # eq (18)'s FMU is its base
    "pid_autopilot": set(),
    "policy_autopilot": {"autopilot_fmu.policy"},      # and its weights, a data file
}


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("name", list(FMUS))
def test_each_fmu_carries_exactly_its_model_and_says_so(fmu_paths, fmi3_paths, name, fmi):
    fmu = (fmu_paths if fmi == 2 else fmi3_paths)[name]
    manifest = read(fmu)
    slave = ".".join(Path(FMUS[name]).with_suffix("").parts)
    assert manifest.model_name == name and manifest.slave_module == slave
    models = {m for m in manifest.modules if not m.startswith("fmukit") and m != slave}
    assert models == MODELS[name]
    assert "fmukit.build" not in manifest.modules and "fmukit.slave" in manifest.modules
    adapters = {m.split(".")[1] for m in manifest.modules if m.startswith("fmukit.pythonfmu")}
    assert adapters == {ADAPTERS[fmi]}                  # its version's adapter, only
    pythonfmu = f"resources/{'pythonfmu' if fmi == 2 else 'pythonfmu3'}/"
    with zipfile.ZipFile(fmu) as package:
        python = {n for n in package.namelist() if n.endswith(".py")
                  and not n.startswith(pythonfmu)}              # pythonfmu's own runtime
        assert package.read("resources/slavemodule.txt").decode() == manifest.entry["module"]
    assert python == {carried["file"] for carried in manifest.modules.values()} | {
        manifest.entry["file"]}                                   # the class pythonfmu loads
    assert digest_of({m: c["sha256"] for m, c in manifest.modules.items()}) == manifest.digest
    assert staleness(manifest, entry_source) is None
    # so no host-only module (fmubuild, cosim), edited or not, can make an FMU stale
    assert not any(m.split(".")[0] in ("fmubuild", "cosim") for m in manifest.modules)


def test_an_fmu_whose_entry_module_this_build_would_not_write_is_stale(fmu_paths, fmi3_paths):
    for fmu in (fmu_paths["pd_autopilot"], fmi3_paths["pd_autopilot"]):
        manifest = read(fmu)
        assert staleness(manifest, entry_source) is None
        other = dataclasses.replace(manifest, entry={**manifest.entry, "sha256": "0" * 64})
        module = manifest.entry["module"]
        assert staleness(other, entry_source) == (
            f"its entry module {module} is not the one this build writes (built before a "
            "change of fmubuild.project: rebuild it)")


def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_bytes())):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_the_runtime_imports_no_project_module_and_only_its_adapters_import_pythonfmu():
    adapters = {"pythonfmu": ADAPTERS[2], "pythonfmu3": ADAPTERS[3]}
    for path in sorted((ROOT / "fmukit").rglob("*.py")):
        if path.name == "build.py" and path.parent.name == "fmukit":
            continue                    # the build command's published name: host-only
        imported = _imports(path)
        assert not imported & (PROJECT - {"fmukit"}), path
        for pythonfmu in imported & set(adapters):
            assert path.parent.name == adapters[pythonfmu], path


def test_two_builds_of_one_commit_are_byte_identical(fmu_paths, fmi3_paths, tmp_path,
                                                     c_autopilot):
    for fmi, paths in ((2, fmu_paths), (3, fmi3_paths)):
        first = build("pid_autopilot", tmp_path / f"a{fmi}", fmi).read_bytes()
        assert build("pid_autopilot", tmp_path / f"b{fmi}", fmi).read_bytes() == first
        assert paths["pid_autopilot"].read_bytes() == first        # and the suite's own
    c = build_c("pd_autopilot_c", tmp_path / "a").read_bytes()
    assert build_c("pd_autopilot_c", tmp_path / "b").read_bytes() == c
