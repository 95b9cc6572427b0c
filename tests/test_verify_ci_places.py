"""What `uitamr verify` writes for CI points where to look: the JUnit test case's one
`file`/`line` (where GitHub's JUnit actions put their annotation) is its first finding's
place, the ST line to fix for a broken rule; a run without a scenario file names the
program's ST file; the JSON names its paths as it names every other; `--list-rules` does not
drop a report silently; the hint of a scenario without sources is right from its folder
(docs/verifier.md, reading a report; docs/ci.md)."""
from __future__ import annotations

import json
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

from click.testing import CliRunner

from verifier.commands.verify import command

PLC = Path(__file__).resolve().parents[1] / "plc"
FX3 = ["plc/core/*.st", "plc/fx3/*.st", "plc/examples/common/*.st", "plc/examples/fx3/UITAMR_ExampleFx3.st"]

# the library's 310 ms pace under a 2 s minimum period: UITAMR-PACING from the second request on
TOO_FAST = """\
name = "too fast"
program = "UITAMR_ExampleFx3"
platform = "fx3u"
duration = "2s"
sources = [{sources}]

[rules]
min_period = "2s"

[[expect]]
name = "the cycle runs"
that = "fbCycle.o_bCycle"
"""


def _project(tmp_path: Path, monkeypatch) -> Path:
    """A working folder as ci.md lays it out: the ST in plc/, the scenarios in verify/."""
    shutil.copytree(PLC, tmp_path / "plc", ignore=shutil.ignore_patterns("scenarios", "ladder"))
    (tmp_path / "verify").mkdir()
    monkeypatch.chdir(tmp_path)
    return tmp_path


def invoke(*args):
    return CliRunner().invoke(command, [str(a) for a in args], catch_exceptions=False)


def test_a_broken_rule_places_the_test_case_at_the_st_line_that_sent_its_first_frame(tmp_path, monkeypatch):
    """Before, the test case of a broken rule had `file` = the scenario file and no `line`
    (or the line of a failed expectation beside it), so GitHub annotated line 1 of the
    scenario, and the ST line to fix was only in the message ("sent by plc/...:134:9")."""
    _project(tmp_path, monkeypatch)
    (tmp_path / "verify" / "x.toml").write_text(
        TOO_FAST.format(sources=", ".join(f'"../{s}"' for s in FX3)), encoding="utf-8")
    result = invoke("--scenario", "verify/x.toml", "--junit", "v.xml", "--json", "v.json")
    assert result.exit_code == 1, result.output
    report = json.loads((tmp_path / "v.json").read_text(encoding="utf-8"))["scenarios"][0]
    sent_by = report["violations"][0]["origin"]
    assert sent_by.startswith("plc/fx3/UITAMR_PortFx3.st:")
    assert f"sent by {sent_by}" in result.output  # the console's, the place the JUnit carries
    (case,) = ET.parse(tmp_path / "v.xml").getroot().iter("testcase")
    file, line, _ = sent_by.rsplit(":", 2)
    assert (case.get("file"), case.get("line")) == (file, line)
    # the rule's failure is listed first: the annotation's message is the finding it points at
    assert [f.get("type") for f in case.findall("failure")] == ["UITAMR-PACING", "expectation"]
    # the failed expectation keeps its own place in its message, as before
    assert case.findall("failure")[1].get("message").endswith("at verify/x.toml:12:8")
    assert report["place"] == sent_by


