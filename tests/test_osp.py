"""OSP's OspSystemStructure.xml beside each package: libcosim runs it to the same bits as the .ssp."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cosim.interop.hosts import run
from cosim.interop.ssp import OSP_FILE, read_osp
from cosim.interop.ssp import described, export

NAMES = ["calm_pd", "waves_smc", "turning_circle"]


@pytest.fixture(scope="module")
def packages(fmu_paths, tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("ssp")
    return {name: export(name, out) for name in NAMES}


@pytest.mark.parametrize("name", [NAMES[0], *(pytest.param(n, marks=pytest.mark.long)
                                              for n in NAMES[1:])])   # quick: calm_pd
def test_libcosim_runs_the_osp_file_to_the_same_bits_as_the_package(packages, name):
    ssp = packages[name]
    folder = ssp.with_suffix("")
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        [OSP_FILE, *{Path(c.source).name for c in described(ssp)[0].components.values()}])
    from_ssp = run("libcosim", ssp)
    for osp in (folder, folder / OSP_FILE):           # the folder, as OSP's tools take it
        from_osp = run("libcosim", osp)
        assert from_osp.keys() == from_ssp.keys()
        assert all(np.array_equal(from_osp[k], from_ssp[k]) for k in from_ssp)


@pytest.mark.parametrize("name", NAMES)
def test_the_osp_file_holds_what_the_ssd_does(packages, name):
    ssd, osp = described(packages[name])[0], read_osp(packages[name].with_suffix(""))
    assert (osp.start_time, osp.stop_time, osp.step_size) == (ssd.start_time, ssd.stop_time,
                                                             ssd.step_size)
    assert osp.connections == ssd.connections
    assert {c: comp.parameters for c, comp in osp.components.items()} == {
        c: comp.parameters for c, comp in ssd.components.items()}
    text = (packages[name].with_suffix("") / OSP_FILE).read_text()
    assert text.count('stepSize="0.1"') == len(ssd.components)


def test_engines_that_read_only_ssp_refuse_the_osp_folder(packages):
    with pytest.raises(ValueError, match="ecos reads SSP packages, not OSP's"):
        run("ecos", packages["calm_pd"].with_suffix(""))
