"""A failed expectation names where its scenario file states it (`verify/x.toml:12:8`), in
every report: the console, the JUnit failure (and the test case's `line`, which GitHub's
JUnit actions put their annotation on), the JSON and the HTML page
(docs/verifier.md, reading a report)."""
from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

from click.testing import CliRunner

from verifier.commands.verify import command

PLC = Path(__file__).resolve().parents[1] / "plc"
FX3_SOURCES = [
    *sorted((PLC / "core").glob("*.st")), *sorted((PLC / "fx3").glob("*.st")),
    *sorted((PLC / "examples" / "common").glob("*.st")), PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st",
]

SCENARIO = """\
name = "too tight"
program = "UITAMR_ExampleFx3"
platform = "fx3u"
duration = "3s"

[[expect]]
sent = "stop"
within = "1s"

[[expect]]
name = "the cycle runs"
that = "fbCycle.o_bCycle"
"""


def test_a_failed_expectation_names_its_line_in_the_scenario_file(tmp_path, monkeypatch):
    """Before, a failed expectation said "expected the cycle runs: 'fbCycle.o_bCycle' never
    became true ..." and nothing of where: with a dozen [[expect]] tables in a file, the
    integrator counted tables, and the JUnit test case carried no line, so a CI annotation
    stood at line 1 of the scenario file."""
    (tmp_path / "verify").mkdir()
    (tmp_path / "verify" / "x.toml").write_text(SCENARIO, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(command, [*map(str, FX3_SOURCES), "--scenario", "verify/x.toml", "--junit", "v.xml",
                                          "--json", "v.json", "--html", "v.html"], catch_exceptions=False)
    assert result.exit_code == 1, result.output
    place = "verify/x.toml:12:8"  # the value of `that = ...` in the second [[expect]]
    (failed,) = [line for line in result.output.splitlines() if "expected the cycle runs" in line]
    assert failed.rstrip().endswith(f"at {place}"), result.output

    (case,) = ET.parse(tmp_path / "v.xml").getroot().iter("testcase")
    assert (case.get("file"), case.get("line")) == ("verify/x.toml", "12")
    (failure,) = case.findall("failure")
    assert failure.get("message").endswith(f"at {place}")
    assert failure.text.startswith(f"{place}: expect[1]: 'fbCycle.o_bCycle' never became true")

    met, not_met = json.loads((tmp_path / "v.json").read_text())["scenarios"][0]["expectations"]
    assert (met["passed"], met["place"]) == (True, "verify/x.toml:7:8")
    assert (not_met["passed"], not_met["place"]) == (False, place)

    assert f'the cycle runs<div class="dim">{place}</div>' in (tmp_path / "v.html").read_text()


def test_an_expectation_no_file_states_names_no_place(tmp_path, monkeypatch):
    """The answered power-on stop a run without a scenario file expects has no line to
    name: no place, no `line` on the test case."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(command, [*map(str, FX3_SOURCES), "--program", "UITAMR_ExampleFx3",
                                          "--duration", "200ms", "--junit", "v.xml", "--json", "v.json"],
                                catch_exceptions=False)
    assert result.exit_code == 1, result.output
    (case,) = ET.parse(tmp_path / "v.xml").getroot().iter("testcase")
    assert case.get("line") is None
    assert " at " not in case.find("failure").get("message")
    (expectation,) = json.loads((tmp_path / "v.json").read_text())["scenarios"][0]["expectations"]
    assert expectation["place"] is None
