"""Sweeps under hostile input: every bad spec, option, cache or trial ends in one clear
message naming the input, before anything runs, with no partial output file.

The quick suite (without ``pytest --long``) interrupts the stage after the runs in one of
the three places only (writing the tables): the other two are the same path to the same
message, with another stage's name."""
from __future__ import annotations

import errno
import functools
import os
import re
import shlex
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

import cosim.scenarios.autopilot as autopilot
from cosim import scenarios
from cosim.core.ssd import write_ssd
from cosim.studies import campaign, sweep_task
from cosim.studies.merit import METRICS
from cosim.studies.sweep_spec import Spec
from cosim.studies.sweep_task import UnsafeCache, file_hash, fmu_cache
from cosim.studies.cluster import ClusterError, SweepError, connect, local_cluster, local_workers
from fmubuild.instantiate import InstantiationFailed, instantiate_in_child
from cosim import sweep as sweep_command
from helpers import command, reference_seconds


@pytest.mark.timeout(60, method="thread")
def test_a_trial_that_runs_out_of_time_names_the_fmu_and_the_limit(fmu_paths, monkeypatch):
    fmu = fmu_paths["pd_autopilot"]
    said = f"{fmu}: instantiating the FMU did not end within 0.01 s (the child was killed)"
    with pytest.raises(InstantiationFailed, match=re.escape(said)):
        instantiate_in_child(fmu, timeout=0.01)            # no Python starts in 10 ms
    # checking a user's autopilot: the same words, as the contract's refusal
    monkeypatch.setattr(autopilot, "instantiate_in_child",
                        functools.partial(instantiate_in_child, timeout=0.01))
    with pytest.raises(autopilot.AutopilotError, match=re.escape(said)):
        autopilot.check_autopilot(fmu, trial=True)


