"""Each FMU describes itself: who made it, its documentation page and its icon (issue 26)."""
from __future__ import annotations

import io
import re
import subprocess
import sys
import tomllib
import zipfile
from dataclasses import replace
from importlib import metadata
from pathlib import Path
from xml.etree.ElementTree import fromstring

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu
from PIL import Image

from fmubuild.manifest import read, staleness
from fmubuild.packaging import build
from fmubuild.project import FMUS, ROOT

PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
BLOCK = (0xdd, 0xe8, 0xf4)
"""The fill of a block icon (fmubuild.icon)."""


def _entry(fmu: Path, name: str) -> bytes:
    with zipfile.ZipFile(fmu) as package:
        return package.read(name)


@pytest.mark.parametrize("name", list(FMUS))
def test_each_fmu_declares_the_projects_version_license_and_fmukit(fmu_paths, name):
    described = read_model_description(str(fmu_paths[name]))
    assert described.version == PROJECT["version"] == metadata.version(PROJECT["name"])
    assert described.license == PROJECT["license"]["text"]
    assert described.author and described.copyright.startswith("Copyright")
    assert described.generationTool == f"fmukit {PROJECT['version']} (pythonfmu 0.7.0)"
    assert validate_fmu(str(fmu_paths[name])) == []


@pytest.mark.parametrize("name", list(FMUS))
def test_the_documentation_lists_every_variable_with_its_unit(fmu_paths, name):
    page = _entry(fmu_paths[name], "documentation/index.html").decode()
    root = fromstring(page)                       # well-formed, so no tag is left open
    assert not re.search(r"\b(src|href)=", page), "the page loads nothing from outside"
    rows = {"".join(tr[0].itertext()): [("".join(td.itertext())) for td in tr]
            for tr in root.iter("tr") if tr[0].tag == "td"}
    described = read_model_description(str(fmu_paths[name]))
    for variable in described.modelVariables:
        row = rows[variable.name]
        assert row[1] == variable.type, variable.name
        assert row[2].split(" (shown in ")[0] == (variable.unit or ""), variable.name
        assert row[-1] == (variable.description or ""), variable.name
        if variable.causality == "parameter":
            assert row[3] == str(variable.start), variable.name
    text = "".join(root.itertext())
    assert described.description in text
    for platform in ("linux64", "win64"):
        assert f"{platform}: " in text and "numpy" in text
    assert "LD_PRELOAD" in text


def test_the_documentation_cites_the_paper_and_the_equations_of_what_the_fmu_carries(fmu_paths):
    page = _entry(fmu_paths["ship"], "documentation/index.html").decode()
    assert "Tomera, M. (2010)" in page and "Fossen" in page
    for module, equations in (("hull", "eqs (1)-(6)"), ("thrusters", "eqs (8)-(13)"),
                              ("waves", "eqs (14)-(17)")):
        assert f"<code>ship_fmu.{module}</code>: " in page and equations in page


@pytest.mark.parametrize("name", list(FMUS))
def test_the_documentations_worked_example_runs(fmu_paths, tmp_path, name):
    page = _entry(fmu_paths[name], "documentation/index.html").decode()
    command = re.search(r"<pre>(fmpy simulate .*?)</pre>", page).group(1).split()
    assert command[:3] == ["fmpy", "simulate", f"{name}.fmu"] and "--start-values" in command
    (tmp_path / f"{name}.fmu").write_bytes(fmu_paths[name].read_bytes())
    fmpy = Path(sys.executable).with_name("fmpy")
    subprocess.run([str(fmpy), *command[1:]], cwd=tmp_path, check=True, capture_output=True)
    header, *rows = (tmp_path / f"{name}.csv").read_text().splitlines()
    stop = command[command.index("--stop-time") + 1]
    outputs = [v.name for v in read_model_description(str(fmu_paths[name])).modelVariables
               if v.causality == "output"]
    assert header.replace('"', "").split(",") == ["time", *outputs]
    assert rows[-1].startswith(f"{stop},")


@pytest.mark.parametrize("name", list(FMUS))
def test_the_icon_is_a_png_drawn_from_the_model(fmu_paths, name):
    icon = Image.open(io.BytesIO(_entry(fmu_paths[name], "model.png")))
    assert icon.format == "PNG" and icon.size == (256, 256)
    colours = {rgba[:3] for _, rgba in icon.convert("RGBA").getcolors(256 * 256)
               if rgba[3] == 255}
    assert (BLOCK in colours) == (name != "ship"), "the ship is a hull, the rest are blocks"


def test_a_rebuild_of_unchanged_sources_is_byte_identical(fmu_paths, tmp_path):
    first = build("ship", tmp_path / "a").read_bytes()
    assert build("ship", tmp_path / "b").read_bytes() == first == fmu_paths["ship"].read_bytes()


def test_an_fmu_built_by_another_version_is_not_current(fmu_paths):
    manifest = read(fmu_paths["ship"])
    assert staleness(manifest) is None
    assert staleness(replace(manifest, version="0.0.1")) == (
        f"it was built by fmukit 0.0.1, this is fmukit {PROJECT['version']} (rebuild it)")
    assert "built by fmukit of an older version" in staleness(replace(manifest, version=None))


def test_the_c_autopilot_describes_itself_too(c_autopilot):
    described = read_model_description(str(c_autopilot))
    assert described.version == PROJECT["version"]
    assert described.license == PROJECT["license"]["text"]
    assert described.generationTool == f"fmukit {PROJECT['version']} (fmubuild.cbuild)"
    page = _entry(c_autopilot, "documentation/index.html").decode()
    assert "only libc and libm" in page
    assert Image.open(io.BytesIO(_entry(c_autopilot, "model.png"))).size == (256, 256)
    assert validate_fmu(str(c_autopilot)) == []
