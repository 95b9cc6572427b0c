"""`uitamr verify --trace` (with `--html` or not) does not hold the run's frames: the run is
judged as it goes and writes each frame's trace line to a file beside the trace as the
line settles it (verifier/verify/report_trace.py), and the trace is completed from that
file at the end. The trace file is the same, byte for byte, as the one written from a run
that held every frame: on every bundled scenario, on the library broken to break each
rule, and on random scenarios; and no spool file is left behind, whatever happens."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from click.testing import CliRunner

from test_idle_skip import robot_scenarios
from test_verify_pipeline import VARIANTS, broken_scenario
from verifier.commands.verify import command
from verifier.verify import report_trace
from verifier.verify import runner as runner_module
from verifier.verify import stream as stream_module
from verifier.verify.result import KEEP_ALL, Keep
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario, parse_scenario
import procs

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))


def _traces(scenario, folder: Path, monkeypatch, every_us: int = 0, compact_at: int = 2) -> tuple[bytes, bytes]:
    """The trace of the run holding its frames and of the run spooling them."""
    monkeypatch.setattr(stream_module, "COMPACT_AT", compact_at)
    monkeypatch.setattr(runner_module, "STREAM_EVERY_US", every_us)  # 0: every virtual second
    held = run_scenario(scenario, keep=KEEP_ALL)
    spooled = run_scenario(scenario, keep=Keep(frames=True, details=False, frames_to_file=str(folder)))
    assert spooled.trace == [] and held.trace_file is None
    assert Path(spooled.trace_file).parent == folder
    assert (spooled.tx_count, spooled.rx_count) == (held.tx_count, held.rx_count)
    assert spooled.violations == held.violations and spooled.expectations == held.expectations
    report_trace.write([held], folder / "held.jsonl")
    report_trace.write([spooled], folder / "spooled.jsonl")
    Path(spooled.trace_file).unlink()
    return (folder / "held.jsonl").read_bytes(), (folder / "spooled.jsonl").read_bytes()


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bundled_scenarios_give_the_same_trace(path, tmp_path, monkeypatch):
    held, spooled = _traces(load_scenario(path), tmp_path, monkeypatch)
    assert spooled == held and held.count(b"\n") > 10


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_broken_libraries_give_the_same_trace_and_blame(tmp_path, monkeypatch, variant):
    """The frames each broken rule blames are marked in the spooled trace as in the held one."""
    held, spooled = _traces(*broken_scenario(tmp_path, variant), monkeypatch)
    assert spooled == held and b'"rules": ["UITAMR-' in held


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=robot_scenarios(), every_s=st.sampled_from([0, 1, 3]), compact_at=st.sampled_from([1, 2, 1024]))
def test_random_scenarios_give_the_same_trace(text, every_s, compact_at, tmp_path_factory, monkeypatch):
    folder = tmp_path_factory.mktemp("spool")
    scenario = parse_scenario(text, ROOT / "plc" / "scenarios" / "random.toml")
    held, spooled = _traces(scenario, folder, monkeypatch, every_s * 1_000_000, compact_at)
    assert spooled == held


def _invoke(*args):
    return CliRunner().invoke(command, [str(a) for a in args], catch_exceptions=False)


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_the_command_leaves_no_spool_file(tmp_path, jobs):
    scenarios = [ROOT / "plc" / "scenarios" / f"{name}.toml" for name in ("fx3u-healthy", "q-bad-crc")]
    args = [arg for path in scenarios for arg in ("--scenario", path)]
    result = _invoke(*args, "--jobs", jobs, "--trace", tmp_path / "t.jsonl", "--duration", "5s")
    assert result.exit_code == 1, result.output  # q-bad-crc fails: the report is still written
    lines = (tmp_path / "t.jsonl").read_text(encoding="utf-8").splitlines()
    assert {'"scenario": "FX3U' in line or '"scenario": "Q' in line for line in lines} == {True}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.jsonl"]


def test_a_run_that_cannot_go_on_leaves_no_spool_file(tmp_path):
    """The second scenario names a label its program lacks: the command exits 2, and the
    trace lines the first run wrote are removed with it."""
    bad = tmp_path / "bad.toml"
    text = (ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8")
    bad.write_text(text.replace('"../', f'"{(ROOT / "plc").as_posix()}/').replace(
        'watch = ["fbEngine.o_wTxCount", "fbCycle.o_wPoint"]', 'watch = ["fbEngine.o_wNoSuchLabel"]'), encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    result = _invoke("--scenario", ROOT / "plc" / "scenarios" / "q-healthy.toml", "--scenario", bad,
                     "--trace", out / "t.jsonl", "--duration", "3s")
    assert result.exit_code == 2 and "o_wNoSuchLabel" in result.output
    assert list(out.iterdir()) == []


REPORTS = [("--trace", "t.jsonl", "trace"), ("--html", "r.html", "HTML report")]  # both spool the frames


@pytest.mark.parametrize("option, name, report", REPORTS)
def test_a_folder_the_report_cannot_go_to_is_said_before_the_run(tmp_path, monkeypatch, option, name, report):
    def refused(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    from verifier.verify import spool as spool_module

    monkeypatch.setattr(spool_module.tempfile, "mkdtemp", refused)
    result = _invoke("--scenario", ROOT / "plc" / "scenarios" / "fx3u-healthy.toml", option, tmp_path / name)
    assert result.exit_code == 2
    assert result.output == f"error: cannot write the {report} in {tmp_path}: Permission denied\n"
    assert list(tmp_path.iterdir()) == []


def test_a_spool_file_that_cannot_be_made_names_its_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(stream_module.tempfile, "mkstemp", lambda *a, **k: (_ for _ in ()).throw(
        PermissionError(13, "Permission denied")))
    result = _invoke("--scenario", ROOT / "plc" / "scenarios" / "fx3u-healthy.toml", "--trace", tmp_path / "t.jsonl")
    assert result.exit_code == 2
    assert f"cannot write the run's frames in {tmp_path}/.uitamr-trace-" in result.output and "Permission denied" in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("option, name, report", REPORTS)
def test_a_disk_that_fills_up_during_the_run_is_said_and_the_spool_removed(tmp_path, monkeypatch, option, name,
                                                                           report):
    original = stream_module.Stream._give

    def full(self, frames):
        if self.spool is not None and self.tx_count > 20:
            raise OSError(28, "No space left on device")
        return original(self, frames)

    monkeypatch.setattr(stream_module.Stream, "_give", full)
    result = _invoke("--scenario", ROOT / "plc" / "scenarios" / "fx3u-healthy.toml", option, tmp_path / name)
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert f"cannot write the run's frames in {tmp_path}/.uitamr-trace-" in result.output
    assert "No space left on device" in result.output
    assert list(tmp_path.iterdir()) == []


def test_a_worker_batch_that_cannot_go_on_leaves_no_spool_file(tmp_path):
    """With --jobs, a batch whose second scenario is unusable loses the first one's result
    in the worker: its trace lines go with the command's spool folder all the same."""
    text = (ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8")
    text = text.replace('"../', f'"{(ROOT / "plc").as_posix()}/')
    good, bad = tmp_path / "good.toml", tmp_path / "bad.toml"
    good.write_text(text.replace('duration = "60s"', 'duration = "3s"'), encoding="utf-8")
    bad.write_text(text.replace('watch = ["fbEngine.o_wTxCount", "fbCycle.o_wPoint"]',
                                'watch = ["fbEngine.o_wNoSuchLabel"]'), encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    result = _invoke("--scenario", good, "--scenario", bad, "--scenario", ROOT / "plc" / "scenarios" / "q-healthy.toml",
                     "--jobs", "2", "--trace", out / "t.jsonl")
    assert result.exit_code == 2 and "o_wNoSuchLabel" in result.output
    assert list(out.iterdir()) == []


def _spawn_matrix(out: Path, duration: str = "600s", each_batch: bool = False):
    """`uitamr verify --matrix --jobs 2 --trace` long enough to be stopped midway, in a
    process group of its own (as a CI job runs it). `each_batch`: a progress line on stderr
    as each batch of scenarios comes back from its worker (the plain progress of a CI log,
    shown at once instead of every 30 s), for the test to act on."""
    import subprocess
    import sys

    program = ["-m", "verifier.cli"] if not each_batch else [
        "-c", "import verifier.commands.verify as v; v.PLAIN_PROGRESS_EVERY_S = 0; from verifier.cli import main; main()"]
    return procs.spawn([sys.executable, *program, "verify", "--matrix", "--duration", duration,
                        "--jobs", "2", "--trace", str(out / "t.jsonl")],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _wait_for_spool(out: Path, proc) -> None:
    import time

    for _ in range(300):
        if any(out.glob(".uitamr-trace-*/*.part")):
            return
        assert proc.poll() is None, proc.stderr.read().decode()
        time.sleep(0.05)
    raise AssertionError("no spool file appeared")


def test_a_ci_time_out_stops_the_run_and_leaves_nothing(tmp_path):
    """SIGTERM to the job's process group (a CI time-out): the command ends through its
    clean-up, exit 143, and the spool folder with the workers' files is gone."""
    import os
    import signal

    proc = _spawn_matrix(tmp_path)
    _wait_for_spool(tmp_path, proc)
    os.killpg(proc.pid, signal.SIGTERM)
    _, stderr = procs.finish(proc, 120)
    assert proc.returncode == 143, stderr.decode()
    assert b"Traceback" not in stderr
    assert list(tmp_path.iterdir()) == []


def _first_line(proc, within_s: float = 120) -> bytes:
    """The first line the process writes on stderr, read from the pipe itself (what
    `communicate` reads later is not taken into a buffer here)."""
    import os
    import select

    line = b""
    while not line.endswith(b"\n"):
        ready, _, _ = select.select([proc.stderr.fileno()], [], [], within_s)
        assert ready, f"no line on stderr in {within_s} s"
        byte = os.read(proc.stderr.fileno(), 1)
        assert byte, f"stderr ended: {line!r}"
        line += byte
    return line


def _workers(proc) -> list[int]:
    return [int(pid) for pid in Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()]


def _running(pid: int) -> bool:
    """A process that is there and not a zombie (reaped or not, a killed worker runs nothing)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False
    return stat[stat.rindex(")") + 2] != "Z"


def test_a_ci_time_out_just_after_a_batch_came_back_stops_the_run_and_leaves_nothing(tmp_path):
    """SIGTERM to the job's process group just as a worker's batch came back, when the pool
    holds batches that no worker has started: the command hung for good (SIGTERM raised its
    exit inside the pool's wait, the clean-up cancelled those batches, the pool's thread then
    failed on them and left its queue's feeder blocked, and the exit waits for that), or
    printed "Exception in thread" with its traceback. Each time: exit 143, nothing left."""
    import os
    import signal

    for attempt in range(3):  # before: most such signals hung it, here
        out = tmp_path / str(attempt)
        out.mkdir()
        proc = _spawn_matrix(out, "60s", each_batch=True)
        line = _first_line(proc)
        assert line.startswith(b"verify: "), line  # the first batch came back
        os.killpg(proc.pid, signal.SIGTERM)
        _, stderr = procs.finish(proc, 60)
        assert proc.returncode == 143, stderr.decode()
        assert b"Traceback" not in stderr and b"Exception in thread" not in stderr, stderr.decode()
        assert list(out.iterdir()) == []


@pytest.mark.parametrize("stop", ["sigterm-to-the-command", "ctrl-c"])
def test_a_stopped_command_stops_its_workers(tmp_path, stop):
    """SIGTERM to the command alone (`kill PID`, `docker stop`): it waited for its workers,
    which had not been signalled, to finish their batches (a day long here). Ctrl-C (to the
    terminal's process group): each worker sent its KeyboardInterrupt back and went on with
    the next batch the pool had queued. Now the workers are killed: exit 143 or 130 (with
    its message), the workers gone, nothing left."""
    import os
    import signal

    proc = _spawn_matrix(tmp_path, "24h")
    _wait_for_spool(tmp_path, proc)
    workers = _workers(proc)
    assert workers, "the pool has no worker process"
    if stop == "ctrl-c":
        os.killpg(proc.pid, signal.SIGINT)
    else:
        os.kill(proc.pid, signal.SIGTERM)
    _, stderr = procs.finish(proc, 60)
    assert proc.returncode == (130 if stop == "ctrl-c" else 143), stderr.decode()
    said = b"\nuitamr verify: interrupted (Ctrl-C) before it finished: no verdict\n" if stop == "ctrl-c" else b""
    assert stderr == said
    assert [pid for pid in workers if _running(pid)] == []
    assert list(tmp_path.iterdir()) == []


def test_a_worker_killed_midway_is_said_and_leaves_nothing(tmp_path):
    """A worker process killed (the OOM killer): exit 2 with a message, no traceback, and
    no spool file left, although the worker could not remove its own."""
    import os
    import signal

    proc = _spawn_matrix(tmp_path)
    _wait_for_spool(tmp_path, proc)
    children = _workers(proc)
    assert children, "the pool has no worker process"
    os.kill(children[0], signal.SIGKILL)
    _, stderr = procs.finish(proc, 120)
    assert proc.returncode == 2, stderr.decode()
    assert b"a worker process of --jobs 2 stopped without a word" in stderr and b"Traceback" not in stderr
    assert list(tmp_path.iterdir()) == []


def test_a_command_killed_outright_leaves_a_spool_the_next_one_removes(tmp_path):
    """SIGKILL runs no clean-up: the spool folder stays. The next `uitamr verify` that
    writes a trace or a page in that folder removes it (its process is gone), and leaves
    the spools of processes that live, or of other hosts, alone."""
    import os
    import signal

    from verifier.verify.spool import PREFIX as SPOOL_PREFIX
    from verifier.verify.spool import owner

    proc = _spawn_matrix(tmp_path)
    _wait_for_spool(tmp_path, proc)
    os.killpg(proc.pid, signal.SIGKILL)
    procs.finish(proc, 60)
    (orphan,) = tmp_path.glob(f"{SPOOL_PREFIX}*")
    living = tmp_path / f"{SPOOL_PREFIX}{owner()}-{os.getpid()}-abc"  # this test's process lives
    elsewhere = tmp_path / f"{SPOOL_PREFIX}otherhost-{proc.pid}-abc"  # another machine's: not ours to judge
    for folder in (living, elsewhere):
        folder.mkdir()
        (folder / "x.part").write_text("")
    result = _invoke("--scenario", ROOT / "plc" / "scenarios" / "fx3u-healthy.toml", "--html", tmp_path / "r.html")
    assert result.exit_code == 0, result.output
    assert not orphan.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["r.html", living.name, elsewhere.name])


@pytest.mark.parametrize("extra", [["--every-scan"], [], ["--html"]], ids=["held", "spooled", "spooled-with-html"])
def test_runs_that_share_a_name_are_apart_in_the_trace_and_replay_reads_them(tmp_path, extra):
    """A copied scenario file that kept its name, and one file given twice: the trace names
    them as the JUnit report does, and `uitamr replay` reads three runs, each whole."""
    from verifier.cli import main

    text = (ROOT / "plc/scenarios/fx3u-healthy.toml").read_text(encoding="utf-8")
    text = text.replace('"../', f'"{(ROOT / "plc").as_posix()}/').replace('duration = "60s"', 'duration = "3s"')
    text = text[:text.index("[[expect]]")]  # the points are reached later than 3 s
    first, copy = tmp_path / "a.toml", tmp_path / "b.toml"
    first.write_text(text, encoding="utf-8")
    copy.write_text(text, encoding="utf-8")
    trace = tmp_path / "t.jsonl"
    # --every-scan (the reference path) holds every frame; --html spools them as the trace does
    extra = [arg for given in extra for arg in ([given, str(tmp_path / "r.html")] if given == "--html" else [given])]
    result = CliRunner().invoke(main, ["verify", "--scenario", str(first), "--scenario", str(copy),
                                       "--scenario", str(first), "--trace", str(trace), *extra])
    assert result.exit_code == 0, result.output
    import json

    name = load_scenario(first).name
    runs = {}
    for line in trace.read_text(encoding="utf-8").splitlines():
        record = json.loads(line)
        if "dir" in record:  # a frame (each run ends with its end record)
            runs.setdefault(record["scenario"], []).append(record["t"])
    assert list(runs) == [f"{name} [{first} #1]", f"{name} [{copy}]", f"{name} [{first} #2]"]
    assert runs[f"{name} [{first} #1]"] == runs[f"{name} [{copy}]"] == runs[f"{name} [{first} #2]"]
    replayed = CliRunner().invoke(main, ["replay", str(trace)])
    assert replayed.exit_code == 0, replayed.output
    assert "PASS: 3 capture(s) compliant" in replayed.output