# -- the spec: what would run something other than the file says ------------------------
def spec_file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, said", [
    # one parameter set twice: by two axes, or by an axis and a controller's set
    ('[axes]\nwave_seed = [1]\n"ship.wave_seed" = [2]',
     "axis 'wave_seed' and axis 'ship.wave_seed' both set ship.wave_seed; give it one place"),
    ("[axes]\nsea_state = [2]\nHs = [0.01]", "axis 'sea_state' and axis 'Hs' both set ship.Hs"),
    ('[axes]\n"ship.T0" = [1.0]\nsea_state = [2]',
     "axis 'ship.T0' and axis 'sea_state' both set ship.T0"),
    ('[controllers]\npd = { scenario = "waves_pd", set = { "ship.Hs" = 0.01 } }\n'
     "[axes]\nsea_state = [2]", "axis 'sea_state' and controller 'pd' both set ship.Hs; give "
                                 "it one place"),
    # a value twice in one axis, as the FMU receives it
    ("[axes]\nwave_seed = [1, 1, 2]", "axis 'wave_seed' has 1 twice"),
    ('[axes]\n"ship.delta_rate_max" = [1, 1.0]',
     "axis 'ship.delta_rate_max' has 1 and 1.0, one value for the FMU"),
    ("[axes]\nHs = [0.01, 1e-2]", "axis 'Hs' has 0.01 twice"),
    ("[axes]\nsea_state = [3, 3]", "axis 'sea_state' has 3 twice"),
    # values the parameter does not take (cosim.core.values), or not of its TOML kind
    ("[axes]\nwave_seed = [4294967297]", "axis 'wave_seed': ship.wave_seed = 4294967297 is "
                                         "outside the range of an FMI Integer \\(32 bits\\)"),
    ("[axes]\nwave_seed = { start = 2147483647, count = 2 }",
     "axis 'wave_seed': ship.wave_seed = 2147483648 is outside the range of an FMI Integer"),
    ('[controllers]\npd = { scenario = "waves_pd", set = { "ship.wave_seed" = -2147483649 } }',
     "controller 'pd' set 'ship.wave_seed': ship.wave_seed = -2147483649 is outside the range"),
    ("[axes]\nwave_seed = [-1]", "axis 'wave_seed': ship.wave_seed = -1 is outside its declared "
                                 "range; ship.wave_seed is an Integer, a whole number from 0"),
    ("[axes]\nHs = [-1.0]", "axis 'Hs': ship.Hs = -1.0 is outside its declared range; ship.Hs "
                            "is a finite Real, from 0.0 to 0.1"),
    ("[axes]\nHs = [nan]", "axis 'Hs': ship.Hs = nan is not a number \\(NaN\\)"),
    ("[axes]\npsi_w = [-inf]", "axis 'psi_w': ship.psi_w = -inf is not finite"),
    ('[axes]\nroute = ["0,0;10,0\\u0000"]', "axis 'route': guidance.waypoints = '0,0;10,0\\\\x00' "
                                             "holds a NUL character"),
    ("[axes]\nwave_seed = [1.5]", "axis 'wave_seed' = 1.5: give an integer \\(ship.wave_seed is "
                                  "an FMI Integer\\)"),
    ("[axes]\nwave_seed = [true]", "axis 'wave_seed' = True: give an integer \\(ship.wave_seed "
                                   "is an FMI Integer\\)"),
    ('[axes]\nHs = ["0.01"]', "axis 'Hs' = '0.01': give a number \\(ship.Hs is an FMI Real\\)"),
    ("[axes]\nHs = [[0.01]]", "axis 'Hs' = \\[0.01\\]: give a number \\(ship.Hs is an FMI "
                              "Real\\)"),
    ("[axes]\nroute = [1]", "axis 'route' = 1: give a string \\(guidance.waypoints is an FMI "
                            "String\\)"),
    ("[axes]\nsea_state = [true]", "axis 'sea_state' has True: give WMO codes"),
    ("[axes]\nsea_state = [2.0]", "axis 'sea_state' has 2.0: give WMO codes"),
    # what the systems do not have
    ('[axes]\n"ship.nope" = [1.0]', "axis 'ship.nope' sets ship.nope, but in controller 'pd' "
                                    "ship \\(ship.fmu\\) has no parameter 'nope'; it has x0"),
    ('[axes]\n"ship.psi" = [1.0]', "axis 'ship.psi' .* has no parameter 'psi'"),   # an output
    ('[axes]\n"rudder.x" = [1.0]', "axis 'rudder.x' sets rudder.x, but in controller 'pd' "
                                    "there is no component 'rudder' \\(there are guidance"),
    ("[axes]\nship.Hs = [0.01]", "axis 'ship' is neither .* quote the key: \"ship.Hs\""),
    ('[controllers]\npd = { scenario = "waves_pd", set = { autopilot.Kp = 2.0 } }',
     "controller 'pd' set 'autopilot' = {'Kp': 2.0}: give component.variable = value"),
    # malformed tables and keys
    ("stop_time = inf", "stop_time = inf: give a number of seconds > 0"),
    ("[controllers]", "\\[controllers\\] is empty"),
    ("[controllers]\npd = { scenario = 3 }", "controller 'pd' scenario = 3: give a string"),
    ('[controllers]\npd = { scenario = "waves_pd", set = [1] }',
     "controller 'pd' set = \\[1\\]: give a table"),
    ('[controllers]\npd = { autopilot = "x.fmu", map = { psi = 1 } }',
     "controller 'pd' map 'psi' = 1: give the FMU's name"),
    ("[plots]\nmap = [{ a = 1 }]", "\\[plots\\] map = \\[{'a': 1}\\]: give two different axes"),
    ("[axes]\nHs = [0.01]\n[plots]\nmap = ['Hs', 'Hs']",
     "\\[plots\\] map = \\['Hs', 'Hs'\\]: give two different axes"),
    ("[plots]\nmaps = []", "\\[plots\\] has unknown key maps; it has map, tracks"),
    ("[axes]\nwave_seed = [1, 2]\n[plots]\ntracks = { wave_seed = true }",
     "\\[plots\\] tracks selects wave_seed = True"),
    # a name that would write outside the output folder, or oddly in it
    ('name = "../../x"', "name = '../../x': a name in the output folder must be one plain file"),
    ('name = "/abs/x"', "name = '/abs/x'"),
    ('name = "a/b"', "name = 'a/b'"),
    ('name = "a\\\\b"', "name = 'a\\\\\\\\b'"),
    ('name = ""', "name = ''"),
    ('name = ".."', "name = '..'"),
    ('name = "a\\u0000b"', "name = 'a\\\\x00b'"),
    ('name = "x\\n"', "name = 'x\\\\n'"),
    ("name = 3", "name = 3"),
    ('[controllers]\n"../evil" = "waves_pd"', "controller '../evil' = '../evil': a name in the "
                                              "output folder"),
])
def test_a_spec_that_would_run_something_else_is_refused_by_file_and_key(tmp_path, text, said):
    path = spec_file(tmp_path, text)
    with pytest.raises(ValueError, match=f"^{re.escape(str(path))}: {said}"):
        Spec.read(path)


