"""Whatever a hurried integrator or a corrupted file hands a command, it answers with an
error that names what to fix and an exit status (2: unusable input), never a traceback."""
from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier.cli import main
from verifier.verify.scenario import ScenarioError, load_scenario
import procs

#: longer than any file name a Linux or Windows file system takes (255 bytes)
LONG = "a" * 300


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


@pytest.mark.parametrize("args", [
    ["check", LONG],
    ["check", LONG + ".toml"],
    ["verify", LONG],
    ["verify", "--scenario", LONG + ".toml"],
    ["verify", "--duration", "1s", "--json", f"{LONG}/x.json"],
    ["export", "--target", "gxworks2", "--out", "{tmp}", LONG],
])
def test_a_file_name_too_long_is_an_error_not_a_traceback(args, tmp_path):
    # os.stat raised OSError (ENAMETOOLONG) from Path.is_dir()/exists() before any check
    result = invoke(*[a.replace("{tmp}", str(tmp_path)) for a in args])
    assert result.exit_code == 2, result.output
    assert "File name too long" in result.output and LONG in result.output


def test_a_source_name_too_long_in_a_scenario_names_its_key_and_line(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(f'program = "Main"\nsources = ["{LONG}.st"]\n', encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert (caught.value.key, caught.value.place.line, caught.value.place.col) == ("sources[0]", 2, 12)
    assert "File name too long" in caught.value.message


def test_a_scenario_file_name_too_long_is_a_scenario_error(tmp_path):
    with pytest.raises(ScenarioError, match="cannot read: File name too long"):
        load_scenario(tmp_path / f"{LONG}.toml")


@pytest.mark.parametrize("args, words", [
    (["check", "{loop}.st"], "cannot read: Too many levels of symbolic links"),
    (["check", "{loop}.toml"], "cannot read: Too many levels of symbolic links"),
    (["verify", "--scenario", "{loop}.toml"], "a symbolic link to nothing"),
    (["verify", "{loop}.st"], "a symbolic link to nothing"),
    (["verify", "--duration", "1s", "--json", "{loop}.st"], "Too many levels of symbolic links"),
    (["replay", "--json", "{loop}.st", "{capture}"], "Too many levels of symbolic links"),
    (["export", "--target", "gxworks2", "--out", "{loop}.st", "{program}"], "cannot write"),
])
def test_a_symlink_loop_is_an_error_not_a_traceback(args, words, tmp_path):
    # Python 3.11's Path.resolve() raised RuntimeError("Symlink loop from ...")
    loop = tmp_path / "loop"
    for suffix in (".st", ".toml"):
        (tmp_path / f"a{suffix}").symlink_to(tmp_path / f"b{suffix}")
        (tmp_path / f"b{suffix}").symlink_to(tmp_path / f"a{suffix}")
        (tmp_path / f"loop{suffix}").symlink_to(tmp_path / f"a{suffix}")
    program = tmp_path / "P.st"
    program.write_text("PROGRAM P\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n", encoding="utf-8")
    capture = tmp_path / "c.txt"
    capture.write_text("0.000 tx 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    fill = {"{loop}": str(loop), "{program}": str(program), "{capture}": str(capture)}
    for key, value in fill.items():
        args = [a.replace(key, value) for a in args]
    result = invoke(*args)
    assert result.exit_code == 2, result.output
    assert words in result.output


def test_a_host_name_the_idna_codec_refuses_is_an_error_not_a_traceback():
    # socket.create_connection raised UnicodeError ("label empty or too long") for a..b
    result = invoke("monitor", "--tcp", "a..b:4001", "--duration", "1s")
    assert result.exit_code == 2
    assert "cannot connect to a..b:4001: not a host name" in result.output


# --- properties: whatever the file holds ------------------------------------------------------

import datetime  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import tempfile  # noqa: E402
import tomllib  # noqa: E402

from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

from verifier.verify.scenario import parse_scenario  # noqa: E402

BUNDLED = sorted((Path(__file__).parents[1] / "plc" / "scenarios").glob("*.toml"))


def toml_value(value) -> str:
    """`value` as an inline TOML value (every table inline, so any value can go anywhere)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        return value.isoformat()
    if isinstance(value, list):
        return "[" + ", ".join(map(toml_value, value)) + "]"
    return "{" + ", ".join(f"{json.dumps(k, ensure_ascii=False)} = {toml_value(v)}" for k, v in value.items()) + "}"


TEXT = st.text(st.characters(blacklist_categories=("Cs",)), max_size=12)
SCALARS = st.one_of(
    st.booleans(), st.integers(), st.integers(-2, 30), st.floats(), TEXT,
    st.sampled_from(["0s", "1s", "-1s", "250ms", "1e3s", "X0", "o_bErr", "o_bErr AND", "fbEngine.o_uErrId",
                     "no_reply", "late_reply", "exception", "stop", "run-point 3", "none", "fx5u", "q", "q:2",
                     "192.168.3.50", "U0\\G164", "D100", "1" * 5000]),
    st.datetimes(), st.dates(), st.times(),
)
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=3),
                                                       st.dictionaries(TEXT, inner, max_size=3)), max_leaves=6)


@settings(max_examples=200, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(BUNDLED), st.data())
def test_any_value_anywhere_in_a_scenario_loads_or_is_a_scenario_error(path, data):
    """A bundled scenario with one value (at any depth) replaced or added: it loads, or
    it is a ScenarioError that names the file; never another exception (a fault kind
    given as an array was a TypeError)."""
    table = tomllib.loads(path.read_text(encoding="utf-8"))
    node = table
    while True:
        key = data.draw(st.sampled_from(sorted(node) + ["new"]), label="key")
        child = node.get(key)
        if isinstance(child, list) and child and isinstance(child[0], dict) and data.draw(st.booleans()):
            node = child[data.draw(st.integers(0, len(child) - 1))]
        elif isinstance(child, dict) and data.draw(st.booleans()):
            node = child
        else:
            node[key] = data.draw(VALUES, label="value")
            break
    text = "".join(f"{json.dumps(k)} = {toml_value(v)}\n" for k, v in table.items())
    try:
        parse_scenario(text, path)
    except ScenarioError as exc:
        assert str(exc).startswith(str(path))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.binary(max_size=300), st.sampled_from([".st", ".toml"]))
def test_any_bytes_as_a_source_or_scenario_are_checked_without_a_traceback(content, suffix):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"any{suffix}"
        path.write_bytes(content)
        result = invoke("check", path)
    assert result.exit_code in (0, 1), result.output
    assert str(path) in result.output or result.exit_code == 0


# --- file names that are not UTF-8 --------------------------------------------------------------

import os  # noqa: E402


def not_utf8(folder: Path, name: bytes) -> Path:
    """A path whose name holds bytes that are not UTF-8 (a Shift-JIS name from a Windows share):
    Python hands it around with lone surrogates in place of the bad bytes."""
    return folder / os.fsdecode(name)


def test_check_prints_a_file_name_that_is_not_utf8(tmp_path):
    # the console (a UTF-8 stdout with strict errors, as CliRunner's is) raised UnicodeEncodeError
    path = not_utf8(tmp_path, b"\x83v\x83\x8d.st")  # "プロ" in Shift-JIS
    path.write_text("PROGRAM P\nVAR x : INT; END_VAR\nx := ;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke("check", path)
    assert result.exit_code == 1
    assert result.output.startswith(f"{tmp_path}/\\udc83v\\udc83\\udc8d.st:3:6: error: expected an expression")


def test_replay_reports_of_a_capture_whose_name_is_not_utf8_are_whole(tmp_path):
    # report_json raised UnicodeEncodeError half-way through r.json, and left it half-written
    capture = not_utf8(tmp_path, b"site\xff.txt")
    capture.write_bytes((Path(__file__).parent / "captures" / "bad-master.txt").read_bytes())
    reports = [tmp_path / f"r.{suffix}" for suffix in ("json", "xml", "jsonl", "html")]
    result = invoke("replay", capture, "--json", reports[0], "--junit", reports[1], "--trace", reports[2],
                    "--html", reports[3])
    assert result.exit_code == 1, result.output
    assert json.loads(reports[0].read_text(encoding="utf-8"))["scenarios"][0]["name"] == capture.name
    assert "site\\udcff.txt" in reports[3].read_text(encoding="utf-8")
    assert json.loads(reports[2].read_text(encoding="utf-8").splitlines()[0])["scenario"] == capture.name
    assert invoke("replay", reports[2]).exit_code == 1  # the trace reads back


def test_verify_reports_of_a_source_whose_name_is_not_utf8_are_whole(tmp_path):
    source = not_utf8(tmp_path, b"Main\xfe.st")
    source.write_text("PROGRAM Main\nVAR x : INT; END_VAR\nx := x + 1;\nEND_PROGRAM\n", encoding="utf-8")
    reports = [tmp_path / f"v.{suffix}" for suffix in ("json", "jsonl", "html")]
    result = invoke("verify", source, "--duration", "1s", "--json", reports[0], "--trace", reports[1],
                    "--html", reports[2])
    assert result.exit_code in (0, 1), result.output
    assert json.loads(reports[0].read_text(encoding="utf-8"))["scenarios"][0]["sources"] == [str(source)]
    assert reports[1].exists()  # (no frames: the program sends nothing)
    assert reports[2].read_text(encoding="utf-8").rstrip().endswith("</html>")


# --- a file that cannot be written to its end -----------------------------------------------------

import resource  # noqa: E402
import signal  # noqa: E402
import sys  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def run_with_file_size_limit(limit: int, *args, cwd: Path):
    """`uitamr ARGS` in a process that may write no file larger than `limit` bytes: a write
    past it fails with EFBIG ("File too large") as on a full disk, half-way through a file."""
    def limit_files():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a failed write, not a killed process
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return procs.run([sys.executable, "-m", "verifier.cli", *map(str, args)], cwd=cwd, capture_output=True,
                     text=True, preexec_fn=limit_files, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=120)


@pytest.mark.parametrize("option, name", [("--json", "r.json"), ("--junit", "r.xml"), ("--trace", "r.jsonl"),
                                          ("--html", "r.html")])
def test_a_report_that_cannot_be_written_to_its_end_is_not_left_half_written(option, name, tmp_path):
    # the first 1000 bytes of r.json stayed behind: a report that no reader can read
    result = run_with_file_size_limit(1000, "replay", ROOT / "tests" / "captures" / "bad-master.txt", option, name,
                                      cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.endswith(f"uitamr replay: cannot write {name}: File too large\n")
    assert not (tmp_path / name).exists()


def test_an_export_file_that_cannot_be_written_to_its_end_is_named_and_not_left_half_written(tmp_path):
    # half of UITAMR_AdpBridge.st stayed behind, and the error named only the --out folder
    result = run_with_file_size_limit(3000, "export", "--platform", "fx3u", "--out", "out", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.endswith("uitamr export: cannot write out/UITAMR_AdpBridge.st: File too large\n")
    assert all(path.stat().st_size < 3000 for path in (tmp_path / "out").iterdir())
    assert not (tmp_path / "out" / "UITAMR_AdpBridge.st").exists()


def test_ctrl_c_in_the_middle_of_a_replay_is_not_a_finding(monkeypatch, tmp_path):
    """Ctrl-C in `uitamr replay` of a long capture (it reads for seconds) was click's
    "Aborted!" and exit status 1, which replay's callers read as "the PLC broke a rule". It
    is 130 (128 + SIGINT, as the shell reports it), said as an interruption with no verdict,
    and writes no report. The KeyboardInterrupt is raised where Ctrl-C lands in a replay: in
    the middle of feeding the capture's chunks."""
    from verifier.monitor.session import MonitorSession

    def interrupted(self, chunk):
        raise KeyboardInterrupt

    monkeypatch.setattr(MonitorSession, "feed", interrupted)
    capture = Path(__file__).resolve().parent / "captures" / "bad-master.txt"
    result = CliRunner().invoke(main, ["replay", str(capture), "--json", str(tmp_path / "r.json")])
    assert result.exit_code == 130, result.output
    assert "uitamr replay: interrupted (Ctrl-C) before it finished: no verdict" in result.output
    assert "Aborted" not in result.output and not (tmp_path / "r.json").exists()
    page = " ".join((Path(__file__).resolve().parents[1] / "docs" / "commissioning.md").read_text(encoding="utf-8").split())
    assert "Ctrl-C in the middle of a replay ends it with exit status 130 and no verdict" in page


@pytest.mark.parametrize("command", ["monitor", "emulate"])
@pytest.mark.parametrize("bare, option", [("/dev/ttyUSB0", "--serial"), ("COM3", "--serial"),
                                          ("socket://10.0.0.5:4001", "--serial"),
                                          ("127.0.0.1:4001", "--tcp"), ("[::1]:4001", "--tcp"), ("4001", "--tcp")])
def test_a_port_typed_without_its_option_is_named_with_the_option_it_needs(command, bare, option):
    """`uitamr monitor /dev/ttyUSB0` (the port without --serial, on site) got click's bare
    "Got unexpected extra argument (/dev/ttyUSB0)"; now the option it needs is named."""
    result = invoke(command, bare)
    assert result.exit_code == 2, result.output
    assert f"Error: {bare!r} is given without its option: {option} {bare}" in result.output


@pytest.mark.parametrize("command", ["monitor", "emulate"])
def test_words_beside_a_port_given_with_its_option_are_refused_as_such(command):
    result = invoke(command, "--serial", "/dev/ttyUSB0", "x", "y")
    assert result.exit_code == 2, result.output
    assert "Error: unexpected arguments 'x' 'y': the command takes options only" in result.output


def test_a_port_typed_without_its_option_is_the_monitors_junit_error(tmp_path):
    """The monitor's CI job shows the mistake, as for click's own refusals."""
    import xml.etree.ElementTree as ET

    result = invoke("monitor", "/dev/ttyUSB0", "--junit", tmp_path / "m.xml")
    assert result.exit_code == 2, result.output
    error = ET.parse(tmp_path / "m.xml").getroot().find(".//testcase/error")
    assert error is not None and error.get("message").startswith("'/dev/ttyUSB0' is given without its option")


def test_check_sarif_names_a_file_whose_name_is_not_utf8_by_its_bytes(tmp_path, monkeypatch):
    """`uitamr check --format sarif` with an error in `\\x83v\\x83\\x8d.st` below the working
    folder: percent-encoding the name for its SARIF URI raised UnicodeEncodeError (a
    traceback); the URI now holds the name's bytes, as an absolute path's file: URI does."""
    monkeypatch.chdir(tmp_path)
    path = not_utf8(tmp_path, b"\x83v\x83\x8d.st")
    path.write_text("PROGRAM P\nVAR x : INT; END_VAR\nx := ;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke("check", "--format", "sarif", path.name)
    assert result.exit_code == 1, result.output
    (found,) = json.loads(result.output)["runs"][0]["results"]
    location = found["locations"][0]["physicalLocation"]
    assert location["artifactLocation"] == {"uri": "%83v%83%8D.st", "uriBaseId": "%SRCROOT%"}
    assert location["region"]["startLine"] == 3


def test_export_of_a_pipe_or_a_device_is_refused_without_reading_it(tmp_path):
    """`uitamr export ... FIFO` hung, and `... /dev/full` read zeros until the memory ran
    out (MemoryError, a traceback): asking whether a file named neither .st nor .toml is a
    scenario read it whole, whatever it was. Only a regular file is read now; these are
    refused as `check` refuses them, naming what they are."""
    import resource
    import sys

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)

    def at_most_a_gigabyte():
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))

    for source, kind in [(fifo, "a pipe"), ("/dev/full", "a character device")]:
        done = procs.run([sys.executable, "-m", "verifier.cli", "export", "--target", "gxworks2", "--out",
                               str(tmp_path / "out"), str(source)], capture_output=True, text=True, timeout=60,
                         preexec_fn=at_most_a_gigabyte)
        assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
        assert f"uitamr export: {source}: is not a regular file ({kind}); give a .st file" in done.stderr
        assert not (tmp_path / "out").exists()


def test_export_refuses_unusable_input_as_check_does(tmp_path, monkeypatch):
    """`uitamr export` of a pipe or a device said 'nothing written, 1 unreadable file(s)' and
    exited 1, the code of a program with mistakes, where `uitamr check` of the same input
    exits 2 (unusable input) with the file and what to give instead: both now refuse it
    alike, with the same line; a file whose bytes are not text stays an error of the
    sources (exit 1) in both, at its line and column."""
    monkeypatch.chdir(tmp_path)
    os.mkfifo("pipe.st")
    os.symlink("gone.st", "link.st")
    (tmp_path / "bad.st").write_bytes(b"PROGRAM P\n\xff\nEND_PROGRAM\n")
    for source, why in [("pipe.st", "is not a regular file (a pipe); give a .st file"),
                        ("/dev/null", "is not a regular file (a character device); give a .st file"),
                        ("link.st", "is a symbolic link to nothing (its target is missing, or a loop of links)")]:
        checked = invoke("check", source)
        exported = invoke("export", "--target", "gxworks2", "--out", "out", source)
        assert checked.exit_code == exported.exit_code == 2, (checked.output, exported.output)
        assert f"uitamr check: {source}: {why}" in checked.output
        assert f"uitamr export: {source}: {why}" in exported.output, exported.output
        assert "unreadable" not in exported.output and not (tmp_path / "out").exists()
    checked = invoke("check", "bad.st")
    exported = invoke("export", "--target", "gxworks2", "--out", "out", "bad.st")
    assert checked.exit_code == exported.exit_code == 1, (checked.output, exported.output)
    assert "bad.st:2:1: error: byte 0xFF" in exported.output


def test_an_empty_fault_file_name_is_refused_not_taken_for_none():
    """`uitamr emulate --faults "$FAULTS"` with FAULTS unset gave an empty name, taken for no
    fault file: the bench test ran the healthy robot, exit 0, and a PLC's fault handling
    passed without meeting a fault. Refused now, naming the option."""
    result = invoke("emulate", "--tcp", "127.0.0.1:0", "--faults", "", "--exit-after", "0.2")
    assert result.exit_code == 2, result.output
    assert "Invalid value for --faults: the file's name is empty" in result.output
    assert "stopped after" not in result.output


def test_a_folder_that_vanishes_during_the_walk_is_passed_over(tmp_path, monkeypatch):
    """`uitamr check /` and `uitamr verify /` stopped with exit 2 ('/proc/10441: No such file
    or directory') when a process ended while its /proc folder was being walked: a folder
    that vanishes between being listed and being read is not the user's file, and is
    passed over; the others are read. Real folders; the scandir wrapper only times the
    removal: the first folder read removes its sibling, listed but not yet read."""
    import shutil

    root = tmp_path / "tree"
    for name in ("a", "b"):
        (root / name).mkdir(parents=True)
        (root / name / f"{name.upper()}.st").write_text(f"PROGRAM {name.upper()}\nVAR x : INT; END_VAR\n"
                                                         "x := x + 1;\nEND_PROGRAM\n")
    real_scandir = os.scandir
    removed = []

    def scandir(path="."):
        if isinstance(path, (str, os.PathLike)) and Path(path).parent == root and not removed:
            removed.extend(sibling for sibling in root.iterdir() if sibling != Path(path))
            for sibling in removed:
                shutil.rmtree(sibling)
        return real_scandir(path)

    monkeypatch.setattr(os, "scandir", scandir)
    result = invoke("check", root)
    assert removed and result.exit_code == 0, result.output
    assert "1 file(s) checked" in result.output and "No such file" not in result.output


def test_a_file_name_with_a_newline_stays_on_its_message_line(tmp_path, monkeypatch):
    """A file named with a line feed or a tab (`a<LF>b.st`) was printed as it is: the message
    `a<LF>b.st:3:6: error: ...` broke into two lines, and the editor's or CI's
    `file:line:col` reader saw `b.st:3:6`. Line-based messages (check, export, verify, their
    usage errors) show such a name escaped as the console report does (`a\\x0ab.st`);
    JSON keeps the name exact."""
    monkeypatch.chdir(tmp_path)
    bad = "a\nb.st"
    Path(bad).write_text("PROGRAM P\nVAR x : INT; END_VAR\nx := ;\nEND_PROGRAM\n", encoding="utf-8")
    os.mkfifo("p\tq.st")
    shown = "a\\x0ab.st:3:6: error: expected an expression"
    for args in (["check", bad], ["export", "--target", "gxworks2", "--out", "out", bad]):
        result = invoke(*args)
        assert result.exit_code == 1, result.output
        assert result.output.splitlines()[0].startswith(shown), result.output
        assert "\n" + "b.st:3:6" not in result.output
    result = invoke("verify", bad)
    # named from the working folder, as check and export name it (it was the absolute path)
    assert result.exit_code == 2 and f"\n  {shown}" in result.output, result.output
    for command in (["check"], ["export", "--target", "gxworks2", "--out", "out"]):
        result = invoke(*command, "p\tq.st")
        assert result.exit_code == 2, result.output
        assert f"uitamr {command[0]}: p\\x09q.st: is not a regular file (a pipe)" in result.output
    (finding,) = json.loads(invoke("check", "--format", "json", bad).output)["diagnostics"]
    assert finding["file"] == bad


def test_a_scenario_or_capture_named_with_a_newline_stays_on_its_message_line(tmp_path, monkeypatch):
    """The places of scenario and capture mistakes (verifier.place.Place) printed a file name
    with a line feed as it is: `verify --scenario 's<LF>c.toml'` said 'error: s' and then
    'c.toml:2:12: duration: ...' on the next line. They now show it escaped, as check's and
    verify's ST messages do (`s\\x0ac.toml:2:12`)."""
    monkeypatch.chdir(tmp_path)
    Path("s\nc.toml").write_text('name = "x"\nduration = "5q"\n', encoding="utf-8")
    result = invoke("verify", "--scenario", "s\nc.toml")
    assert result.exit_code == 2, result.output
    assert "s\\x0ac.toml:2:12: duration: '5q' is not a duration" in result.output, result.output
    assert "\nc.toml:" not in result.output
    Path("t\nc.txt").write_text("0.000 rx 01 05\nbogus\n", encoding="utf-8")
    result = invoke("replay", "t\nc.txt")
    assert result.exit_code == 2, result.output
    assert "t\\x0ac.txt:" in result.output and "\nc.txt:" not in result.output, result.output


#: `uitamr` as a program whose lazy import of the sub-command's module gets a real SIGINT
#: (Ctrl-C pressed in the first tenth of a second, while a loaded bench PC still imports
#: pyserial and the robot model): the signal is sent from inside that import, so the test
#: does not depend on when the host runs it
CTRL_C_WHILE_IMPORTING = """
import importlib, os, signal, sys
real = importlib.import_module
def import_module(name, *args):
    if name.startswith("verifier.commands."):
        os.kill(os.getpid(), signal.SIGINT)
    return real(name, *args)
importlib.import_module = import_module
from verifier.cli import main
sys.argv[0] = "uitamr"
main()
"""


@pytest.mark.parametrize("command", [["emulate", "--tcp", "0"], ["monitor", "--tcp", "4001"], ["frame", "stop"]])
def test_ctrl_c_while_the_command_is_being_loaded_names_the_command(command):
    """It said `uitamr None: interrupted (Ctrl-C) ...`: the command's name is known only
    once its module is imported, and the message was made from that."""
    import sys
    result = procs.run([sys.executable, "-c", CTRL_C_WHILE_IMPORTING, *command], timeout=60, capture_output=True,
                         text=True)
    assert result.returncode == 130, (result.returncode, result.stderr)
    assert result.stderr.endswith(f"\nuitamr {command[0]}: interrupted (Ctrl-C) before it finished: no verdict\n"), result.stderr
    assert "Traceback" not in result.stderr


#: the `uitamr` program (pyproject's console script) with a real SIGINT sent while
#: `verifier.cli` itself imports (click, the package): before any handler of its exists
CTRL_C_WHILE_THE_CLI_IMPORTS = """
import os, signal, sys
class CtrlC:
    def find_spec(self, name, path=None, target=None):
        if name == "verifier.cli":
            os.kill(os.getpid(), signal.SIGINT)
        return None
sys.meta_path.insert(0, CtrlC())
from importlib.metadata import entry_points
(script,) = [e for e in entry_points(group="console_scripts") if e.name == "uitamr"]
sys.argv[0] = "uitamr"
script.load()()
"""


def test_ctrl_c_while_the_program_itself_starts_is_no_traceback():
    """Ctrl-C in the first tenth of a second, while `verifier.cli` (click, the package) was
    still being imported, ended in Python's KeyboardInterrupt traceback; now the installed
    `uitamr` says it as any Ctrl-C, exit 130."""
    import sys
    result = procs.run([sys.executable, "-c", CTRL_C_WHILE_THE_CLI_IMPORTS, "verify", "--jobs", "2"], timeout=60,
                       capture_output=True, text=True)
    assert result.returncode == 130, (result.returncode, result.stderr)
    assert result.stderr == "\nuitamr verify: interrupted (Ctrl-C) before it finished: no verdict\n", result.stderr
