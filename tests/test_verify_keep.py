"""A run that keeps neither its frames nor its watched labels' changes and events (what
`uitamr verify` does when no report lists them: verifier.verify.result.Keep) reaches the
same verdict, findings, expectations, notes and frame counts as one that keeps
everything, and every report it can feed reads the same."""
from __future__ import annotations

import io
import json
import re
import sys
from pathlib import Path

import pytest
from rich.console import Console

from verifier.verify import report_console, report_junit
from verifier.verify.report_json import to_dict
from verifier.verify.result import Keep
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario
import procs

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))
NOTHING = Keep(frames=False, details=False)


def _console(result) -> str:
    out = io.StringIO()
    report_console.render([result], Console(file=out, width=200, highlight=False, soft_wrap=True), first=3)
    return out.getvalue()


def _junit(result, tmp_path) -> str:
    path = tmp_path / "r.xml"
    report_junit.write([result], path)
    return re.sub(r'time="[^"]*"', 'time=""', path.read_text(encoding="utf-8"))


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_keeping_nothing_changes_no_finding(path, tmp_path):
    scenario = load_scenario(path)
    full = run_scenario(scenario)
    lean = run_scenario(scenario, keep=NOTHING)
    assert lean.trace == [] and lean.watched == {} and lean.events == []
    assert (lean.tx_count, lean.rx_count) == (full.tx_count, full.rx_count)
    assert full.tx_count == sum(f.direction == "tx" for f in full.trace) and full.tx_count > 0
    for field in ("violations", "expectations", "notes", "aborted", "ended_us", "diagnostics"):
        assert getattr(lean, field) == getattr(full, field), field
    full.wall_s = lean.wall_s = 0.0
    assert _console(lean) == _console(full)
    assert _junit(lean, tmp_path) == _junit(full, tmp_path)
    lean_json, full_json = to_dict([lean]), to_dict([full])
    for data in (lean_json, full_json):
        data["scenarios"][0].pop("watched")
        data["scenarios"][0].pop("line_events")
    assert lean_json == full_json


def test_watched_changes_and_events_are_kept_without_the_frames():
    scenario = load_scenario(ROOT / "plc" / "scenarios" / "fx3u-healthy.toml")
    full = run_scenario(scenario)
    details_only = run_scenario(scenario, keep=Keep(frames=False, details=True))
    assert details_only.watched == full.watched and full.watched["fbEngine.o_wTxCount"]
    assert details_only.events == full.events and full.events
    assert details_only.trace == []


def _verify(*args, cwd):
    return procs.run([sys.executable, "-m", "verifier.cli", "verify", *map(str, args)],
                     capture_output=True, text=True, timeout=300, cwd=cwd)


def test_the_command_keeps_what_its_reports_list(tmp_path):
    """--json lists the watched labels and the events, --trace every frame: each still gets
    them when the other is not asked for."""
    scenario = ROOT / "plc" / "scenarios" / "fx3u-healthy.toml"
    done = _verify("--scenario", scenario, "--json", tmp_path / "r.json", cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
    data = json.loads((tmp_path / "r.json").read_text(encoding="utf-8"))["scenarios"][0]
    assert data["watched"]["fbEngine.o_wTxCount"][-1][1] == data["frames"]["tx"]
    assert any(event["kind"] == "robot.task" for event in data["line_events"])
    done = _verify("--scenario", scenario, "--trace", tmp_path / "t.jsonl", cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
    *lines, end = (tmp_path / "t.jsonl").read_text(encoding="utf-8").splitlines()
    assert sum('"dir": "tx"' in line for line in lines) == data["frames"]["tx"]
    assert len(lines) == data["frames"]["tx"] + data["frames"]["rx"]
    assert json.loads(end)["end"] == data["ended"]  # then the run's end record
