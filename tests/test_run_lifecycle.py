"""A run ends in one of two ways: complete outputs, or a non-zero exit that says why and
leaves the earlier results as they were (issue 25: nothing lost, nothing hangs).

The hung FMUs are the fault FMU of the fault matrix (``tests/faulty/fault_slave.py``)
looping in Python ('loop') or waiting in C ('block') from t = 5 s; every child process
here has a time limit of its own. The quick suite sends each hang one of the two signals
(SIGINT to the loop, SIGTERM to the block); ``pytest --long`` sends both to both.
"""
from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cosim import run as cli
from cosim.core.files import FolderLock, Outputs, OutputError, whole_file
from cosim.core.interrupt import StopSignals
from cosim.core.watchdog import Limits, Watchdog
from fmubuild.project import ROOT
from helpers import fault_system, reference_seconds

PY = sys.executable
LIMIT = 120                      # seconds any child process here may take
KINDS = {"none": 0, "loop": 6, "block": 7}


@pytest.fixture(scope="module")
def reference(tmp_path_factory, fmu_paths) -> float:
    """Seconds a plain short run takes in a child here now (``helpers.reference_seconds``)."""
    return reference_seconds(tmp_path_factory.mktemp("reference"))


@pytest.fixture(scope="module")
def hung(fmu_paths, tmp_path_factory, faulty_fmu) -> dict[str, Path]:
    """A system per kind: the ship steered by the fault FMU, which hangs from t = 5 s."""
    root, fault = tmp_path_factory.mktemp("hung"), faulty_fmu("fault")
    return {kind: fault_system(root / f"{kind}.ssd", fault, fmu_paths["ship"], number, 1000.0,
                               f"hangs: {kind}") for kind, number in KINDS.items()}


def _run(args: list[str], cwd: Path, **popen) -> subprocess.CompletedProcess:
    popen.setdefault("env", {**os.environ, "PYTHONPATH": str(ROOT)})
    return subprocess.run([PY, "-m", "cosim.run", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=LIMIT, **popen)


def _folder(path: Path) -> dict[str, bytes]:
    """Every file in a folder, hidden ones included, by name (a folder reads b"/")."""
    return {p.name: b"/" if p.is_dir() else p.read_bytes()
            for p in path.iterdir()} if path.exists() else {}


def _errors(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("error:")]


@pytest.fixture(scope="module")
def good(tmp_path_factory, fmu_paths) -> Path:
    """A folder holding a good calm_pd run (no figure), and a file of the user's beside it."""
    out = tmp_path_factory.mktemp("good")
    assert cli.main(["calm_pd", "--out", str(out), "--no-plot", "--backend", "inprocess"]) == 0
    (out / "calm_pd.orig.csv").write_text("the user's own file\n")
    return out


def test_a_refused_command_keeps_the_previous_results(good, capsys):
    before = _folder(good)
    assert cli.main(["calm_pd", "--out", str(good), "--stop-time", "400.05"]) == 2
    assert "400.05" in capsys.readouterr().err
    assert _folder(good) == before


def test_a_new_run_replaces_only_its_own_files_by_exact_name(good, tmp_path):
    out = tmp_path / "out[1]*"                 # glob characters in the folder's name
    out.mkdir()
    for name in ("calm_pd.orig.csv", "calm_pd.gif", "calm_pd[x].csv", "calm_pd.csv"):
        (out / name).write_text("old\n")
    assert cli.main(["calm_pd", "--out", str(out), "--no-plot", "--backend", "inprocess",
                     "--stop-time", "10"]) == 0
    files = _folder(out)
    assert sorted(files) == ["calm_pd.csv", "calm_pd.json", "calm_pd.orig.csv", "calm_pd[x].csv"]
    assert files["calm_pd.csv"].count(b"\n") == 102       # header and 101 rows, not "old"


def test_a_second_writer_of_one_folder_is_refused(tmp_path, capsys):
    with FolderLock(tmp_path):
        assert cli.main(["calm_pd", "--out", str(tmp_path), "--stop-time", "1"]) == 2
    assert "being written by another command" in capsys.readouterr().err
    assert _folder(tmp_path) == {}


def _file_size_limit(size: int):
    def limit() -> None:                # a full disk, as the process sees it
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))
    return limit


