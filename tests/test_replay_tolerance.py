"""`uitamr replay`'s default timing tolerance: 20 ms for host-timed chunks, 0 for a capture
whose frames say their side (our JSONL traces, `tx`/`rx` lines), as `--help` says."""
from __future__ import annotations

import subprocess

import pytest

from monitor_helpers import WAIT_S, uitamr

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
    done = subprocess.run(uitamr("replay", capture, *extra), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode in (0, 1), done.stdout + done.stderr
    assert f"timing rules allow {allowed} ms" in done.stdout, done.stdout


def test_the_help_says_which_captures_get_no_tolerance():
    done = subprocess.run(uitamr("replay", "--help"), capture_output=True, text=True, timeout=WAIT_S)
    text = " ".join(done.stdout.split())
    assert "Default 20ms" in text and "tx/rx lines: 0" in text, text