def test_a_stopped_cpu_places_the_test_case_at_the_st_statement_that_stopped_it(tmp_path, monkeypatch):
    (tmp_path / "Crash.st").write_text(
        "PROGRAM Crash\nVAR\n    a : ARRAY[0..3] OF INT;\n    i : INT;\nEND_VAR\ni := i + 1;\na[i] := 1;\nEND_PROGRAM\n",
        encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("Crash.st", "--platform", "fx3u", "--duration", "1s", "--junit", "v.xml", "--json", "v.json")
    assert result.exit_code == 1, result.output
    (case,) = ET.parse(tmp_path / "v.xml").getroot().iter("testcase")
    assert (case.get("file"), case.get("line")) == ("Crash.st", "7")
    assert json.loads((tmp_path / "v.json").read_text(encoding="utf-8"))["scenarios"][0]["place"] == "Crash.st:7:3"


def test_a_run_without_a_scenario_file_names_the_programs_st_file(tmp_path, monkeypatch):
    """Before, `uitamr verify plc/*.st --program MAIN` wrote test cases without `file`."""
    _project(tmp_path, monkeypatch)
    result = invoke(*FX3, "--program", "UITAMR_ExampleFx3", "--duration", "200ms", "--junit", "v.xml")
    assert result.exit_code == 1, result.output  # the power-on stop is not answered within 200 ms
    (case,) = ET.parse(tmp_path / "v.xml").getroot().iter("testcase")
    assert (case.get("file"), case.get("line")) == ("plc/examples/fx3/UITAMR_ExampleFx3.st", None)


def test_the_json_names_its_sources_as_it_names_every_other_path(tmp_path, monkeypatch):
    """Before, `sources` were absolute (a scenario's are found from its folder) while `file`,
    the origins and the places were relative to the working folder."""
    _project(tmp_path, monkeypatch)
    (tmp_path / "verify" / "x.toml").write_text(
        TOO_FAST.format(sources='"../plc/fx3/*.st", "../plc/core", "../plc/examples/common/*.st", '
                                '"../plc/examples/fx3/UITAMR_ExampleFx3.st"'), encoding="utf-8")
    outside = tmp_path.parent / f"{tmp_path.name}-outside.st"  # a source beyond the working folder stays whole
    shutil.copy(PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st", outside)
    try:
        assert invoke("--scenario", "verify/x.toml", "--json", "v.json").exit_code == 1
        sources = json.loads((tmp_path / "v.json").read_text(encoding="utf-8"))["scenarios"][0]["sources"]
        assert "plc/fx3/UITAMR_PortFx3.st" in sources and "plc/examples/fx3/UITAMR_ExampleFx3.st" in sources
        assert all(not Path(s).is_absolute() and (tmp_path / s).is_file() for s in sources), sources
        given = [*FX3[:3], outside]
        assert invoke(*given, "--program", "UITAMR_ExampleFx3", "--duration", "200ms", "--json", "w.json").exit_code == 1
        sources = json.loads((tmp_path / "w.json").read_text(encoding="utf-8"))["scenarios"][0]["sources"]
        assert str(outside) in sources and "plc/core/UITAMR_Engine.st" in sources
    finally:
        outside.unlink()


def test_list_rules_refuses_a_report_it_would_not_write(tmp_path, monkeypatch):
    """Before, `uitamr verify --list-rules --junit r.xml` printed the rules, exited 0 and
    wrote no r.xml: a CI job read an earlier run's file, or none."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(command, ["--list-rules", "--junit", "r.xml"])
    assert result.exit_code == 2
    said = "--list-rules prints the rules and exits: it runs nothing and writes no report, so --junit would do nothing"
    assert said in " ".join(result.output.split())
    (error,) = ET.parse(tmp_path / "r.xml").getroot().iter("error")  # the mistake, as for any usage mistake
    assert error.get("message").startswith(said)
    result = CliRunner().invoke(command, ["--list-rules", "plc", "--html", "r.html"])
    assert result.exit_code == 2 and "so SOURCES, --html would do nothing; leave them out" in result.output
    assert not (tmp_path / "r.html").exists()
    assert CliRunner().invoke(command, ["--list-rules"]).exit_code == 0


def test_the_hint_of_a_scenario_without_sources_is_right_from_its_folder(tmp_path, monkeypatch):
    """Before, it said `sources = ["plc/*.st"], relative to it` for verify/x.toml too, where
    the right value is "../plc/*.st"."""
    _project(tmp_path, monkeypatch)
    (tmp_path / "plc" / "MAIN.st").write_text("PROGRAM MAIN\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n",
                                             encoding="utf-8")
    (tmp_path / "verify" / "x.toml").write_text('program = "MAIN"\n', encoding="utf-8")
    result = invoke("--scenario", "verify/x.toml")
    assert result.exit_code == 2
    shown = " ".join(result.output.split())
    assert 'list them in the file (sources = ["../plc/*.st"] for the .st files in plc/: paths relative' in shown
    (tmp_path / "plc" / "MAIN.st").unlink()  # no .st file right inside a folder: a plc/ said as an example
    shutil.rmtree(tmp_path / "plc" / "core")
    result = invoke("--scenario", "verify/x.toml")
    assert 'sources = ["../plc/*.st"] for .st files in plc/ of the working folder' in " ".join(result.output.split())
    (tmp_path / "x.toml").write_text('program = "MAIN"\n', encoding="utf-8")
    result = invoke("--scenario", "x.toml")
    assert 'sources = ["plc/*.st"] for .st files in plc/ of the working folder' in " ".join(result.output.split())


def test_verifier_md_says_where_each_finding_places_the_test_case(tmp_path, monkeypatch):
    """verifier.md, `--junit FILE`: the three places it lists, in its order, are what the
    JUnit test case carries for each kind of finding: the stopped CPU, the console example's
    library paced at 200 ms (sent by lib/fx3/UITAMR_PortFx3.st:134:9), and a failed
    expectation of test_verify_expect_place's scenario."""
    import re

    from test_verify_expect_place import SCENARIO

    page = (Path(__file__).resolve().parents[1] / "docs" / "verifier.md").read_text(encoding="utf-8")
    section = page.split("### `--junit FILE`", 1)[1].split("\n### ", 1)[0]
    listed = re.findall(r'^\d\. (.*?)`file="([^"]+)" line="(\d+)"`', section, re.M | re.S)
    kinds = ["stopped the CPU", "**sent by**", "first failed expectation"]
    assert len(listed) == len(kinds) and all(kind in what for kind, (what, _, _) in zip(kinds, listed)), listed

    def placed(*args) -> tuple[str, str]:
        result = CliRunner().invoke(command, [*map(str, args), "--junit", "v.xml"], catch_exceptions=False)
        assert result.exit_code == 1, result.output
        (case,) = ET.parse("v.xml").getroot().iter("testcase")
        return case.get("file"), case.get("line")

    (tmp_path / "stop").mkdir()
    monkeypatch.chdir(tmp_path / "stop")
    Path("Crash.st").write_text(
        "PROGRAM Crash\nVAR\n    a : ARRAY[0..3] OF INT;\n    i : INT;\nEND_VAR\ni := i + 1;\na[i] := 1;\nEND_PROGRAM\n",
        encoding="utf-8")
    assert placed("Crash.st", "--platform", "fx3u", "--duration", "1s") == listed[0][1:]

    shutil.copytree(PLC, tmp_path / "paced" / "lib")
    monkeypatch.chdir(tmp_path / "paced")
    engine = Path("lib/core/UITAMR_Engine.st")
    engine.write_text(engine.read_text(encoding="utf-8").replace("PACE_TIME : TIME := T#300ms;",
                                                                 "PACE_TIME : TIME := T#200ms;"), encoding="utf-8")
    assert placed("--scenario", "lib/scenarios/fx3u-healthy.toml", "--duration", "2s") == listed[1][1:]

    (tmp_path / "expect" / "verify").mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "expect")
    Path("verify/x.toml").write_text(SCENARIO, encoding="utf-8")
    sources = [*sorted((PLC / "core").glob("*.st")), *sorted((PLC / "fx3").glob("*.st")),
               *sorted((PLC / "examples" / "common").glob("*.st")), PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st"]
    assert placed(*sources, "--scenario", "verify/x.toml") == listed[2][1:]
