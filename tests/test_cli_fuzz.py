"""Mutated inputs through the whole command, in process: the bundled scenarios, the bundled
capture and its trace, the PLC library's ST files and the command lines of `frame`,
`replay` and `emulate`, each changed the way files and typing go wrong (cut short, bytes
changed, CRLF, a byte order mark, lone CRs, Shift-JIS, text in other scripts, numbers too
big, values of the wrong type, nesting hundreds deep).

Whatever the input, a command ends with its documented exit status and never a
traceback (CliRunner is run with catch_exceptions=False: an exception fails the test);
an error names its place (file:line:col, or file: line L, column C (byte N)); the input
file is as it was; and a report is whole or not written (on exit 2, --junit holds the
mistake as an error test case). (test_st_fuzz.py fuzzes the ST
reader itself; test_cli_robustness.py single values of a scenario and any bytes as a
file; this file goes through the commands with inputs close to real ones.)
"""
from __future__ import annotations

import json
import re
import tempfile
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

from hypothesis import HealthCheck, given, settings, strategies as st

from test_cli_robustness import VALUES, invoke, toml_value
from verifier.textfile import BOM
from verifier.verify.scenario import ScenarioError, parse_scenario

ROOT = Path(__file__).resolve().parents[1]
CAPTURE = (ROOT / "tests" / "captures" / "bad-master.txt").read_bytes()
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))
ST_FILES = [p for p in sorted((ROOT / "plc").rglob("*.st")) if p.stat().st_size < 8000]
FUZZ = settings(deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])


def trace_of_the_capture() -> bytes:
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "c.txt").write_bytes(CAPTURE)
        invoke("replay", Path(folder) / "c.txt", "--trace", Path(folder) / "t.jsonl")
        return (Path(folder) / "t.jsonl").read_bytes()


TRACE = trace_of_the_capture()

#: what typing, editors, transfer and other tools put into a text file
PIECES = [b"tx", b"rx", b" TX ", b"#", b"\r\n", b"\r", b"\n", BOM, b"\xff", b"\xc3", b"\x82\xa0", b"\t", b"\x00",
          b"1e400", b"-1", b".", b"9" * 30, b"\xd9\xa3", b"\xef\xbc\x91", b"\xe2\x80\xa8", b"\x0c", b"{", b"}", b'"',
          b"'", b"nan", b"Infinity", b"0.5", b"GG", b"0", b" ", b"\\u0000", b"(*", b"*)", b"(* (* *) *)", b"//", b"/*",
          b"$", b"[", b"]", b"[[", b"=", b"[" * 600, b"{a=" * 500, b"x" * 3000, "\u65e5\u672c".encode()]


@st.composite
def mutated(draw, seeds: list[bytes]) -> bytes:
    """One of `seeds` with one to five edits: bytes deleted, inserted, repeated, changed,
    the end cut off, or every line end made CRLF."""
    data = bytearray(draw(st.sampled_from(seeds)))
    for _ in range(draw(st.integers(1, 5))):
        pos = draw(st.integers(0, len(data)))
        edit = draw(st.sampled_from(["delete", "insert", "insert", "repeat", "cut", "change", "crlf"]))
        if edit == "delete":
            del data[pos:pos + draw(st.integers(1, 30))]
        elif edit == "insert":
            data[pos:pos] = draw(st.one_of(st.sampled_from(PIECES), st.binary(max_size=4),
                                           st.text(max_size=3).map(lambda t: t.encode("utf-8", "surrogatepass"))))
        elif edit == "repeat":
            data[pos:pos] = data[pos:pos + draw(st.integers(1, 80))]
        elif edit == "cut":
            del data[pos:]
        elif edit == "change" and pos < len(data):
            data[pos] = draw(st.integers(0, 255))
        elif edit == "crlf":
            data = bytearray(bytes(data).replace(b"\r\n", b"\n").replace(b"\n", b"\r\n"))
    return bytes(data)


def line_ends(data: bytes):
    """The same text with other line ends, or a byte order mark: read alike."""
    lf = data.replace(b"\r\n", b"\n")
    yield "crlf", lf.replace(b"\n", b"\r\n")
    if b"\r" not in lf:
        yield "cr", lf.replace(b"\n", b"\r")
    if not data.startswith(BOM):
        yield "bom", BOM + data


