"""FMUs in processes of their own (issue 37, ``cosim.core.isolated``): whatever an isolated FMU
does (a segfault, an exit, an abort, a loop in Python, a wait in C, a kill from outside, memory
past its limit), the run ends at once with the rows of every complete step, its JSON names the
FMU, the call, the time and the cause, the status is 1 and no process is left running.

The fault FMU (``tests/faulty/fault_slave.py``) steers the ship and goes wrong at t = 5 s,
after 50 complete steps; it writes its process id to ``FAULT_HANG_MARKER`` as it does.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from cosim import scenarios
from cosim.core.isolation import Isolation
from cosim.core.master import Master
from cosim.core.ssd import read_ssd
from cosim.core.watchdog import Limits
from cosim.outputs import Options, run_and_write
from fmubuild.project import ROOT
from helpers import fault_system

PY = sys.executable
LIMIT = 120                      # seconds any child process here may take
FAULTS = {"none": 0, "loop": 6, "block": 7, "segv": 8, "exit": 9, "abort": 10, "memory": 11,
          "spawn": 12, "garble": 13}
CAUSES = {"segv": "its process was ended by signal SIGSEGV",
          "spawn": "its process was ended by signal SIGSEGV",      # and its sleep ended too
          "garble": "it garbled its reply (something in it wrote to the master's socket)",
          "exit": "its process exited with status 3",
          "abort": "its process was ended by signal SIGABRT",
          "loop": "killed when it did not end within the step time limit of 1 s",
          "block": "killed when it did not end within the step time limit of 1 s",
          "memory": "its memory limit of 1024 MiB"}


@pytest.fixture(scope="module")
def faulty(fmu_paths, tmp_path_factory, faulty_fmu) -> dict[str, Path]:
    """A system per fault: the ship steered by the fault FMU, which goes wrong at t = 5 s."""
    root, fault = tmp_path_factory.mktemp("faulty"), faulty_fmu("fault")
    return {kind: fault_system(root / f"{kind}.ssd", fault, fmu_paths["ship"], number, 20.0,
                               f"goes wrong: {kind}") for kind, number in FAULTS.items()}


@pytest.fixture
def marker(tmp_path, monkeypatch) -> Path:
    """Where the fault FMU writes its process id as it goes wrong (children inherit it)."""
    path = tmp_path / "fault.pid"
    monkeypatch.setenv("FAULT_HANG_MARKER", str(path))
    return path


def _running(marker: Path) -> list[int]:
    """The processes still running whose environment names ``marker`` (their own test's)."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdecimal() and str(marker).encode() in (entry / "environ"
                                                                    ).read_bytes():
                found.append(int(entry.name))
        except OSError:                      # ended meanwhile, or not ours to read
            pass
    return [pid for pid in found if pid != os.getpid()]


def _ended(out: Path, kind: str, marker: Path, cause: str) -> dict:
    """The run's JSON, once the run has ended with the rows of its 50 complete steps (more
    for memory, which grows past its limit a few steps later)."""
    meta = json.loads((out / f"{kind}.json").read_text())
    rows = meta["rows"]
    assert rows == 50 or kind == "memory" and 50 < rows < 100
    assert (out / f"{kind}.csv").read_text().count("\n") == rows + 1
    assert meta["failure"]["fmu"] == "fault" and meta["failure"]["time"] == rows / 10
    assert meta["failure"]["cause"] == cause
    assert meta["backends"]["fault"] == "fmi, isolated" and meta["backends"]["ship"] == "fmi"
    assert not _running(marker), "a process of the run is still running"
    return meta


@pytest.mark.parametrize("kind", ["segv", *(pytest.param(k, marks=pytest.mark.long)
                                           for k in ("exit", "abort")), "spawn", "garble",
                                  pytest.param("loop", marks=pytest.mark.long), "block",
                                  pytest.param("memory", marks=pytest.mark.long)])
def test_an_isolated_fmu_that_fails_ends_its_run_with_the_rows_and_the_cause(
        faulty, kind, marker, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "earlier.csv").write_text("earlier\n")
    options = Options(plot=False, limits=Limits(step=1.0),
                      isolation=Isolation(("fault",), 2**30))
    outcome = run_and_write(read_ssd(faulty[kind]), kind, out, options=options)
    assert outcome.status == 1
    meta = _ended(out, kind, marker, CAUSES[kind])
    assert meta["failure"]["call"] == "doStep"
    assert f"FMU 'fault': doStep at t = {meta['rows'] / 10:g} s returned" in meta["error"]
    assert (out / "earlier.csv").read_text() == "earlier\n"


