"""Archives from others unpacked only where they say (issue 38, kind 1): every route that
unpacks an FMU or an SSP package, or hands one to another tool, refuses a member that would
land outside its folder, a link, or a zip bomb, naming the file and the member, and writes
nothing."""
from __future__ import annotations

import stat
import zipfile
from pathlib import Path

import pytest

from cosim import scenarios
from cosim.core.archives import UnsafeArchive, check_archive, unpack
from cosim.core.master import Master
from cosim.interop.hosts import EngineError, run as run_engine
from cosim.interop.ssp import export


def _with_member(source: Path, target: Path, name: str, link: bool = False) -> Path:
    """A copy of the archive ``source`` with one more member ``name`` (a link if ``link``)."""
    with zipfile.ZipFile(source) as old, zipfile.ZipFile(target, "w") as new:
        for member in old.infolist():
            new.writestr(member, old.read(member))
        extra = zipfile.ZipInfo(name)
        if link:
            extra.external_attr = (stat.S_IFLNK | 0o777) << 16
        new.writestr(extra, "/etc/passwd" if link else "written where it should not be")
    return target


@pytest.mark.parametrize("name, link, said", [
    ("../escaped.txt", False, "would be written outside the folder it is unpacked into"),
    ("/tmp/escaped.txt", False, "would be written outside the folder it is unpacked into"),
    ("resources/link", True, "is a symbolic link")])
def test_an_fmu_that_would_write_outside_its_folder_is_refused(fmu_paths, tmp_path, name,
                                                               link, said):
    bad = _with_member(fmu_paths["pd_autopilot"], tmp_path / "pd_autopilot.fmu", name, link)
    system = scenarios.load("calm_pd", autopilot=bad)
    with pytest.raises(UnsafeArchive, match=f"{bad}: member {name!r} {said}; refused"):
        Master(system)
    assert not (tmp_path.parent / "escaped.txt").exists()
    assert not Path("/tmp/escaped.txt").exists()


def test_an_ssp_that_would_write_outside_is_refused_before_any_engine_unpacks_it(tmp_path):
    (tmp_path / "good").mkdir()
    package = export("calm_pd", tmp_path / "good")
    bad = _with_member(package, tmp_path / "bad.ssp", "../../escaped.txt")
    with pytest.raises(EngineError, match="member '../../escaped.txt' would be written outside"):
        run_engine("libcosim", bad)
    assert not list(tmp_path.parent.glob("escaped.txt"))


def test_a_zip_bomb_is_refused_and_a_failed_unpack_leaves_nothing(fmu_paths, tmp_path,
                                                                   monkeypatch):
    with pytest.raises(UnsafeArchive, match="unpacks to more than .* GiB .* refused as a zip "
                                            "bomb"):
        check_archive(fmu_paths["ship"], limit=1000)
    made = []
    real_mkdtemp = __import__("tempfile").mkdtemp

    def mkdtemp(**kwargs):
        made.append(real_mkdtemp(dir=tmp_path, **kwargs))
        return made[-1]

    def full(self, *args, **kwargs):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr("cosim.core.archives.tempfile.mkdtemp", mkdtemp)
    monkeypatch.setattr(zipfile.ZipFile, "extractall", full)
    with pytest.raises(OSError, match=f"cannot unpack {fmu_paths['ship']}: No space left"):
        unpack(fmu_paths["ship"])
    assert made and not Path(made[0]).exists()


def test_export_refuses_to_package_an_fmu_that_would_write_outside(fmu_paths, tmp_path, capsys):
    from cosim.export import main as export_main
    bad = _with_member(fmu_paths["pd_autopilot"], tmp_path / "mine.fmu", "../escaped.txt")
    assert export_main(["calm_pd", "--autopilot", str(bad), "--out", str(tmp_path / "out")]) == 2
    assert "member '../escaped.txt' would be written outside" in capsys.readouterr().err
    assert not list((tmp_path / "out").iterdir())