@pytest.mark.parametrize("stream", [False, True], ids=["in-memory", "stream"])
def test_a_full_disk_says_which_file_and_keeps_the_previous_results(good, stream, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    for name, data in _folder(good).items():
        (out / name).write_bytes(data)
    before = _folder(out)
    result = _run(["calm_pd", "--out", str(out), "--backend", "inprocess",
                   *(["--stream"] if stream else [])], tmp_path,
                  preexec_fn=_file_size_limit(300_000))
    assert result.returncode == 1, result.stderr
    assert _errors(result.stderr) == [f"error: cannot write {out / 'calm_pd.csv'}: File too "
                                      f"large (a limit on file size); the earlier files in "
                                      f"{out} are kept"]
    assert "Traceback" not in result.stderr
    assert _folder(out) == before


def test_an_export_on_a_full_disk_leaves_no_package(tmp_path):
    result = subprocess.run([PY, "-m", "cosim.export", "calm_pd", "--out", str(tmp_path)],
                            capture_output=True, text=True, timeout=LIMIT, cwd=ROOT,
                            preexec_fn=_file_size_limit(300_000))
    assert result.returncode == 1
    assert _errors(result.stderr) == [f"error: cannot write {tmp_path / 'calm_pd.ssp'}: File "
                                      "too large (a limit on file size); no calm_pd.ssp was "
                                      "written"]
    assert _folder(tmp_path) == {}


def test_whole_file_and_outputs_leave_nothing_when_interrupted(tmp_path):
    target = tmp_path / "x.ssp"
    target.write_text("old")
    with pytest.raises(KeyboardInterrupt), whole_file(target) as partial:
        partial.write_text("half")
        raise KeyboardInterrupt
    (tmp_path / "x.csv").write_text("old")
    with pytest.raises(KeyboardInterrupt), Outputs(tmp_path, [tmp_path / "x.csv"]) as outputs:
        (outputs.stage / "x.csv").write_text("new")
        raise KeyboardInterrupt
    assert _folder(tmp_path) == {"x.ssp": b"old", "x.csv": b"old"}
    with pytest.raises(OutputError, match=f"cannot write {tmp_path / 'x.json'}"), \
            Outputs(tmp_path) as outputs, outputs.writing("x.json"):
        raise OSError(28, "No space left on device")
    assert _folder(tmp_path) == {"x.ssp": b"old", "x.csv": b"old"}


def test_a_run_s_files_are_replaced_together_or_not_at_all(tmp_path, monkeypatch):
    """Issue 38: the JSON could not be put in place (an immutable file, a permission) after the
    CSV was: the folder held the new CSV beside the old JSON."""
    from cosim.core import files

    for name in ("x.csv", "x.json", "mine.txt"):
        (tmp_path / name).write_text(f"old {name}")
    before, replace = _folder(tmp_path), os.replace

    def refuse_json(source, target):             # as for an immutable x.json
        if Path(source) == tmp_path / "x.json":
            raise PermissionError(1, "Operation not permitted", str(source))
        replace(source, target)
    monkeypatch.setattr(files.os, "replace", refuse_json)
    with pytest.raises(OutputError, match=f"cannot write {tmp_path / 'x.json'}: Operation not "
                                          f"permitted; the earlier files in {tmp_path} are as"):
        with Outputs(tmp_path, [tmp_path / "x.csv", tmp_path / "x.json"], "x") as outputs:
            for name in ("x.csv", "x.json"):
                with outputs.writing(name) as path:
                    path.write_text(f"new {name}")
    assert _folder(tmp_path) == before
    monkeypatch.setattr(files.os, "replace", replace)
    with Outputs(tmp_path, [tmp_path / "x.csv", tmp_path / "x.json"], "x") as outputs:
        for name in ("x.csv", "x.json"):
            with outputs.writing(name) as path:
                path.write_text(f"new {name}")
    assert _folder(tmp_path) == {**before, "x.csv": b"new x.csv", "x.json": b"new x.json"}
    before = _folder(tmp_path)

    def refuse_to_x_json(source, target):       # set aside, then neither placed nor put back
        if Path(target) == tmp_path / "x.json":
            raise PermissionError(1, "Operation not permitted", str(target))
        replace(source, target)
    monkeypatch.setattr(files.os, "replace", refuse_to_x_json)
    with pytest.raises(OutputError, match="the earlier files it could not put back are in "):
        with Outputs(tmp_path, [], "x") as outputs, outputs.writing("x.json") as path:
            path.write_text("newer")
    kept = next(tmp_path.glob("earlier-*"))
    assert (kept / "x.json").read_bytes() == before["x.json"]      # nothing lost


@pytest.mark.parametrize("kind, backend", [    # quick: each kind and each backend once
    ("loop", "fmi"), ("block", "inprocess"), pytest.param("block", "fmi", marks=pytest.mark.long),
    pytest.param("loop", "inprocess", marks=pytest.mark.long)])
def test_a_hung_fmu_ends_at_the_step_time_limit_with_its_rows(hung, kind, backend, tmp_path,
                                                               reference):
    started = time.monotonic()
    result = _run([str(hung[kind]), "--out", str(tmp_path), "--backend", backend,
                   "--step-timeout", "1"], tmp_path)
    took = time.monotonic() - started
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr
    expected = ("error: the step at t = 5 s did not end within the step time limit of 1 s "
                "(in FMU 'fault')")
    assert _errors(result.stderr)[0].startswith(expected), result.stderr
    meta = json.loads((tmp_path / f"{kind}.json").read_text())
    assert meta["rows"] == 50 and "step time limit of 1 s" in meta["error"]
    assert (tmp_path / f"{kind}.csv").read_text().count("\n") == 51
    assert sorted(_folder(tmp_path)) == [f"{kind}.csv", f"{kind}.json"]
    assert took < 1 + 5 * reference, f"took {took:.1f} s, a plain run {reference:.1f} s"


@pytest.mark.parametrize("kind, number", [
    pytest.param(kind, number, id=f"{kind}-{number.name}",
                 marks=() if (kind == "loop") == (number == signal.SIGINT) else pytest.mark.long)
    for kind in ("loop", "block") for number in (signal.SIGINT, signal.SIGTERM)])
def test_a_signal_stops_a_hung_fmu_within_its_grace(hung, kind, number, tmp_path, reference):
    with subprocess.Popen([PY, "-m", "cosim.run", str(hung[kind]), "--out", str(tmp_path)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          cwd=tmp_path, start_new_session=True, env=_hang_env(tmp_path)) as child:
        _await_hang(child, tmp_path)
        sent = time.monotonic()
        child.send_signal(number)
        _, stderr = child.communicate(timeout=LIMIT)
    took = time.monotonic() - sent
    assert child.returncode == 128 + number, stderr
    assert took < 3 * Limits().grace + 2 * reference, f"took {took:.1f} s"
    assert f"within {Limits().grace:g} s of {number.name}" in stderr
    assert json.loads((tmp_path / f"{kind}.json").read_text())["rows"] == 50


def _hang_env(out: Path) -> dict[str, str]:
    """The environment of a child whose fault FMU marks its hang (``faulty/fault_slave.py``)."""
    return {**os.environ, "FAULT_HANG_MARKER": str(out.parent / f"{out.name}.hung")}


def _await_hang(child: subprocess.Popen, out: Path) -> None:
    """Until the fault FMU has begun to hang (at t = 5 s, 50 steps in), and a little more."""
    marker = out.parent / f"{out.name}.hung"
    deadline = time.monotonic() + LIMIT
    while time.monotonic() < deadline and child.poll() is None:
        if marker.exists():
            time.sleep(0.2)
            return
        time.sleep(0.05)
    pytest.fail("the run did not reach its hang")


def test_a_second_signal_ends_the_run_at_once_keeping_the_earlier_results(hung, tmp_path):
    (tmp_path / "block.csv").write_text("earlier\n")
    with subprocess.Popen([PY, "-m", "cosim.run", str(hung["block"]), "--out", str(tmp_path)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          cwd=tmp_path, start_new_session=True, env=_hang_env(tmp_path)) as child:
        _await_hang(child, tmp_path)
        child.send_signal(signal.SIGINT)
        time.sleep(0.3)
        child.send_signal(signal.SIGINT)
        _, stderr = child.communicate(timeout=LIMIT)
    assert child.returncode == 130
    assert "did not end within" not in stderr          # it did not wait out the grace
    assert "SIGINT again: stopped at once; the earlier outputs of block" in stderr
    assert _folder(tmp_path) == {"block.csv": b"earlier\n"}


@pytest.mark.parametrize("first", ["raised", "between steps"])
def test_a_second_signal_while_the_first_is_handled_ends_the_command_at_once(first):
    """The second Ctrl-C may fall anywhere after the first (here: while a command keeps what it
    did, in a weakref callback as the garbage collector runs): one line, no traceback."""
    catch = ("with StopSignals() as stop:\n        os.kill(os.getpid(), signal.SIGINT)\n"
             "    stop.check()" if first == "between steps" else
             "os.kill(os.getpid(), signal.SIGINT)\n    time.sleep(5)")
    code = ("import gc, os, signal, sys, time, weakref\n"
            "from cosim._cli import entry\nfrom cosim.core.interrupt import Interrupted, "
            "StopSignals\nclass Kept: pass\n"
            "def main():\n  try:\n    " + catch + "\n  except Interrupted:\n"
            "    kept = Kept()\n    weakref.finalize(kept, os.kill, os.getpid(), signal.SIGINT)\n"
            "    del kept\n    gc.collect()\n    time.sleep(5)\n    print('not ended')\n"
            "  return 0\nsys.exit(entry(main))\n")
    done = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=60)
    assert (done.returncode, done.stdout, done.stderr) == (130, "",
                                                           "SIGINT again: stopped at once\n")


def test_the_run_time_limit_keeps_the_rows(tmp_path, capsys):
    assert cli.main(["calm_pd", "--out", str(tmp_path), "--backend", "inprocess",
                     "--stop-time", "100000", "--stream", "--run-timeout", "1"]) == 1
    err = capsys.readouterr().err
    assert "the run did not end within its time limit of 1 s" in err
    meta = json.loads((tmp_path / "calm_pd.json").read_text())
    rows = (tmp_path / "calm_pd.csv").read_text().count("\n") - 1
    assert 100 < rows == meta["rows"] < 1_000_001


def test_a_signal_after_the_last_step_leaves_complete_outputs(tmp_path, capsys, monkeypatch):
    """SIGTERM as the last step is recorded: the outputs are written whole, then the
    status says the command was signalled."""
    class Bar:                      # the progress bar, which hears each 100th step and the last
        n = total = 0

        def __init__(self, **options):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc_info):
            pass

        def update(self, steps: int) -> None:
            self.n += steps
            if self.n == self.total:
                os.kill(os.getpid(), signal.SIGTERM)
    monkeypatch.setattr(cli, "tqdm", Bar)
    assert cli.main(["calm_pd", "--out", str(tmp_path), "--backend", "inprocess"]) == 143
    assert "interrupted by SIGTERM after the last step" in capsys.readouterr().err
    assert sorted(_folder(tmp_path)) == ["calm_pd.csv", "calm_pd.json", "calm_pd.png"]
    assert json.loads((tmp_path / "calm_pd.json").read_text())["rows"] == 4001


def test_limits_are_positive_numbers():
    for bad in (Limits(step=0), Limits(run=-1), Limits(step=float("inf")),
                Limits(grace=float("nan"))):
        with pytest.raises(ValueError, match="time limit must be a positive number"):
            Watchdog(bad)
    assert Limits().step is not None           # the default catches a hung FMU
    for bad in ("0", "-1", "inf", "nan", "x"):
        with pytest.raises(SystemExit):
            cli.main(["calm_pd", "--step-timeout", bad])


def test_a_watchdog_without_signals_leaves_the_handlers_alone():
    before = signal.getsignal(signal.SIGINT)
    with StopSignals() as stop, Watchdog(Limits(), stop):
        assert signal.getsignal(signal.SIGINT) is not before
    assert signal.getsignal(signal.SIGINT) is before
    with Watchdog(Limits(step=None)):
        assert signal.getsignal(signal.SIGINT) is before


def test_a_sweep_records_a_hung_run_as_failed_and_goes_on(fmu_paths, tmp_path, reference,
                                                          faulty_fmu):
    """A run whose autopilot loops in its step fails at the step time limit, saying so;
    the worker (here, this process) is free for the next run."""
    from cosim.studies import campaign, sweep_task
    from cosim.studies.sweep_spec import Spec

    pilot = faulty_fmu("idle_pilot")
    spec_path = tmp_path / "spec.toml"
    spec_path.write_text(f'stop_time = 10\n[controllers]\nidle = {{ autopilot = "{pilot}" }}\n'
                         '[axes]\n"autopilot.hang_time" = [5.0, 1e9]\n')
    spec = Spec.read(spec_path)
    started = time.monotonic()
    rows = [campaign.run_locally(spec, run, limits=Limits(step=4)) for run in spec.runs()]
    sweep_task.free_masters()
    assert [r["status"] for r in rows] == ["failed", "ok"], [r["error"] for r in rows]
    assert rows[0]["error"].startswith(            # a user's FMU: isolated, by default
        "FMU 'autopilot': doStep at t = 5 s returned no reply: killed when it did not end "
        "within the step time limit of 4 s")
    assert time.monotonic() - started < 4 + 10 * reference   # two runs, each its own child


def test_names_that_would_write_outside_the_folder_are_refused(tmp_path, capsys):
    for name in ("../x", "/abs", "a/b", ".hidden", ""):
        with pytest.raises(SystemExit) as refused:
            cli.main(["waves_pd", "--autopilot", "fmus/pid_autopilot.fmu", "--name", name,
                      "--out", str(tmp_path / "out")])
        assert refused.value.code == 2
        assert "must be one plain file name" in capsys.readouterr().err
    assert not (tmp_path / "out").exists() and not (tmp_path / "x.csv").exists()


def test_an_output_folder_that_cannot_be_made_is_a_refusal(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    with pytest.raises(SystemExit) as refused:
        cli.main(["calm_pd", "--out", str(tmp_path / "file" / "out")])
    assert refused.value.code == 2
    assert capsys.readouterr().err.startswith(f"error: output folder {tmp_path / 'file'}")


def test_a_killed_run_s_stage_is_removed_by_the_next_run_of_its_label(tmp_path):
    for name in (".partial-calm_pd-abcd1234", ".partial-calm_pd-PID-abcd1234"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "calm_pd.csv").write_text("half")
    assert cli.main(["calm_pd", "--out", str(tmp_path), "--no-plot", "--backend", "inprocess",
                     "--stop-time", "1"]) == 0
    assert sorted(_folder(tmp_path)) == [".partial-calm_pd-PID-abcd1234", "calm_pd.csv",
                                         "calm_pd.json"]       # another label's is its own


def test_an_error_reading_another_file_is_not_called_a_failed_write(tmp_path):
    with pytest.raises(FileNotFoundError), whole_file(tmp_path / "x.ssp"):
        (tmp_path / "missing.fmu").read_bytes()
    with pytest.raises(FileNotFoundError), Outputs(tmp_path) as outputs, \
            outputs.writing("x.csv"):
        (tmp_path / "missing.csv").read_bytes()
    assert _folder(tmp_path) == {}


def test_a_run_that_fails_before_its_first_row_keeps_the_earlier_results(good, capsys):
    before = _folder(good)
    assert cli.main(["calm_pd", "--out", str(good), "--backend", "inprocess",
                     "--set", "guidance.waypoints=0,0;30,0;x"]) == 1
    err = capsys.readouterr()
    assert "route '0,0;30,0;x' m" in err.out            # described as given, no traceback
    assert "point 2 is 'x'" in err.err and "nothing was written" in err.err
    assert _folder(good) == before


@pytest.mark.parametrize("limit", ["1e-6", "1e-3"])
def test_an_absurdly_short_step_limit_ends_the_run_with_a_message(tmp_path, limit):
    result = _run(["calm_pd", "--out", str(tmp_path), "--backend", "inprocess",
                   "--step-timeout", limit, "--no-plot"], tmp_path)
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert f"within the step time limit of {float(limit):g} s" in result.stderr


def test_a_file_is_not_written_over_a_device_or_a_folder_or_into_a_missing_one(tmp_path):
    (tmp_path / "folder").mkdir()
    for target, said in ((tmp_path / "folder", "is not a regular file"),
                         (Path("/dev/null"), "is not a regular file"),
                         (tmp_path / "missing" / "x.npz", "No such file")):
        with pytest.raises(OutputError, match=said), whole_file(target) as partial:
            partial.write_text("x")
    assert Path("/dev/null").is_char_device() and (tmp_path / "folder").is_dir()


def test_the_scorecard_refuses_settings_that_would_make_it_unfair(tmp_path, capsys):
    from cosim import score
    for argv, said in ((["--set", "ship.Hs=0.01"], "would change only your runs' conditions"),
                       (["--seeds", "1000000000"], "--seeds must be from 1 to"),
                       (["--workers", "0"], "argument --workers: give a whole number >= 1, "
                                            "got '0'")):
        with pytest.raises(SystemExit) as refused:
            score.main(["fmus/pid_autopilot.fmu", "--out", str(tmp_path), *argv])
        assert refused.value.code == 2 and said in capsys.readouterr().err


def test_a_scheduler_file_that_is_not_small_and_regular_is_refused():
    from cosim.studies.cluster import ClusterError, scheduler_address
    with pytest.raises(ClusterError, match="not a regular file"):
        scheduler_address("/dev/zero")


@pytest.mark.parametrize("argv, said", [
    (["--stop-time", "5_0"], "expected a finite number, got '5_0'"),
    (["--stop-time", "inf"], "expected a finite number"),
    (["--step-timeout", "inf"], "expected a finite number"),
])
def test_numbers_on_the_command_line_are_read_strictly(argv, said, capsys):
    with pytest.raises(SystemExit) as refused:
        cli.main(["calm_pd", *argv])
    assert refused.value.code == 2 and said in capsys.readouterr().err


def test_a_stop_time_past_exact_nanoseconds_says_so(tmp_path, capsys):
    assert cli.main(["calm_pd", "--stop-time", "1e14", "--out", str(tmp_path)]) == 2
    assert "beyond 9.007e+06 s (2^53 ns, 104 days)" in capsys.readouterr().err


def test_an_ssd_time_beyond_what_an_fmu_takes_is_refused_by_name(tmp_path):
    from cosim import scenarios
    from cosim.core.ssd import read_ssd
    path = tmp_path / "far.ssd"
    path.write_text(scenarios.path("calm_pd").read_text().replace('stopTime="400.0"',
                                                                   'stopTime="1e300"'))
    with pytest.raises(ValueError, match=r"far.ssd: DefaultExperiment: stop time 1e\+300 s is "
                                         r"not a finite time within \+-1e\+15 s"):
        read_ssd(path)


def test_an_absolute_fmu_source_that_is_missing_is_not_replaced_by_one_of_its_name(tmp_path):
    from cosim import scenarios
    from cosim.core.ssd import read_ssd
    path = tmp_path / "mine.ssd"
    path.write_text(scenarios.path("calm_pd").read_text().replace(
        'source="../../fmus/pd_autopilot.fmu"', 'source="/home/me/mine/pd_autopilot.fmu"'))
    system = read_ssd(path)
    assert system.components["autopilot"].source == "/home/me/mine/pd_autopilot.fmu"
    with pytest.raises(FileNotFoundError, match="tried /home/me/mine/pd_autopilot.fmu;"):
        system.fmu_path("autopilot")


@pytest.mark.parametrize("backend", ["inprocess", pytest.param("fmi", marks=pytest.mark.long)])
def test_an_fmu_that_hangs_in_terminate_keeps_the_finished_run(fmu_paths, tmp_path, backend,
                                                               faulty_fmu):
    """Nothing is raised into fmi2Terminate (an exception there has no safe way out of
    pythonfmu); past the step limit the finished run's files are written and the process
    ends, saying so."""
    pilot = faulty_fmu("idle_pilot")
    result = _run(["calm_pd", "--autopilot", str(pilot), "--set", "autopilot.hang_terminate=1",
                   "--stop-time", "10", "--step-timeout", "1", "--backend", backend,
                   "--out", str(tmp_path / "out"), "--no-plot"], tmp_path,
                  env={**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(
                      ROOT / "tests" / "faulty")])})
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert ("terminating and freeing the FMUs did not end within the step time limit of 1 s "
            "(in FMU 'autopilot')") in result.stderr
    assert "ending the process" in result.stderr
    out = tmp_path / "out"
    assert sorted(_folder(out)) == ["calm_pd-idle_pilot.csv", "calm_pd-idle_pilot.json"]
    assert json.loads((out / "calm_pd-idle_pilot.json").read_text())["rows"] == 101


