"""Fixtures shared by several test files."""
from __future__ import annotations

import pytest

import procs
import verifier.sim.project as project_module


@pytest.fixture(autouse=True)
def _no_process_left():
    """What a test spawned through procs.spawn/run and did not wait for (it failed or hung
    first) is killed with its whole process group after the test."""
    yield
    procs.end_all()


@pytest.fixture
def idle_runs(monkeypatch):
    """The IdleScans of every run started in the test, to see how much each skipped."""
    made = []
    original = project_module.Project.skip_idle_scans

    def recording(self, *args, **kwargs):
        made.append(original(self, *args, **kwargs))
        return made[-1]

    monkeypatch.setattr(project_module.Project, "skip_idle_scans", recording)
    return made