def test_a_sweep_is_counted_before_it_is_listed(tmp_path):
    """A range of 2^62 values is refused at once, without a list of them; so is a product
    of axes beyond max_runs, with the count."""
    path = spec_file(tmp_path, "[axes]\nwave_seed = { start = 1, count = 1000 }")
    started = time.perf_counter()
    Spec.read(path, max_runs=2000)                  # a reference: a spec of 2,000 runs, read
    reference = time.perf_counter() - started
    path = spec_file(tmp_path, "[axes]\nwave_seed = { start = 1, count = 4611686018427387904 }")
    started = time.perf_counter()
    with pytest.raises(ValueError, match="4611686018427387904 values, more than the 100000 runs "
                                         "a sweep may have \\(cosim.sweep --max-runs\\)"):
        Spec.read(path)
    assert time.perf_counter() - started < 10 * reference     # not a list of 2^62 values
    path = spec_file(tmp_path, "[axes]\nwave_seed = { start = 1, count = 300 }\n"
                               "psi_w = { start = 0, count = 3 }")
    with pytest.raises(ValueError, match=re.escape(
            f"{path}: 2 controllers x 300 wave_seed x 3 psi_w = 1800 runs, more than the 1000")):
        Spec.read(path, max_runs=1000)
    assert len(Spec.read(path, max_runs=1800).runs()) == 1800


def test_the_command_refuses_a_bad_spec_with_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "out"
    for text, said in [('name = "../escaped"\n', "name = '../escaped'"),
                       ("[axes]\nwave_seed = [1, 1]\n", "axis 'wave_seed' has 1 twice"),
                       ("[axes]\nwave_seed = { start = 1, count = 60 }\n",
                        "2 controllers x 60 wave_seed = 120 runs, more than the 100")]:
        child = command(sweep_command.main, str(spec_file(tmp_path, text)), "--out", str(out),
                        "--max-runs", "100")
        assert child.returncode == 2 and child.stdout == "", child
        assert child.stderr.startswith(f"error: {tmp_path / 'spec.toml'}: {said}"), child.stderr
        assert len(child.stderr.splitlines()) == 1 and "Traceback" not in child.stderr
    assert not out.exists() and not (tmp_path / "escaped").exists()


# -- cluster options: a clear error, never a hang ---------------------------------------
@pytest.mark.timeout(30, method="thread")
def test_a_scheduler_file_that_is_missing_empty_or_malformed_is_named(tmp_path):
    missing = tmp_path / "sched.json"
    with pytest.raises(ClusterError, match=f"scheduler file {missing} does not exist"):
        connect(scheduler_file=str(missing))          # Dask's own client waits for ever
    for content, said in [("", "is not a Dask scheduler file"), ("[1]", "is not a Dask"),
                          ('{"address": 3}', "names no scheduler address"),
                          ('{"id": "x"}', "names no scheduler address")]:
        missing.write_text(content)
        with pytest.raises(ClusterError, match=re.escape(f"scheduler file {missing} {said}")):
            connect(scheduler_file=str(missing))


@pytest.mark.timeout(120, method="thread")
def test_an_unreachable_or_malformed_scheduler_address_is_named_within_the_timeout(tmp_path,
                                                                                    fmu_paths):
    reference = reference_seconds(tmp_path / "reference")     # a child's start, run, exit
    started = time.perf_counter()
    with pytest.raises(ClusterError, match="cannot reach the Dask scheduler at "
                                           "tcp://127.0.0.1:9 \\(from --scheduler\\) within 1 s"):
        connect("tcp://127.0.0.1:9", timeout=1)
    assert time.perf_counter() - started < 1 + 5 * reference
    with pytest.raises(ClusterError, match="'nowhere' \\(from --scheduler\\) is not a Dask "
                                           "scheduler address"):
        connect("nowhere", timeout=1)
    (tmp_path / "sched.json").write_text('{"address": "tcp://127.0.0.1:9"}')
    with pytest.raises(ClusterError, match=f"from scheduler file {tmp_path / 'sched.json'}"):
        connect(scheduler_file=str(tmp_path / "sched.json"), timeout=1)