# --- replay: captures and traces ---------------------------------------------------------------

#: `uitamr replay: FILE:LINE:COL: ...` or, for bytes that are not text, `FILE: line L, column C (byte N)`
REPLAY_ERROR = r"uitamr replay: {path}:(\d+):(\d+): |uitamr replay: {path}: line (\d+), column (\d+) \(byte \d+\): "


@settings(FUZZ, max_examples=80)
@given(mutated([CAPTURE, TRACE]))
def test_a_mutated_capture_is_judged_or_an_error_at_its_place(content):
    with tempfile.TemporaryDirectory() as folder:
        capture = Path(folder) / "site.txt"
        capture.write_bytes(content)
        reports = {suffix: Path(folder) / f"r.{suffix}" for suffix in ("json", "xml", "jsonl", "html")}
        result = invoke("replay", capture, "--json", reports["json"], "--junit", reports["xml"],
                        "--trace", reports["jsonl"], "--html", reports["html"])
        assert result.exit_code in (0, 1, 2, 3), result.output
        assert capture.read_bytes() == content
        if result.exit_code == 2:
            match = re.match(REPLAY_ERROR.format(path=re.escape(str(capture))), result.stderr)
            assert match, result.stderr
            assert all(int(n) >= 1 for n in match.groups() if n is not None), result.stderr
            assert not any(reports[kind].exists() for kind in ("json", "jsonl", "html"))
            # the JUnit is the mistake, whole: one error test case at the place the console names
            (case,) = ET.parse(reports["xml"]).getroot().findall("./testsuite/testcase")
            assert case.find("error").get("type") == "unusable-input"
            return
        json.loads(reports["json"].read_text(encoding="utf-8"))
        assert reports["html"].read_text(encoding="utf-8").rstrip().endswith("</html>")
        again = invoke("replay", reports["jsonl"])  # the trace it wrote reads back
        assert again.exit_code == result.exit_code, again.output


@settings(FUZZ, max_examples=40)
@given(mutated([CAPTURE, TRACE]))
def test_line_ends_and_a_byte_order_mark_do_not_change_a_verdict(content):
    with tempfile.TemporaryDirectory() as folder:
        capture, report = Path(folder) / "site.txt", Path(folder) / "r.json"
        capture.write_bytes(content)
        first = invoke("replay", capture, "--json", report)
        if first.exit_code == 2:
            return
        expected = [s["violations"] for s in json.loads(report.read_text(encoding="utf-8"))["scenarios"]]
        for kind, variant in line_ends(content):
            capture.write_bytes(variant)
            result = invoke("replay", capture, "--json", report)
            assert result.exit_code == first.exit_code, (kind, result.output)
            got = [s["violations"] for s in json.loads(report.read_text(encoding="utf-8"))["scenarios"]]
            assert got == expected, kind


# --- frame: the command line -------------------------------------------------------------------

WORDS = ["stop", "pause", "run-point", "seek-tape", "follow-tape", "rotate-on-tape", "coordinate-reset",
         "manual-mode", "speed", "collision-range", "jog", "move", "rotate", "read", "raw", "forward", "backward",
         "left", "right", "trackless", "magnetic", "task", "vehicle", "battery", "x", "front", "rear", "y",
         "shift-left", "0", "1", "3", "21", "22", "-1", "+1", "-2.5", "25.5", "25.6", "2.55", "2.56", "0x0A", "0x",
         "0xFFFFFFFFFFFF", "1e3", "nan", "inf", "-0", "1" * 5000, "\u0663", "\uff11", "0.001", "+", "-", "", " ",
         "--explain", "--words", "--decode", "--as", "request", "reply", "--address", "0", "248", "--mbpoll",
         "/dev/ttyUSB0", "--field-order", "code-low", "--codes-10-13", "hex", "--status-order", "return",
         "--manual-stop-counts-as-stop", "01", "06", "01 06 01 A0 00 00 88 14", "01 01 03 00 00 01 FD 8E", "--bogus",
         "--", "0x0,0x1", "1_0", "\x00", "\u00e9"]


