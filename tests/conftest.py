"""Fixtures shared by several test files."""
from __future__ import annotations

import pytest

import verifier.sim.project as project_module


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