def test_a_thread_an_fmu_leaves_running_does_not_keep_the_command_alive(tmp_path, faulty_fmu):
    """Issue 38: an FMU's thread that is not a daemon kept cosim.run alive after its outputs
    were written; now the command says so and ends with its status."""
    pilot = faulty_fmu("idle_pilot")
    result = _run(["calm_pd", "--autopilot", str(pilot), "--set", "autopilot.linger_time=1",
                   "--stop-time", "3", "--no-plot", "--out", str(tmp_path / "out")], tmp_path,
                  env={**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(
                      ROOT / "tests" / "faulty")])})
    assert result.returncode == 0, result.stderr
    assert "note: threads still running after the command (lingerer), started by an FMU" in \
        result.stderr
    assert json.loads((tmp_path / "out" / "calm_pd-idle_pilot.json").read_text())["rows"] == 31


def test_steps_each_shorter_than_the_limit_never_expire_it():
    """The watchdog waited until the deadline of the step it saw and then judged that one:
    a step begun meanwhile was flagged at once (0.1 s steps under a 1 s limit: a step would
    have to take ten times as long on a busy machine to expire it)."""
    watchdog = Watchdog(Limits(step=1.0))
    with watchdog:
        for k in range(15):
            watchdog.beat(float(k))
            time.sleep(0.1)
    assert watchdog.expired is None


def test_a_run_named_after_a_file_that_is_no_plain_name_is_refused(tmp_path, capsys):
    """Issue 38: a scenario file named '...ssd', run without --out, wrote into the checkout
    root (its label '..'); exported, it raised a raw OSError."""
    from cosim import export

    odd = tmp_path / "...ssd"
    odd.write_bytes((ROOT / "cosim" / "scenarios" / "calm_pd.ssd").read_bytes())
    with pytest.raises(SystemExit):
        cli.main([str(odd)])
    assert "error: the run's name from ...ssd (rename the file) = '..': a name in the output " \
           "folder must be one plain file name" in capsys.readouterr().err
    assert export.main([str(odd), "--out", str(tmp_path / "out")]) != 0
    assert "the run's name from ...ssd" in capsys.readouterr().err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