@settings(FUZZ, max_examples=250)
@given(st.lists(st.one_of(st.sampled_from(WORDS), st.binary(max_size=10).map(lambda b: b.hex(" ")),
                          st.text(max_size=5)), max_size=8))
def test_any_frame_command_line_prints_decodes_or_is_refused_by_name(words):
    result = invoke("frame", *words)
    assert result.exit_code in (0, 1, 2), result.output
    if result.exit_code == 2:
        assert "Error:" in result.stderr or "uitamr" in result.stderr, result.stderr


# --- check and export: ST sources --------------------------------------------------------------

ST_SEEDS = [p.read_bytes() for p in ST_FILES]
ST_SEEDS += [p.read_text(encoding="utf-8").encode("cp932", "replace") for p in ST_FILES[:3]]  # Shift-JIS
TEXT_ERROR = re.compile(r"(?P<file>.+?):(?P<line>\d+):(?P<col>\d+): error: ")


@settings(FUZZ, max_examples=90)
@given(mutated(ST_SEEDS), st.sampled_from([[], ["--platform", "fx3u"], ["--platform", "fx5u"], ["--target", "gxworks3"]]))
def test_a_mutated_st_file_is_checked_with_every_error_at_a_place(content, options):
    with tempfile.TemporaryDirectory() as folder:
        source = Path(folder) / "Mutated.st"
        source.write_bytes(content)
        text = invoke("check", *options, source)
        assert text.exit_code in (0, 1), text.output
        for line in text.output.splitlines():
            if ": error: " in line and not line.startswith(" "):
                match = TEXT_ERROR.match(line)
                assert match and match["file"] == str(source), line
                assert int(match["line"]) >= 1 and int(match["col"]) >= 1, line
        as_json = invoke("check", "--format", "json", *options, source)
        diagnostics = json.loads(as_json.output)["diagnostics"]
        assert (as_json.exit_code, len(diagnostics)) == (text.exit_code, text.output.count(": error: ")
                                                         + text.output.count(": warning: "))
        sarif = invoke("check", "--format", "sarif", *options, source)
        assert sarif.exit_code == text.exit_code and json.loads(sarif.output)["version"] == "2.1.0"
        for kind, variant in line_ends(content):
            if kind == "cr":  # a lone CR in a string or comment is a line end there: not the same text
                continue
            if kind == "bom" and not is_utf8(content):  # a UTF-8 mark on Shift-JIS text is neither
                continue
            source.write_bytes(variant)
            again = json.loads(invoke("check", "--format", "json", *options, source).output)["diagnostics"]
            assert list(map(place_and_words, again)) == list(map(place_and_words, diagnostics)), kind
        source.write_bytes(content)
        out = Path(folder) / "out"
        export = invoke("export", "--out", out, *(options or ["--target", "gxworks2"]), source)
        assert export.exit_code in (0, 1, 2), export.output
        if export.exit_code != 0:
            assert "nothing written" in export.stderr, export.stderr
            assert not out.exists() or not any(out.iterdir())
        elif text.exit_code == 0:
            assert (out / "IMPORT_ORDER.txt").exists()
        assert source.read_bytes() == content


def is_utf8(data: bytes) -> bool:
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def place_and_words(diagnostic: dict) -> tuple:
    """What a diagnostic says, but the byte offset of a byte that is not text (a byte order
    mark before it moves it, not its line and column)."""
    return diagnostic["line"], diagnostic["col"], re.sub(r"at offset \d+", "at offset N", diagnostic["message"])


# --- scenarios: check and verify ---------------------------------------------------------------

SCENARIO_SEEDS = [p.read_bytes() for p in SCENARIOS]


@settings(FUZZ, max_examples=150)
@given(mutated(SCENARIO_SEEDS))
def test_a_mutated_scenario_is_checked_with_every_error_at_a_line(content):
    with tempfile.TemporaryDirectory() as folder:
        scenario = Path(folder) / "site.toml"
        scenario.write_bytes(content)
        result = invoke("check", scenario)
        assert result.exit_code in (0, 1), result.output
        for line in result.output.splitlines():
            if line.startswith(str(scenario)):
                match = TEXT_ERROR.match(line)
                assert match, line
                assert int(match["line"]) >= 1 and int(match["col"]) >= 1, line  # file:0:0 was printed
        assert scenario.read_bytes() == content


