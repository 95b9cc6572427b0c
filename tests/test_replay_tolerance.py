"""`uitamr replay`'s default timing tolerance: 20 ms for host-timed chunks, 0 for a capture
whose frames say their side (our JSONL traces, `tx`/`rx` lines), as `--help` says."""
from __future__ import annotations

import json

import pytest

from monitor_helpers import WAIT_S, uitamr
import procs

CHUNKS = "0.001042 01\n0.001097 06 01 01 00 00 D9 F6\n0.012000 01 06 01 01 00 00 D9 F6\n"
SIDED = "0.001097 tx 01 06 01 01 00 00 D9 F6\n0.006417 rx 01 06 01 01 00 00 D9 F6\n"


@pytest.mark.parametrize("text, extra, allowed", [
    (CHUNKS, (), "20"),
    (SIDED, (), "0"),
    (SIDED, ("--tolerance", "20ms"), "20"),
    (CHUNKS, ("--tolerance", "0"), "0"),
    (CHUNKS, ("--tolerance", "0.00"), "0"),
    (CHUNKS, ("--tolerance", "-0"), "0"),
])
def test_default_tolerance_follows_the_kind_of_capture(tmp_path, text, extra, allowed):
    capture = tmp_path / "c.txt"
    capture.write_text(text, encoding="utf-8")
    done = procs.run(uitamr("replay", capture, *extra), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode in (0, 1), done.stdout + done.stderr
    assert f"timing rules allow {allowed} ms" in done.stdout, done.stdout


def test_the_help_says_which_captures_get_no_tolerance():
    done = procs.run(uitamr("replay", "--help"), capture_output=True, text=True, timeout=WAIT_S)
    text = " ".join(done.stdout.split())
    assert "Default 20ms" in text and "tx/rx lines: 0" in text, text


@pytest.mark.parametrize("command", ["replay", "monitor"])
@pytest.mark.parametrize("tolerance", ["20s", "250ms", "1min"])
def test_a_tolerance_that_no_pacing_violation_could_beat_is_refused(tmp_path, command, tolerance):
    """`--tolerance 20s` for 20ms passed the bad master's 100 ms pacing without a word
    (a period plus the tolerance must be 250 ms or less to be a violation)."""
    capture = tmp_path / "c.txt"
    capture.write_text(CHUNKS, encoding="utf-8")
    where = [capture] if command == "replay" else ["--serial", tmp_path / "nope"]
    done = procs.run(uitamr(command, "--tolerance", tolerance, *where), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"'{tolerance}' is not below the pacing period of 250 ms" in done.stderr
    assert "was the unit mistyped?" in done.stderr and "Traceback" not in done.stderr


def test_a_tolerance_just_below_the_period_is_taken(tmp_path):
    capture = tmp_path / "c.txt"
    capture.write_text(CHUNKS, encoding="utf-8")
    done = procs.run(uitamr("replay", "--tolerance", "249ms", capture), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode in (0, 1) and "timing rules allow 249 ms" in done.stdout, done.stdout + done.stderr


@pytest.mark.parametrize("recorded, refused", [(20, True), (0.25, True), (0.249, False), (0.02, False)])
def test_a_trace_that_records_a_tolerance_no_pacing_violation_could_beat_is_refused(tmp_path, recorded, refused):
    """A monitor trace whose records say "tolerance": 20 (a hand edit that lost "0.0") was
    replayed with 20 s and the bad master's three PACING violations were gone; only a note
    said so. `--tolerance 20s` is refused for the same reason."""
    from click.testing import CliRunner

    from verifier.cli import main

    trace = tmp_path / "site.jsonl"
    record = {"scenario": "site", "t": 0.0, "t_end": 0.0011, "dir": "tx", "hex": "01 06 01 01 00 00 D9 F6",
              "tolerance": recorded}
    later = dict(record, t=0.1, t_end=0.1011)
    trace.write_text(json.dumps(record) + "\n" + json.dumps(later) + "\n", encoding="utf-8")
    result = CliRunner().invoke(main, ["replay", str(trace)], catch_exceptions=False)
    if refused:
        assert result.exit_code == 2
        assert result.stderr == (f"uitamr replay: {trace}:1:1: 'tolerance' is {recorded} s; a monitor records its "
                                 "--tolerance, which is below the pacing period of 0.25 s\n")
    else:
        assert result.exit_code == 1 and "UITAMR-PACING" in result.output, result.output
