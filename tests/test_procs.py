"""tests/procs.py: a test's subprocess that hangs past its time-out is ended with its whole
process group, so the test fails cleanly and leaves no process behind (subprocess.run kills
only the process it started: a `uitamr verify --jobs 2` that hung left its workers)."""
from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

import procs

#: a process that starts a child, writes the child's pid and then hangs, as a hung
#: `uitamr verify --jobs 2` with its workers does
HANGS_WITH_A_CHILD = ("import subprocess, sys, time\n"
                      "child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(600)'])\n"
                      "print(child.pid, flush=True)\n"
                      "time.sleep(600)\n")


def _gone(pid: int) -> bool:
    """pid has ended (a zombie not yet reaped by init counts as ended)."""
    for _ in range(200):
        try:
            with open(f"/proc/{pid}/stat") as stat:
                if stat.read().rsplit(")", 1)[1].split()[0] == "Z":
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False


def test_a_run_past_its_time_out_ends_the_whole_group(tmp_path):
    with pytest.raises(subprocess.TimeoutExpired) as hung:
        procs.run([sys.executable, "-c", HANGS_WITH_A_CHILD], capture_output=True, text=True, timeout=3)
    child = int(hung.value.stdout.split()[0])
    assert _gone(child), "the child of the timed-out process still runs"


def test_what_a_test_left_running_is_ended_after_it():
    proc = procs.spawn([sys.executable, "-c", HANGS_WITH_A_CHILD], stdout=subprocess.PIPE, text=True)
    child = int(proc.stdout.readline())
    procs.end_all()  # what conftest's fixture does after each test
    assert proc.returncode is not None and _gone(child)
    assert _gone(proc.pid)