def test_a_worker_count_past_the_cores_is_capped(capsys):
    from dask.system import CPU_COUNT

    assert local_workers(None) is None and local_workers(1) == 1
    assert capsys.readouterr().err == ""
    assert local_workers(10 ** 6) == CPU_COUNT
    assert capsys.readouterr().err.startswith(
        f"note: --workers 1000000: this machine gives this process {CPU_COUNT} cores")


@pytest.mark.timeout(60, method="thread")
def test_the_command_ends_bad_cluster_options_in_one_line(tmp_path):
    """What the command says, in this process (a test of messages, not of processes)."""
    spec = spec_file(tmp_path, "stop_time = 5\n[axes]\nwave_seed = [1]\n")
    for options, said in [(["--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "1"],
                           "error: cannot reach the Dask scheduler at tcp://127.0.0.1:9"),
                          (["--scheduler-file", str(tmp_path / "none.json")],
                           f"error: scheduler file {tmp_path / 'none.json'} does not exist"),
                          (["--workers", "0"], "argument --workers: give a whole number >= 1"),
                          (["--max-runs", "-1"], "argument --max-runs: give a whole number")]:
        child = command(sweep_command.main, str(spec), "--out", str(tmp_path / "out"), *options)
        assert child.returncode == 2 and said in child.stderr, child
        assert "Traceback" not in child.stderr
    assert not list((tmp_path / "out").rglob("*.*"))         # no file of any kind


# -- the workers' FMU cache: private, and checked when used ------------------------------
def test_the_fmu_cache_is_a_private_folder_of_this_user(tmp_path, monkeypatch):
    monkeypatch.delenv("COSIM_FMU_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    folder = fmu_cache()
    assert folder == tmp_path / "cache" / "cosim-fmus"
    assert stat.S_IMODE(folder.stat().st_mode) & 0o077 == 0
    folder.chmod(0o777)                     # anyone may plant an FMU there
    with pytest.raises(UnsafeCache, match=f"the FMU cache {folder} may be written by others "
                                          "\\(mode drwxrwxrwx\\)"):
        fmu_cache()
    folder.chmod(0o700)
    real = os.getuid()
    monkeypatch.setattr(os, "getuid", lambda: real + 1)
    with pytest.raises(UnsafeCache, match=f"{folder} belongs to another user \\(uid {real}\\)"):
        fmu_cache()
    monkeypatch.undo()
    elsewhere = tmp_path / "link"
    elsewhere.symlink_to(folder)
    monkeypatch.setenv("COSIM_FMU_CACHE", str(elsewhere))
    with pytest.raises(UnsafeCache, match=f"{elsewhere} is not a folder"):
        fmu_cache()


def test_a_corrupt_cached_fmu_is_written_again_and_said_to_be_the_cache(
        fmu_paths, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("COSIM_FMU_CACHE", str(tmp_path / "cache"))
    spec = Spec.read(spec_file(tmp_path, "stop_time = 2\n[controllers]\npd = 'waves_pd'\n"
                                               "[axes]\nwave_seed = [1]\n"))
    ship = next(sha for sha, path in spec.files().items() if path.name == "ship.fmu")
    cached = fmu_cache() / f"{ship}.fmu"
    cached.write_bytes(b"PK\x03\x04 not an FMU")          # a crash while it was written, say
    row = campaign.run_locally(spec, spec.runs()[0])
    assert row["status"] == "ok", row["error"]
    assert f"the FMU cache's {cached} does not match its hash" in capsys.readouterr().err
    assert cached.read_bytes() == spec.files()[ship].read_bytes()
    sweep_task.free_masters()


@pytest.mark.timeout(90, method="thread")
def test_a_sweep_on_workers_with_an_unsafe_cache_is_refused_before_any_run(
        fmu_paths, tmp_path, monkeypatch):
    cache = tmp_path / "shared"
    cache.mkdir()
    cache.chmod(0o777)
    monkeypatch.setenv("COSIM_FMU_CACHE", str(cache))     # the local cluster's workers inherit it
    spec = Spec.read(spec_file(tmp_path, "stop_time = 2\n[axes]\nwave_seed = [1]\n"))
    (tmp_path / "out").mkdir()
    with pytest.raises(SweepError, match=f"workers whose FMU cache is not safe to run FMUs "
                                               f"from:\n  tcp://.*: the FMU cache {cache} may be "
                                               "written by others"):
        campaign.execute(spec, tmp_path / "out", workers=1, progress=False)
    assert not (tmp_path / "out" / "runs.jsonl").exists() and not list(cache.iterdir())


# -- outputs: whole or not at all ------------------------------------------------------
def _rows(spec) -> list[dict]:
    return [{**run, "status": "ok", "error": "", **{m: 1.0 + i for m in METRICS},
             "seconds": 0.1, "sim_seconds": 0.1, "backend": "fmi"}
            for i, run in enumerate(spec.runs())]


def test_a_figure_that_cannot_be_written_leaves_the_old_one(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    from cosim.core.files import OutputError
    from cosim.studies.sweep_figures import save_figures

    spec = Spec.read(spec_file(tmp_path, "[axes]\nwave_seed = [1, 2]\n"))
    old = tmp_path / "J_distribution.png"
    old.write_bytes(b"the previous sweep's figure")

    def disk_full(self, target, **options):
        Path(target).write_bytes(b"\x89PNG half")
        raise OSError(errno.ENOSPC, "No space left on device")
    monkeypatch.setattr(Figure, "savefig", disk_full)
    with pytest.raises(OutputError, match=f"cannot write {old}: No space left on device"):
        save_figures(spec, _rows(spec), tmp_path)
    assert old.read_bytes() == b"the previous sweep's figure"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["J_distribution.png", "spec.toml"]


def test_a_comparison_that_cannot_be_written_leaves_the_old_one(tmp_path, monkeypatch, capsys):
    from cosim import sweep as command

    spec_path = spec_file(tmp_path, 'name = "full"\n[axes]\nwave_seed = [1, 2]\n')
    out = tmp_path / "out" / "full"
    out.mkdir(parents=True)
    (out / "comparison.md").write_text("the previous comparison\n")
    monkeypatch.setattr(command.campaign, "execute",
                        lambda spec, *args, **options: _rows(spec))
    write_text = Path.write_text

    def disk_full(self, text, *args, **options):
        if self.suffix == ".md":
            write_text(self, text[:10])
            raise OSError(errno.ENOSPC, "No space left on device")
        return write_text(self, text, *args, **options)
    monkeypatch.setattr(Path, "write_text", disk_full)
    assert command.main([str(spec_path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"error: cannot write {out / 'comparison.md'}: No space left on device" in err
    assert f"every row is kept in {out / 'runs.jsonl'}" in err
    monkeypatch.undo()
    assert (out / "comparison.md").read_text() == "the previous comparison\n"
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


# -- a rebuild of unchanged sources reruns nothing --------------------------------------
@pytest.mark.long     # the quick suite resumes sweeps in test_sweep.py
@pytest.mark.timeout(120, method="thread")
def test_a_finished_sweep_resumed_after_a_rebuild_reruns_nothing(fmu_paths, tmp_path, capsys,
                                                                  scheduler):
    """The FMUs are built into a folder of the test's, the sweep runs on waves_pd pointed at
    them, they are built again from the same sources, and the sweep is resumed."""
    built = tmp_path / "fmus"

    def build() -> dict[str, str]:
        subprocess.run([sys.executable, "-m", "fmukit.build", "ship", "pd_autopilot",
                        "guidance", "--out", str(built)],
                       check=True, capture_output=True, timeout=100)
        return {p.name: file_hash(p) for p in built.glob("*.fmu")}

    before = build()
    system = scenarios.load("waves_pd")
    for component in system.components.values():
        component.source = str(built / Path(component.source).name)
    write_ssd(system, tmp_path / "rebuilt.ssd")
    spec = Spec.read(spec_file(tmp_path, "stop_time = 2\n[controllers]\n"
                                               "pd = 'rebuilt.ssd'\n[axes]\nwave_seed = [1, 2]\n"))
    assert set(spec.files().values()) == {built / name for name in before}
    out = tmp_path / "out"
    out.mkdir()
    rows = campaign.execute(spec, out, scheduler, progress=False)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    journal = (out / "runs.jsonl").read_text()
    assert build() == before                                   # the same bytes
    capsys.readouterr()
    again = campaign.execute(Spec.read(tmp_path / "spec.toml"), out, scheduler,
                             progress=False)
    assert "2 of 2 runs already done" in capsys.readouterr().err
    assert (out / "runs.jsonl").read_text() == journal and again == rows


@pytest.mark.parametrize("make, said", [
    (lambda tmp: tmp / "none.toml", "no such file"),
    (lambda tmp: tmp, "not a regular file"),
    (lambda tmp: Path("/dev/zero"), "not a regular file"),      # read, it would never end
    (lambda tmp: _written(tmp / "big.toml", b"#" * (17 << 20)), "more than 16 MiB"),
    (lambda tmp: _written(tmp / "latin1.toml", b'name = "\xe9t\xe9"'), "can't decode byte"),
])
def test_a_spec_that_is_not_a_small_text_file_is_not_read(tmp_path, make, said):
    path = make(tmp_path)
    with pytest.raises(ValueError, match=f"^cannot read sweep spec {re.escape(str(path))}: .*"
                                         f"{said}"):
        Spec.read(path)


def _written(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def test_a_controller_whose_runs_cannot_be_measured_is_refused(tmp_path):
    path = spec_file(tmp_path, '[controllers]\nturn = "turning_circle"\n')
    with pytest.raises(ValueError, match=re.escape(
            f"{path}: controller 'turn': its system 'turning_circle' has no output "
            "guidance.psi_d, guidance.wp_index; a run is measured by guidance.psi_d, "
            "guidance.wp_index, ship.psi")):
        Spec.read(path)


# -- Ctrl-C: one message, at whatever stage, with the command that resumes ----------------
STOPPED = re.compile(r"^interrupted by SIGINT(?P<stage> while [a-z. ]+)?: (?P<done>\d+) of "
                     r"(?P<runs>\d+) runs done, kept in (?P<journal>\S+/runs.jsonl)"
                     r"(?P<tables>(, \S+)*); this command (?P<then>[^:]+): (?P<resume>.+)$")


def _sweep_child(tmp_path: Path, spec: Path, code: str | None = None) -> subprocess.Popen:
    """The sweep command in a session of its own, as a terminal's foreground job: a signal
    to its process group reaches the local cluster's workers too (``code``: the command's
    module patched, then run)."""
    options = [str(spec), "--out", str(tmp_path / "out"), "--workers", "2", "--no-progress"]
    launch = ["-m", "cosim.sweep"] if code is None else ["-c", code]
    return subprocess.Popen([sys.executable, *launch, *options], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def _resumed(line: str, journal: Path, runs: int) -> str:
    """Run the command an interrupted sweep printed; what it said on standard error."""
    resume = shlex.split(STOPPED.match(line)["resume"])
    assert resume[:3] == [sys.executable, "-m", "cosim.sweep"]
    child = subprocess.run(resume, capture_output=True, text=True, timeout=240)
    assert child.returncode == 0, child.stderr
    assert len(journal.read_text().splitlines()) == runs           # nothing run twice
    return child.stderr


@pytest.mark.timeout(300, method="thread")
def test_ctrl_c_during_the_runs_prints_one_line_that_says_how_to_resume(fmu_paths, tmp_path):
    """SIGINT to the whole process group, as a terminal's Ctrl-C: the workers, which would
    each print a traceback, do not take it; the client stops, says what it keeps and
    removes its lock."""
    spec = spec_file(tmp_path, 'name = "stopped"\nstop_time = 400\n[axes]\n'
                               'wave_seed = [1, 2, 3, 4]\nsea_state = [2]\n')
    journal = tmp_path / "out" / "stopped" / "runs.jsonl"
    with _sweep_child(tmp_path, spec) as child:
        deadline = time.monotonic() + 120
        while child.poll() is None and time.monotonic() < deadline and not (
                journal.exists() and journal.read_text().strip()):
            time.sleep(0.05)
        os.killpg(child.pid, signal.SIGINT)
        _, stderr = child.communicate(timeout=60)
    assert child.returncode == 130, stderr
    (line,) = stderr.splitlines()
    said = STOPPED.match(line)
    assert said and said["stage"] is None and said["then"] == "resumes the sweep", line
    done = int(said["done"])
    assert 1 <= done < 8 == int(said["runs"])
    assert len(journal.read_text().splitlines()) == done
    assert said["tables"].endswith("results.json, " + str(journal.parent / "summary.csv"))
    assert [p.name for p in journal.parent.iterdir() if p.name.startswith(("runs.jsonl.",
                                                                          "."))] == []
    assert f"{done} of 8 runs already done" in _resumed(line, journal, 8)


@pytest.mark.timeout(300, method="thread")
@pytest.mark.parametrize("module, step, stage", [
    ("cosim.sweep", "write_tables", "writing the tables"),
    pytest.param("cosim.studies.sweep_figures", "save_figures", "drawing the figures",
                 marks=pytest.mark.long),
    pytest.param("cosim.sweep", "write_comparison", "writing comparison.md",
                 marks=pytest.mark.long)])
def test_ctrl_c_after_the_runs_says_they_are_kept_and_how_to_finish(fmu_paths, tmp_path, module,
                                                                   step, stage):
    """The stage is made to take the signal: it signals its own process, then waits."""
    spec = spec_file(tmp_path, 'name = "late"\nstop_time = 5\n[axes]\nwave_seed = [1]\n')
    code = ("import os, signal, sys, time\nimport cosim.sweep as command\n"
            f"import {module} as stage\nfrom cosim._cli import entry\n"
            f"def {step}(*args, **kwargs):\n    os.kill(os.getpid(), signal.SIGINT)\n"
            f"    time.sleep(60)\nstage.{step} = {step}\nsys.exit(entry(command.main))\n")
    with _sweep_child(tmp_path, spec, code) as child:
        _, stderr = child.communicate(timeout=240)
    assert child.returncode == 130, stderr
    (line,) = stderr.splitlines()
    said = STOPPED.match(line)
    assert said and said["stage"] == f" while {stage}", line
    assert (said["done"], said["runs"], said["tables"]) == ("2", "2", "")
    assert said["then"] == "runs nothing again, and writes the tables and figures"
    journal = tmp_path / "out" / "late" / "runs.jsonl"
    assert "2 of 2 runs already done" in _resumed(line, journal, 2)
    assert {"results.parquet", "summary.csv", "comparison.md", "J_distribution.png"} <= {
        p.name for p in journal.parent.iterdir()}


@pytest.mark.timeout(300, method="thread")
def test_a_second_ctrl_c_ends_the_sweep_at_once_without_a_traceback(fmu_paths, tmp_path):
    """Wherever the second signal falls (while the cluster closes, while the tables are
    written, as the process ends), one or two lines and no traceback."""
    spec = spec_file(tmp_path, 'name = "twice"\nstop_time = 400\n[axes]\n'
                               'wave_seed = [1, 2, 3, 4]\nsea_state = [2]\n')
    journal = tmp_path / "out" / "twice" / "runs.jsonl"
    with _sweep_child(tmp_path, spec) as child:
        deadline = time.monotonic() + 120
        while child.poll() is None and time.monotonic() < deadline and not journal.exists():
            time.sleep(0.05)
        os.killpg(child.pid, signal.SIGINT)
        time.sleep(0.3)
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGINT)
        _, stderr = child.communicate(timeout=60)
    # 130, or ended by the signal itself once Python has begun to shut down (a shell says 130)
    assert child.returncode in (130, -signal.SIGINT), stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    lines = stderr.splitlines()
    assert 1 <= len(lines) <= 2 and all(line.startswith(("interrupted by SIGINT",
                                                         "SIGINT again: stopped at once"))
                                        for line in lines), stderr


@pytest.mark.timeout(60, method="thread")
def test_the_workers_of_a_local_cluster_never_take_sigint():
    """Blocked in each worker process, so that Ctrl-C at a terminal reaches the client alone;
    the client's own main thread still takes it."""
    from dask.distributed import Client

    def blocked() -> bool:
        mask = open("/proc/self/status").read().split("SigBlk:")[1].split()[0]
        return bool(int(mask, 16) & (1 << (signal.SIGINT - 1)))

    cluster = local_cluster(2)
    try:
        with Client(cluster) as client:
            assert list(client.run(blocked).values()) == [True, True]
        assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    finally:
        cluster.close()
