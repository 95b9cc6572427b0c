"""The tests' subprocesses, each in a process group of its own, so that a time-out ends
the whole group (a `uitamr verify --jobs 2` and its workers, socat and what it started)
and a hang fails the test cleanly and leaves nothing running.

`subprocess.run(timeout=...)` kills only the process it started, and `communicate(timeout=)`
of a Popen kills none: a `uitamr verify --jobs` that hung was left running with its
workers once its test had failed. Use `run` (a drop-in for subprocess.run that needs a
timeout) and `spawn` (a Popen); `finish` is `communicate` that ends the group on time-out.
Every group spawned here whose leader the test did not wait for is killed after the test
(conftest.py's autouse fixture calls `end_all`)."""
from __future__ import annotations

import os
import signal
import subprocess

#: spawned processes the test may not have waited for (end_all ends them)
_STARTED: list[subprocess.Popen] = []


def spawn(args, **kw) -> subprocess.Popen:
    """subprocess.Popen in a new session (its own process group, as a CI job runs it)."""
    proc = subprocess.Popen(args, start_new_session=True, **kw)
    _STARTED.append(proc)
    return proc


def kill_group(proc: subprocess.Popen, sig: int = signal.SIGKILL) -> None:
    """`sig` to every process of proc's group. Only while proc is not yet waited for: its
    pid (the group's id) cannot have been taken by another process until then."""
    if proc.returncode is None:
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:  # the whole group has ended already
            pass


def finish(proc: subprocess.Popen, timeout: float, input=None):
    """proc.communicate(input, timeout); on time-out the whole group is killed, and
    TimeoutExpired is raised with what the process wrote."""
    try:
        return proc.communicate(input, timeout=timeout)
    except subprocess.TimeoutExpired:
        kill_group(proc)
        out, err = proc.communicate()
        raise subprocess.TimeoutExpired(proc.args, timeout, out, err) from None


def run(args, *, timeout: float, input=None, capture_output: bool = False, check: bool = False,
        **kw) -> subprocess.CompletedProcess:
    """subprocess.run in a process group of its own, which a time-out kills whole."""
    if capture_output:
        kw["stdout"] = kw["stderr"] = subprocess.PIPE
    if input is not None:
        kw["stdin"] = subprocess.PIPE
    with spawn(args, **kw) as proc:
        out, err = finish(proc, timeout, input)
    done = subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
    if check:
        done.check_returncode()
    return done


def end_all() -> None:
    """Kill the group of every spawned process not waited for, and wait for it."""
    while _STARTED:
        proc = _STARTED.pop()
        kill_group(proc)
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:  # unkillable (D state): nothing more to do here
            pass
        # its pipes are left open: a test's reader thread may still be reading what came
        # (closing them under it raised ValueError in that thread)