def test_a_child_killed_from_outside_ends_its_run(faulty, marker, tmp_path):
    def kill_it() -> None:
        deadline = time.monotonic() + LIMIT
        while not marker.exists() or not marker.read_text():
            if time.monotonic() > deadline:
                return
            time.sleep(0.05)
        os.kill(int(marker.read_text()), signal.SIGKILL)
    killer = threading.Thread(target=kill_it)
    killer.start()
    outcome = run_and_write(read_ssd(faulty["block"]), "block", tmp_path,
                            options=Options(plot=False, isolation=Isolation(("fault",))))
    killer.join()
    assert outcome.status == 1
    _ended(tmp_path, "block", marker, "its process was ended by signal SIGKILL")


def _command(args: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([PY, "-m", "cosim.run", *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env={**os.environ, "PYTHONPATH": str(ROOT)})


def test_cosim_run_isolate_survives_a_segfault_and_says_where(faulty, marker, tmp_path):
    with _command([str(faulty["segv"]), "--isolate", "--out", str(tmp_path)], tmp_path) as run:
        _, stderr = run.communicate(timeout=LIMIT)
    assert run.returncode == 1, stderr
    assert "error: FMU 'fault': doStep at t = 5 s returned no reply: its process was ended " \
           "by signal SIGSEGV" in stderr
    assert "the 50 rows recorded before the error are in" in stderr
    meta = json.loads((tmp_path / "segv.json").read_text())
    assert meta["rows"] == 50 and meta["failure"]["cause"].endswith("SIGSEGV")
    assert set(meta["backends"].values()) == {"fmi, isolated"}
    assert not _running(marker)


@pytest.mark.parametrize("second", [pytest.param(False, marks=pytest.mark.long), True],
                         ids=["one-signal", "two-signals"])     # quick: the grace is tested
                                                                # in test_run_lifecycle
def test_ctrl_c_kills_a_hung_isolated_fmu_and_keeps_the_rows(faulty, marker, tmp_path, second):
    """One SIGINT: the step under way has its grace, then its child is killed; a second
    SIGINT kills it at once. Either way the run ends interrupted, its 50 rows written."""
    with _command([str(faulty["block"]), "--isolate", "fault", "--out", str(tmp_path)],
                  tmp_path) as run:
        deadline = time.monotonic() + LIMIT
        while not marker.exists() and run.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.2)
        sent = time.monotonic()
        run.send_signal(signal.SIGINT)
        if second:
            time.sleep(0.3)
            run.send_signal(signal.SIGINT)
        _, stderr = run.communicate(timeout=LIMIT)
    took = time.monotonic() - sent
    assert run.returncode == 130, stderr
    meta = json.loads((tmp_path / "block.json").read_text())
    assert meta["rows"] == 50
    assert meta["failure"]["cause"] == ("killed on a second SIGINT" if second else
                                        f"killed when it did not end within "
                                        f"{Limits().grace:g} s of SIGINT")
    if second:
        assert took < Limits().grace, f"took {took:.1f} s: the second signal waited"
    assert not _running(marker)


def test_a_sweep_records_a_crashed_run_as_failed_and_finishes_the_others(
        fmu_paths, tmp_path, faulty_fmu, marker):
    """A user's FMU runs isolated in sweeps by default: a segfault fails its run only."""
    from cosim.studies import campaign, sweep_task
    from cosim.studies.sweep_spec import Spec

    spec_path = tmp_path / "spec.toml"
    spec_path.write_text(f'stop_time = 10\n[controllers]\ncrash = {{ autopilot = '
                         f'"{faulty_fmu("idle_pilot")}" }}\n'
                         '[axes]\n"autopilot.crash_time" = [5.0, 1e9]\n')
    spec = Spec.read(spec_path)
    rows = [campaign.run_locally(spec, run) for run in spec.runs()]
    sweep_task.free_masters()
    assert [r["status"] for r in rows] == ["failed", "ok"]
    assert "doStep at t = 5 s returned no reply: its process was ended by signal SIGSEGV" \
        in rows[0]["error"]
    assert "isolated" in rows[0]["backend"]


@pytest.mark.parametrize("name", [
    "calm_pd", *(pytest.param(n, marks=pytest.mark.long) for n in scenarios.names()
                 if n != "calm_pd")])
def test_the_isolated_route_gives_the_fmi_route_s_bytes(fmu_paths, name, tmp_path):
    csv = {}
    for isolate in ("none", "all"):
        with Master(scenarios.load(name), isolation=Isolation(isolate)) as master:
            csv[isolate] = tmp_path / f"{isolate}.csv"
            recording = master.run()
            assert recording.error is None
            recording.write_csv(csv[isolate])
    assert csv["none"].read_bytes() == csv["all"].read_bytes()


def test_what_to_isolate_is_checked_before_anything_runs(tmp_path, capsys):
    from cosim import run as cli

    with pytest.raises(ValueError, match="isolate names pilot, which the system does not "
                                         "have; its components: guidance, autopilot, ship"):
        Master(scenarios.load("calm_pd"), isolation=Isolation(("pilot",)))
    for bad, said in ((["--isolate", ","], "expected all, none, foreign or component names"),
                      (["--memory-limit", "2G"], "--memory-limit limits the processes of "
                                                 "isolated FMUs; add --isolate"),
                      (["--isolate", "--memory-limit", "2X"], "expected a size such as 512M"),
                      (["--isolate", "--memory-limit", "1K"], "bytes from 1 MiB to 4 EiB, got 1024")):
        with pytest.raises(SystemExit):
            cli.main(["calm_pd", "--out", str(tmp_path), *bad])
        assert said in capsys.readouterr().err
    assert Isolation.of(True) == Isolation("all") and Isolation.of(None).chosen == "none"
    assert Isolation.of("autopilot, ship").chosen == ("autopilot", "ship")
    for which, limit, said in ((1, None, "expected all, none, foreign or component names"),
                               (True, 1.5e9, "a whole number of bytes"),
                               (True, "2G", "a whole number of bytes"),
                               (False, 2**30, "isolate some")):
        with pytest.raises(ValueError, match=said):
            Isolation.of(which, limit)


def test_a_sweep_refuses_an_fmu_to_isolate_that_a_controller_lacks(tmp_path, capsys):
    from cosim import sweep

    spec = tmp_path / "spec.toml"
    spec.write_text('stop_time = 5\n[controllers]\npd = "calm_pd"\n[axes]\nwave_seed = [1]\n')
    with pytest.raises(SystemExit):
        sweep.main([str(spec), "--isolate", "pilot", "--out", str(tmp_path / "out")])
    assert "controller 'pd': --isolate names pilot, which the system does not have" in \
        capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_child_dead_between_messages_fails_its_run_under_the_commands_sigpipe(fmu_paths):
    """The commands give SIGPIPE its default action (``cosim._cli.entry``): writing to a dead
    child must not end the master."""
    code = ("import os, signal, time\nfrom cosim import scenarios\n"
            "from cosim.core.isolation import Isolation\nfrom cosim.core.master import Master\n"
            "signal.signal(signal.SIGPIPE, signal.SIG_DFL)\n"
            "with Master(scenarios.load('calm_pd'), isolation=Isolation(('autopilot',))) as m:\n"
            "    child = m.instances['autopilot'].process\n"
            "    os.kill(child.pid, signal.SIGKILL)\n"
            "    child.wait()\n"
            "    print(m.run().error.splitlines()[0])\n")
    done = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=LIMIT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("FMU 'autopilot': ") and \
        done.stdout.rstrip().endswith("returned no reply: its process was ended by signal SIGKILL")


def test_without_isolation_a_crash_still_names_the_fmu_it_was_in(faulty, marker, tmp_path):
    """Issue 38: a segfault in an FMU in the master's process ended cosim.run silently; where
    the platform allows it, its traceback now names the FMU (``exchange_with_fault``)."""
    with _command([str(faulty["segv"]), "--out", str(tmp_path)], tmp_path) as run:
        _, stderr = run.communicate(timeout=LIMIT)
    assert run.returncode == -signal.SIGSEGV
    assert "Fatal Python error: Segmentation fault" in stderr
    assert "in exchange_with_fault" in stderr