ASSIGNMENT = re.compile(r"^(\s*[A-Za-z0-9_.\"-]+\s*=\s*)(.+)$", re.M)
KEYS = ["kind", "at", "at_s", "on_request", "delay_ms", "within", "after", "sent", "that", "never", "reached_point",
        "set", "pulse", "name", "program", "platform", "channel", "sources", "duration", "scan", "seed", "watch",
        "signal", "turnaround_ms", "point_duration_s", "pacing", "before_stop", "drops", "D100", "X0", "U0\\G164",
        "fbEngine.o_bErr", "\u00e9", "", "1", "a.b", "faults", "robot", "inputs", "expect", "initial", "converter"]
HEADERS = ["[robot]", "[[faults]]", "[[inputs]]", "[[expect]]", "[initial]", "[converter]", "[[c24]]", "[x]",
           "[robot.point_poses]", "[inputs.set]", "[[robot]]", "[response_handling]"]


@st.composite
def edited_scenario(draw) -> tuple[Path, str]:
    """A bundled scenario with a value, a key or a table changed in its own text (so the
    rest keeps its tables, arrays of tables and lines), still TOML."""
    path = draw(st.sampled_from(SCENARIOS))
    text = path.read_text(encoding="utf-8")
    for _ in range(draw(st.integers(1, 3))):
        found = draw(st.sampled_from(list(ASSIGNMENT.finditer(text))))
        edit = draw(st.sampled_from(["value", "value", "key", "new key", "table", "deep"]))
        if edit == "deep":  # tomllib runs out of stack some 400 levels down
            depth = draw(st.sampled_from([100, 1000]))
            brackets = draw(st.sampled_from([("[", "]"), ("{a=", "}")]))
            deep = brackets[0] * depth + ("1" if brackets[0] == "{a=" else "") + brackets[1] * depth
            text = text[:found.start(2)] + deep + text[found.end(2):]
        elif edit == "value":
            text = text[:found.start(2)] + toml_value(draw(VALUES)) + text[found.end(2):]
        elif edit == "key":
            text = text[:found.start(1)] + json.dumps(draw(st.sampled_from(KEYS))) + " = " + text[found.start(2):]
        elif edit == "new key":
            new = json.dumps(draw(st.sampled_from(KEYS))) + " = " + toml_value(draw(VALUES))
            text = text[:found.end()] + "\n" + new + text[found.end():]
        else:
            text = text[:found.end()] + "\n" + draw(st.sampled_from(HEADERS)) + "\n" + text[found.end():]
    return path, text


@settings(FUZZ, max_examples=200)
@given(edited_scenario(), st.sampled_from([None, "fx3u", "fx5u", "q"]))
def test_every_mistake_in_a_scenario_is_placed_on_a_line(edited, platform):
    """test_cli_robustness checks that any value gives a ScenarioError naming the file;
    here the error also has a line: an unknown key "" had none."""
    path, text = edited
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return  # a key made twice, a table opened twice: the TOML tests' part
    except RecursionError:
        pass  # nested deeper than tomllib reads: the scenario's error, at its key
    try:
        parse_scenario(text, path, platform)
    except ScenarioError as error:
        assert error.place is not None and error.place.line >= 1 and error.place.col >= 1, str(error)


DURATION_VALUE = re.compile(r'"[0-9.]+(?:us|ms|s|min|h)"')
NUMBER_VALUE = re.compile(r"-?[0-9][0-9_]*(?:\.[0-9]+)?")


@st.composite
def retimed_scenario(draw) -> tuple[Path, str]:
    """A bundled scenario with one duration, number or boolean changed to another of its
    kind (0, negative, huge, finer than the clock): most still run."""
    path = draw(st.sampled_from(SCENARIOS))
    text = path.read_text(encoding="utf-8")
    candidates = [m for m in ASSIGNMENT.finditer(text)
                  if DURATION_VALUE.fullmatch(m.group(2)) or NUMBER_VALUE.fullmatch(m.group(2))
                  or m.group(2) in ("true", "false")]
    found = draw(st.sampled_from(candidates))
    old = found.group(2)
    if DURATION_VALUE.fullmatch(old):
        new = json.dumps(draw(st.sampled_from(["0s", "1us", "0.5us", "3s", "250ms", "59s", "2h", "100000h"])))
    elif old in ("true", "false"):
        new = "false" if old == "true" else "true"
    else:
        new = draw(st.sampled_from(["0", "-1", "1", "2", "7", "0.001", "255", "65536", "1e9", "1e10", "-0.0"]))
    return path, text[:found.start(2)] + new + text[found.end(2):]


