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

from fmukit.manifest import read, staleness
from fmubuild.packaging import build
from fmubuild.project import FMUS, ROOT

PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
BLOCK = (0xdd, 0xe8, 0xf4)
"""The fill of a block icon (fmubuild.documentation)."""
BUILT_WITH = {2: "pythonfmu 0.7.0", 3: "pythonfmu3 0.3.4"}
PLATFORMS = {2: ("linux64", "win64"), 3: ("x86_64-linux", "x86_64-windows")}
"""What builds each FMI version, and the platforms of its binaries."""


@pytest.fixture(params=[2, 3], ids=["fmi2", "fmi3"])
def fmi(request) -> int:
    return request.param


@pytest.fixture
def built(fmi, request) -> dict[str, Path]:
    """This project's FMUs of the version ``fmi``: FMI 2.0's, or their FMI 3.0 twins."""
    return request.getfixturevalue("fmu_paths" if fmi == 2 else "fmi3_paths")


def _entry(fmu: Path, name: str) -> bytes:
    with zipfile.ZipFile(fmu) as package:
        return package.read(name)


@pytest.mark.parametrize("name", list(FMUS))
def test_each_fmu_declares_the_projects_version_license_and_fmukit(built, fmi, name):
    described = read_model_description(str(built[name]))
    assert described.version == PROJECT["version"] == metadata.version(PROJECT["name"])
    assert described.license == PROJECT["license"]["text"]
    assert described.author and described.copyright.startswith("Copyright")
    assert described.generationTool == f"fmukit {PROJECT['version']} ({BUILT_WITH[fmi]})"
    assert validate_fmu(str(built[name])) == []


@pytest.mark.parametrize("name", list(FMUS))
def test_the_documentation_lists_every_variable_with_its_unit(built, fmi, name):
    page = _entry(built[name], "documentation/index.html").decode()
    root = fromstring(page)                       # well-formed, so no tag is left open
    assert not re.search(r"\b(src|href)=", page), "the page loads nothing from outside"
    rows = {"".join(tr[0].itertext()): [("".join(td.itertext())) for td in tr]
            for tr in root.iter("tr") if tr[0].tag == "td"}
    described = read_model_description(str(built[name]))
    for variable in described.modelVariables:
        if variable.causality == "independent":        # FMI 3.0's time: no port
            assert variable.name not in rows
            continue
        row = rows[variable.name]
        assert row[1] == variable.type, variable.name
        assert row[2].split(" (shown in ")[0] == (variable.unit or ""), variable.name
        assert row[-1] == (variable.description or ""), variable.name
        if variable.causality == "parameter":
            assert row[3] == str(variable.start), variable.name
    text = "".join(root.itertext())
    assert described.description in text and f"FMI{described.fmiVersion}, co-simulation" in text
    for platform in PLATFORMS[fmi]:
        assert f"{platform}: " in text and "numpy" in text
    assert "LD_PRELOAD" in text


def test_the_documentation_cites_the_paper_and_the_equations_of_what_the_fmu_carries(fmu_paths):
    page = _entry(fmu_paths["ship"], "documentation/index.html").decode()
    assert "Tomera, M. (2010)" in page and "Fossen" in page
    for module, equations in (("hull", "eqs (1)-(6)"), ("thrusters", "eqs (8)-(13)"),
                              ("waves", "eqs (14)-(17)")):
        assert f"<code>ship_fmu.{module}</code>: " in page and equations in page


@pytest.mark.parametrize("name", list(FMUS))
def test_the_documentations_worked_example_runs(built, tmp_path, name):
    page = _entry(built[name], "documentation/index.html").decode()
    command = re.search(r"<pre>(fmpy simulate .*?)</pre>", page).group(1).split()
    assert command[:3] == ["fmpy", "simulate", f"{name}.fmu"] and "--start-values" in command
    (tmp_path / f"{name}.fmu").write_bytes(built[name].read_bytes())
    fmpy = Path(sys.executable).with_name("fmpy")
    subprocess.run([str(fmpy), *command[1:]], cwd=tmp_path, check=True, capture_output=True,
                   timeout=300)
    header, *rows = (tmp_path / f"{name}.csv").read_text().splitlines()
    stop = command[command.index("--stop-time") + 1]
    outputs = [v.name for v in read_model_description(str(built[name])).modelVariables
               if v.causality == "output"]
    assert header.replace('"', "").split(",") == ["time", *outputs]
    assert rows[-1].startswith(f"{stop},")


@pytest.mark.parametrize("name", list(FMUS))
def test_the_icon_is_a_png_drawn_from_the_model(built, name):
    icon = Image.open(io.BytesIO(_entry(built[name], "model.png")))
    assert icon.format == "PNG" and icon.size == (256, 256)
    colours = {rgba[:3] for _, rgba in icon.convert("RGBA").getcolors(256 * 256)
               if rgba[3] == 255}
    assert (BLOCK in colours) == (name != "ship"), "the ship is a hull, the rest are blocks"


def test_a_rebuild_of_unchanged_sources_is_byte_identical(built, fmi, tmp_path):
    first = build("ship", tmp_path / "a", fmi).read_bytes()
    assert build("ship", tmp_path / "b", fmi).read_bytes() == first == built["ship"].read_bytes()


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