@settings(FUZZ, max_examples=16)
@given(retimed_scenario())
def test_verify_runs_an_edited_scenario_or_refuses_it_at_its_place(edited):
    path, text = edited
    with tempfile.TemporaryDirectory() as folder:
        scenarios = Path(folder) / "scenarios"
        scenarios.mkdir()
        for part in ("core", "fx3", "fx5", "q", "examples"):  # what the scenario's sources name
            (Path(folder) / part).symlink_to(ROOT / "plc" / part)
        scenario = scenarios / path.name
        scenario.write_text(text, encoding="utf-8")
        report = Path(folder) / "r.json"
        result = invoke("verify", "--scenario", scenario, "--duration", "3s", "--json", report)
        assert result.exit_code in (0, 1, 2), result.output
        if result.exit_code == 2:
            assert re.search(rf"{re.escape(str(scenario))}:\d+:\d+: |\.st:\d+:\d+: ", result.stderr), result.stderr
            assert not report.exists()
        else:
            assert json.loads(report.read_text(encoding="utf-8"))["scenarios"]
        assert scenario.read_text(encoding="utf-8") == text


# --- options -----------------------------------------------------------------------------------

NUMBERS = ["0", "-1", "1", "0.5", "1e3", "1e309", "nan", "inf", "-inf", "9" * 30, "9" * 5000, "0x10", "1_000", "",
           " ", "\u0663", "\uff11", "1.5.2", "abc", "3:", ":3", "3:4", "3:-1", "3:999999999999", "0:0", "1:1:1",
           "5:nan", "2:1e400", "\x00"]
DURATIONS = ["0s", "1s", "-1s", "250ms", "1e3s", "10min", "99999999999999999999h", "1us", "0.5us", "1.5", "ms",
             "1 s", "1\u00b5s", "\u0663s", "\uff11s", "nan s", "1" * 5000 + "s", "0.0000000000000000000001s"]
EMULATE_OPTIONS = ["--baud", "--turnaround-ms", "--point-duration-s", "--no-reply-on", "--bad-crc-on",
                   "--garbage-on", "--wrong-address-on", "--exception-on", "--late-reply-on", "--anti-collision-at",
                   "--off-tape-at", "--low-battery-at", "--frame-gap-ms", "--address"]


@settings(FUZZ, max_examples=60)
@given(st.lists(st.tuples(st.sampled_from(["--tolerance", "--reply-timeout"]),
                          st.one_of(st.sampled_from(DURATIONS), st.text(max_size=4))), min_size=1, max_size=2))
def test_any_replay_duration_option_is_taken_or_refused_by_name(options):
    with tempfile.TemporaryDirectory() as folder:
        capture = Path(folder) / "site.txt"
        capture.write_bytes(CAPTURE)
        result = invoke("replay", capture, *[part for option in options for part in option])
    assert result.exit_code in (1, 2), result.output  # the capture breaks rules: 1 when the options are taken
    if result.exit_code == 2:
        assert "Invalid value for '--tolerance'" in result.stderr or "Invalid value for '--reply-timeout'" \
            in result.stderr, result.stderr


@settings(FUZZ, max_examples=60)
@given(st.lists(st.tuples(st.sampled_from(EMULATE_OPTIONS), st.one_of(st.sampled_from(NUMBERS), st.text(max_size=4))),
                min_size=1, max_size=3))
def test_any_emulate_number_option_is_taken_or_refused_by_name(options):
    args = [part for option in options for part in option]
    result = invoke("emulate", "--tcp", "127.0.0.1:0", *args, "--quiet", "--exit-after", "0.05")
    assert result.exit_code in (0, 2), result.output
    if result.exit_code == 2:
        assert any(f"'{name}'" in result.stderr or f"{name} " in result.stderr or f"{name}:" in result.stderr
                   for name, _ in options), result.stderr
