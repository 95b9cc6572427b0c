"""The reports: JSON verdict, JUnit XML as CI servers read it, the JSON Lines trace, the console
summary, and the HTML page rendered in headless Chromium and checked from its DOM."""
from __future__ import annotations

import dataclasses
import io
import json
import re
import shutil
import tempfile
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

from rich.console import Console

from verifier import protocol
from verifier.verify import report_console, report_html, report_json, report_junit, report_trace
from verifier.verify.conditions import parse_condition
from verifier.verify.evidence import RunEvidence
from verifier.verify.expectations import Expectation, ExpectationResult
from verifier.verify.result import LineEvent, ScenarioResult, TraceRecord
from verifier.verify.rules import RULES, check_all
import procs

S = protocol.Settings()
STOP = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, protocol.RobotCommand.STOP)
POINT3 = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, 3)
READ = protocol.StatusRequest(1, protocol.Query.TASK)


def _frames(t_us: int, request, reply) -> list[TraceRecord]:
    data = protocol.encode(request, S)
    end = t_us + protocol.frame_time_us(len(data))
    out = [TraceRecord(t_us, end, "tx", data, "UITAMR_Engine.st:210:9")]
    if reply is not None:
        answer = protocol.encode(reply, S)
        out.append(TraceRecord(end + 5000, end + 5000 + protocol.frame_time_us(len(answer)), "rx", answer))
    return out


def _result(name: str, trace: list[TraceRecord], end_us: int, expectations=()) -> ScenarioResult:
    evidence = RunEvidence(S, trace, end_us)
    return ScenarioResult(
        name=name, file=f"plc/scenarios/{name}.toml", description=f"{name} <desc & more>",
        program="Main", platform="fx3u", channel="fx3:1", sources=["Main.st"], duration_us=end_us,
        scan_us=10_000, seed=0, settings=S, trace=trace, violations=check_all(evidence),
        expectations=list(expectations), ended_us=end_us,
        events=[LineEvent(1_000_000, "collision", "both sides transmitted")],
        faults=["no_reply at 10 s for 2 s"],
    )


def good_result() -> ScenarioResult:
    trace = _frames(0, STOP, protocol.ControlReply.echo(STOP))
    for i in range(1, 20):
        trace += _frames(300_000 * i, READ, protocol.StatusReply(1, 0, 0))
    met = ExpectationResult(Expectation("that", "o_bOK within 2 s", condition=parse_condition("o_bOK")), True, "true at 0.400 s", 400_000)
    return _result("healthy", trace, 6_000_000, [met])


def bad_result() -> ScenarioResult:
    trace = _frames(0, POINT3, protocol.ControlReply.echo(POINT3))
    for i in range(1, 10):
        trace += _frames(200_000 * i, READ, protocol.StatusReply(1, 0, 1))
    missed = ExpectationResult(Expectation("reached_point", "robot reached point 3", point=3), False, "did not finish")
    return _result("broken", trace, 2_500_000, [missed])


def test_json_has_a_top_level_verdict_and_every_violation(tmp_path):
    path = tmp_path / "r.json"
    report_json.write([good_result(), bad_result()], path)
    data = json.loads(path.read_text())
    assert data["verdict"] == "fail"
    healthy, broken = data["scenarios"]
    assert healthy["verdict"] == "pass" and broken["verdict"] == "fail"
    assert broken["rules"]["UITAMR-PACING"] == {"status": "fail", "violations": 9}
    assert broken["rules"]["UITAMR-POWERON-STOP"]["violations"] == 1
    first = broken["violations"][0]
    assert first["rule"] == "UITAMR-POWERON-STOP" and first["t"] == 0.0
    assert first["frames"][0]["hex"] == "01 06 01 03 00 00 78 36"
    assert first["origin"] == "UITAMR_Engine.st:210:9"
    assert broken["expectations"][0]["passed"] is False
    assert data["summary"]["violations"]["UITAMR-PACING"] == 9
    assert [r["id"] for r in data["rules"]] == [r.id for r in RULES]
    report_json.write([good_result()], path)
    assert json.loads(path.read_text())["verdict"] == "pass"


def test_junit_has_one_testcase_per_scenario_and_a_failure_per_broken_rule(tmp_path):
    path = tmp_path / "r.xml"
    report_junit.write([good_result(), bad_result()], path)
    root = ET.parse(path).getroot()
    assert root.tag == "testsuites" and root.get("tests") == "2" and root.get("failures") == "3"
    cases = root.findall("./testsuite/testcase")
    assert [c.get("name") for c in cases] == ["healthy", "broken"]
    assert cases[0].find("failure") is None
    kinds = sorted(f.get("type") for f in cases[1].findall("failure"))
    assert kinds == ["UITAMR-PACING", "UITAMR-POWERON-STOP", "expectation"]
    pacing = next(f for f in cases[1].findall("failure") if f.get("type") == "UITAMR-PACING")
    assert pacing.get("message").startswith("UITAMR-PACING: 9 violation(s); first at 0.200 s")
    assert "01 01 00 00 00 16 BD C4" in pacing.text
    # the annotation's place: the ST statement that sent the first broken rule's first frame
    assert (cases[1].get("file"), cases[1].get("line")) == ("UITAMR_Engine.st", "210")
    assert (cases[0].get("file"), cases[0].get("line")) == ("plc/scenarios/healthy.toml", None)


def test_junit_keeps_runs_that_share_a_name_apart(tmp_path):
    """A copied scenario file that kept its name: a CI server would file the two runs as
    one test, so each such case is named with its file (or a number without one)."""
    from dataclasses import replace

    copy = replace(good_result(), file="plc/scenarios/healthy-copy.toml")
    unfiled = replace(good_result(), file=None)
    path = tmp_path / "r.xml"
    report_junit.write([good_result(), bad_result(), copy, unfiled], path)
    names = [c.get("name") for c in ET.parse(path).getroot().findall("./testsuite/testcase")]
    assert names == ["healthy [plc/scenarios/healthy.toml]", "broken", "healthy [plc/scenarios/healthy-copy.toml]",
                     "healthy [3]"]


def test_the_same_file_run_twice_gets_a_number_after_its_file(tmp_path):
    path = tmp_path / "r.xml"
    report_junit.write([good_result(), bad_result(), good_result()], path)
    names = [c.get("name") for c in ET.parse(path).getroot().findall("./testsuite/testcase")]
    assert names == ["healthy [plc/scenarios/healthy.toml #1]", "broken", "healthy [plc/scenarios/healthy.toml #2]"]


def test_trace_is_one_frame_per_line_with_time_direction_hex_and_meaning(tmp_path):
    path = tmp_path / "t.jsonl"
    report_trace.write([bad_result()], path)
    lines = path.read_text().splitlines()
    *records, end = [json.loads(line) for line in lines]
    assert len(records) == 20
    result = bad_result()  # the run's end and the rules' settings it was judged with
    assert end == {"scenario": "broken", "end": result.ended_us / 1e6, "reply_timeout": result.reply_timeout_us / 1e6,
                   "min_period": result.min_period_us / 1e6, "response_within": result.response_within_us / 1e6,
                   "protocol": dataclasses.asdict(result.settings)}
    first, reply = records[0], records[1]
    assert first["t"] == 0.0 and first["dir"] == "tx" and first["hex"] == "01 06 01 03 00 00 78 36"
    assert "point" in first["meaning"] and first["origin"] == "UITAMR_Engine.st:210:9"
    assert first["rules"] == ["UITAMR-PACING", "UITAMR-POWERON-STOP"]  # evidence for both
    assert reply["dir"] == "rx" and reply["t"] > first["t_end"]
    assert "running" in records[3]["meaning"]
    assert all(isinstance(r["t"], float) for r in records)


def test_console_summary_shows_verdict_counts_and_first_violations():
    out = io.StringIO()
    report_console.render([good_result(), bad_result()], Console(file=out, width=200, color_system=None))
    text = out.getvalue()
    assert "PASS healthy" in text and "FAIL broken" in text
    assert "UITAMR-POWERON-STOP, first at 0.000 s: the first control command" in text
    assert "sent by UITAMR_Engine.st:210:9" in text
    assert "UITAMR-PACING ×9, first at 0.200 s" in text
    assert "also at 0.400 s, 0.600 s and 6 more" in text
    assert "expected robot reached point 3: did not finish" in text
    assert text.rstrip().endswith("FAIL: 1 of 2 scenario(s) failed")


def test_console_lists_five_kinds_of_simulator_note_and_counts_the_rest():
    from verifier.sim.errors import SimDiagnostic
    from verifier.verify.result import summarize_diagnostics

    diagnostics = [SimDiagnostic(1000 * i, f"Main.st:{i % 7 + 1}:1", 0, f"note kind {chr(65 + i % 7)}: {i} byte(s)")
                   for i in range(70)]
    result = good_result()
    result.diagnostic_summary = summarize_diagnostics(diagnostics)
    assert result.diagnostic_summary[0] == "×10, first at 0.000 s: note kind A: 0 byte(s)  at Main.st:1:1"
    out = io.StringIO()
    report_console.render([result], Console(file=out, width=200, color_system=None))
    lines = [line for line in out.getvalue().splitlines() if line.startswith("    simulator ")]
    assert len(lines) == 6 and lines[-1] == "    simulator and 2 more kind(s) of note (see --json or --html)"


def test_a_capture_with_no_traffic_neither_passes_nor_fails():
    """A monitored line or a capture with no bytes verified nothing: its verdict is
    "no-traffic" (any failure elsewhere still makes the whole run fail)."""
    from dataclasses import replace

    from verifier.verify.result import NO_TRAFFIC, overall_verdict

    silent = replace(_result("silent", [], 0), no_traffic="no bytes were seen on COM5 in 20.0 s: check the wiring")
    assert silent.verdict == NO_TRAFFIC == "no-traffic" and not silent.passed
    assert overall_verdict([silent]) == overall_verdict([good_result(), silent]) == NO_TRAFFIC
    assert overall_verdict([silent, bad_result()]) == "fail" and overall_verdict([good_result()]) == "pass"
    out = io.StringIO()
    report_console.render([good_result(), silent], Console(file=out, width=200, color_system=None))
    text = out.getvalue()
    assert "NO TRAFFIC silent" in text and "violations per rule" in text
    assert text.rstrip().endswith("NO TRAFFIC: no bytes were seen on COM5 in 20.0 s: check the wiring")
    data = report_json.to_dict([good_result(), silent])
    assert data["verdict"] == "no-traffic" and data["summary"]["no_traffic"] == 1
    assert [s["no_traffic"] for s in data["scenarios"]] == [None, silent.no_traffic]


def test_a_capture_cut_short_neither_passes_nor_outranks_a_failure():
    """A capture whose port went away (`uitamr monitor`) was verified only in part: with
    frames that broke no rule its verdict is "cut-short", not "pass"; a rule its frames broke
    still fails it, and a capture with nothing at all ranks first among the rest. Each
    report counts it: passed + failed + no_traffic + cut_short = scenarios."""
    from dataclasses import replace

    from verifier.verify.result import CUT_SHORT, NO_TRAFFIC, overall_verdict

    said = "COM5 went away after 5.2 s of the 600 s asked: the 12 frame(s) before it were verified, but ..."
    cut = replace(good_result(), cut_short=said)
    silent = replace(_result("silent", [], 0), no_traffic="no bytes were seen on COM6 in 20.0 s: check the wiring")
    failed = replace(bad_result(), cut_short=said)
    assert cut.verdict == CUT_SHORT == "cut-short" and not cut.passed
    assert failed.verdict == "fail" and failed.unverified == [(CUT_SHORT, said)]
    assert overall_verdict([good_result(), cut]) == CUT_SHORT and overall_verdict([cut, silent]) == NO_TRAFFIC
    assert overall_verdict([cut, bad_result()]) == "fail"
    out = io.StringIO()
    report_console.render([good_result(), cut], Console(file=out, width=400, color_system=None))
    assert "CUT SHORT" in out.getvalue() and out.getvalue().rstrip().endswith(f"CUT SHORT: {said}")
    out = io.StringIO()
    report_console.render([cut, silent, failed], Console(file=out, width=400, color_system=None))
    assert out.getvalue().rstrip().endswith("FAIL: 1 of 3 scenario(s) failed, 1 saw no traffic, 1 cut short")
    data = report_json.to_dict([good_result(), cut, silent, failed])
    assert [s["verdict"] for s in data["scenarios"]] == ["pass", "cut-short", "no-traffic", "fail"]
    assert [s["cut_short"] for s in data["scenarios"]] == [None, said, None, said]
    assert {key: data["summary"][key] for key in ("scenarios", "passed", "failed", "no_traffic", "cut_short")} == {
        "scenarios": 4, "passed": 1, "failed": 1, "no_traffic": 1, "cut_short": 1}


def test_the_last_line_of_a_capture_with_no_traffic_counts_the_ones_cut_short_too():
    """`uitamr replay` of a cut-short monitor trace and an empty capture exits 3 (no traffic
    ranks first), and its last line said the empty one's sentence alone: the session cut
    short was not named where the verdict is read, though the FAIL line counts both. It now
    counts them after the sentence (verifier.md: the console's last line counts them)."""
    from dataclasses import replace

    said = "COM5 went away after 5.2 s of the 600 s asked: the 12 frame(s) before it were verified, but ..."
    cut = replace(good_result(), cut_short=said)
    silent = replace(_result("silent", [], 0), no_traffic="no bytes were seen on COM6 in 20.0 s: check the wiring")
    out = io.StringIO()
    report_console.render([cut, silent, silent], Console(file=out, width=400, color_system=None))
    assert out.getvalue().rstrip().endswith(
        "NO TRAFFIC: no bytes were seen on COM6 in 20.0 s: check the wiring (and 1 more capture(s) with no bytes); "
        "1 cut short"), out.getvalue()
    out = io.StringIO()
    report_console.render([silent, good_result()], Console(file=out, width=400, color_system=None))
    assert out.getvalue().rstrip().endswith("NO TRAFFIC: no bytes were seen on COM6 in 20.0 s: check the wiring")


def test_captures_are_counted_as_captures_without_expectations():
    """`uitamr replay` of a capture said "PASS: 1 scenario(s) compliant, every expectation met"
    and "0 expectation(s) met" for a run that was no scenario and could have no expectation;
    the page said "scenario(s)" too, with a column of "0 / 0 met" in its index. Simulated runs
    keep their words."""
    from dataclasses import replace

    from verifier.verify.result import LINE

    captured = [replace(good_result(), platform=LINE, program=None, expectations=[], name=f"site{i}.txt")
                for i in (1, 2)]
    out = io.StringIO()
    report_console.render(captured, Console(file=out, width=200, color_system=None))
    lines = out.getvalue().splitlines()
    assert lines[0] == "PASS site1.txt (plc/scenarios/healthy.toml): the PLC on the line, 20 requests in 6.000 s, 0 violation(s)"
    assert lines[-1] == "PASS: 2 capture(s) compliant"
    out = io.StringIO()
    report_console.render([captured[0], replace(bad_result(), platform=LINE, expectations=[])],
                          Console(file=out, width=200, color_system=None))
    assert out.getvalue().rstrip().endswith("FAIL: 1 of 2 capture(s) failed")
    page = report_html.render([captured[0], replace(bad_result(), platform=LINE, expectations=[])])
    assert "1 of 2 capture(s) compliant" in page and "<h2>Captures</h2>" in page
    assert "<th>capture</th>" in page and "<th>expectations</th>" not in page and " met</td>" not in page
    out = io.StringIO()
    report_console.render([good_result()], Console(file=out, width=200, color_system=None))
    assert "1 expectation(s) met" in out.getvalue()
    assert out.getvalue().rstrip().endswith("PASS: 1 scenario(s) compliant, every expectation met")
    page = report_html.render([good_result(), bad_result()])
    assert "1 of 2 scenario(s) compliant" in page and "<h2>Scenarios</h2>" in page
    assert "<th>scenario</th>" in page and "<th>expectations</th>" in page and "1 / 1 met</td>" in page


def test_console_lists_as_many_times_per_rule_as_asked():
    out = io.StringIO()
    report_console.render([bad_result()], Console(file=out, width=200, color_system=None), first=1)
    text = out.getvalue()
    assert "UITAMR-PACING ×9, first at 0.200 s" in text and "also at" not in text
    out = io.StringIO()
    report_console.render([bad_result()], Console(file=out, width=200, color_system=None), first=20)
    assert "and 6 more" not in out.getvalue() and "1.800 s" in out.getvalue()


def _chromium() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    assert found, "chromium is required (CI installs it: apt-get install chromium)"
    return found


def _chromium_flags(profile: str) -> list[str]:
    return [
        "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        f"--user-data-dir={profile}", "--window-size=1400,1000",
    ]


def test_html_report_renders_in_chromium_with_a_timing_diagram_and_violation_markers(tmp_path):
    page = tmp_path / "report.html"
    report_html.write([good_result(), bad_result()], page)
    html = page.read_text()
    assert not re.search(r"(src|href)=\"?(https?:)?//|<link|@import|url\(", html)  # self-contained
    root = _rendered(page.as_uri())
    sections = [s for s in root.iter("section") if "scenario" in (s.get("class") or "")]
    assert [s.get("data-verdict") for s in sections] == ["pass", "fail"]
    good, bad = sections
    assert _count(good, "rect", "frame") == 40 and _count(good, "g", "violation") == 0
    assert _count(bad, "rect", "frame") == 20
    markers = [g for g in bad.iter("g") if "violation" in (g.get("class") or "").split()]
    assert len(markers) == 10
    assert {m.get("data-rule") for m in markers} == {"UITAMR-PACING", "UITAMR-POWERON-STOP"}
    windows = [r for r in bad.iter("rect") if "window" in (r.get("class") or "").split()]
    assert len(windows) == 10 and sum("broken" in r.get("class") for r in windows) == 9
    # the script laid the diagram out: every frame has a position and a visible width
    frames = [r for r in bad.iter("rect") if "frame" in (r.get("class") or "").split()]
    assert all(float(r.get("width")) >= 2 for r in frames)
    assert sorted(float(r.get("x")) for r in frames) == [float(r.get("x")) for r in frames]
    events = [g for g in bad.iter("g") if "event" in (g.get("class") or "").split()]
    assert [(g.get("data-kind"), g.get("class")) for g in events] == [("collision", "event line")]
    assert root.find(".//*[@id='verdict']").text == "FAIL"
    index = root.find(".//*[@id='index']")
    assert [a.get("href") for a in index.iter("a")] == ["#s0", "#s1"]


def long_result() -> ScenarioResult:
    """Over 4,000 frames (about 10 minutes of status polls), one request too early at 615 s."""
    trace = _frames(0, STOP, protocol.ControlReply.echo(STOP))
    for i in range(1, 2101):
        t = 300_000 * i - (100_000 if i == 2050 else 0)
        trace += _frames(t, READ, protocol.StatusReply(1, 0, 0))
    return _result("long", trace, 631_000_000)


def test_html_of_a_long_run_draws_what_a_page_can_hold_and_says_so(tmp_path):
    """A soak test's page opens at once: the diagram and the table hold the frames around
    each violation and the run's first ones, the overview strip marks the whole run, and
    the page says what it left out and where every frame is."""
    result = long_result()
    assert len(result.trace) == 4202
    page = tmp_path / "report.html"
    report_html.write([result], page)
    html = page.read_text()
    assert "the diagram and the frame table show 4000 of its 4202 frames" in html
    assert "4000 of the 4202 frames" in html and "--trace lists them" in html
    root = _rendered(page.as_uri())
    frames = [r for r in root.iter("rect") if "frame" in (r.get("class") or "").split()]
    assert len(frames) == report_html.FRAMES_AT_MOST
    blamed = [float(r.get("data-t0")) for r in frames if "blamed" in r.get("class")]
    assert blamed == [614_700.0, 614_900.0]  # the request before and the early one
    assert max(float(r.get("data-t0")) for r in frames) == 615_600.0  # 4 frames after it
    rows = [tr for tr in root.iter("tr") if "left-out" in (tr.get("class") or "")]
    left_out = [int(re.search(r"… (\d+) frame", "".join(tr.itertext())).group(1)) for tr in rows]
    assert sum(left_out) == 202 and len(rows) == 2  # between the first frames and the violation, and after
    overview = [line for line in root.iter("line") if (line.get("class") or "").startswith("ov")]
    assert 1000 < len(overview) < 4202 and max(float(line.get("x1")) for line in overview) > 990
    assert root.find(".//*[@id='verdict']").text == "FAIL"


def test_a_page_of_many_runs_shares_its_frames_between_them(monkeypatch):
    """A --matrix of soak tests would draw FRAMES_AT_MOST frames for each run: the page
    shares PAGE_FRAMES_AT_MOST between them instead (each keeps a floor); a page with
    fewer frames in all is drawn whole."""
    results = [good_result(), long_result(), long_result()]
    assert report_html.frames_each(results[:1]) == report_html.FRAMES_AT_MOST
    monkeypatch.setattr(report_html, "PAGE_FRAMES_AT_MOST", 3000)
    monkeypatch.setattr(report_html, "FRAMES_EACH_AT_LEAST", 200)
    assert report_html.frames_each(results) == 1000
    html = report_html.render(results)
    assert html.count('class="frame ') == 40 + 1000 + 1000  # the short run whole, the long ones 1000 each
    assert html.count("show 1000 of its 4202 frames") == 2
    monkeypatch.setattr(report_html, "PAGE_FRAMES_AT_MOST", 300)
    assert report_html.frames_each(results) == 200


def test_html_lists_at_most_so_many_violations_and_points_to_the_json(tmp_path, monkeypatch):
    monkeypatch.setattr(report_html, "VIOLATIONS_AT_MOST", 3)
    page = tmp_path / "report.html"
    report_html.write([bad_result()], page)
    html = page.read_text()
    assert "Violations (10)" in html and "The first 3 are marked and listed" in html
    assert html.count('class="violation-row"') == 3 and html.count('<g class="violation"') == 3


def test_html_of_a_run_with_many_events_says_only_what_it_left_out(monkeypatch):
    from dataclasses import replace

    monkeypatch.setattr(report_html, "EVENTS_AT_MOST", 10)
    result = replace(good_result(), events=[LineEvent(1000 * i, "robot.task", "done") for i in range(30)])
    note = re.search(r"<b>A long run:</b>.*?</p>", report_html.render([result])).group(0)
    assert "the diagram shows 10 of its 30 events (the faults first)" in note
    assert "frames (" not in note  # every frame is drawn: nothing said of them


def test_html_diagram_zooms_in_the_browser(tmp_path):
    page = tmp_path / "report.html"
    report_html.write([bad_result()], page)
    root = _rendered(page.as_uri() + "#zoom=8")
    svg = root.find(".//svg[@id='s0-svg']")
    assert svg.get("width") == str(round(2_500 * 8 + 40))  # 2.5 s of virtual time at 8 px/ms
    assert "zoomed" in svg.get("class")  # frame labels are shown from 8 px/ms on
    first = next(r for r in svg.iter("rect") if "frame" in (r.get("class") or "").split())
    assert float(first.get("width")) == round(8.333 * 8, 2)
    assert root.find(".//*[@id='s0-scale']").text == "8.0 px/ms"


def test_html_violations_table_fits_the_window_with_a_long_frame(tmp_path):
    """Two requests run together make a 16-byte frame with a long meaning: its cell, kept on
    one line, pushed the ST location out of a 1400 px window and squeezed 'what' to one word
    per line. Measured in Chromium: a script added to a copy of the page writes the cells'
    boxes into the DOM that --dump-dom returns."""
    merged = protocol.encode(READ, S) + bytes.fromhex("01 06 01 02 00 00 D9 F6")
    trace = [TraceRecord(0, protocol.frame_time_us(16), "tx", merged, "plc/CELL_BUGGY.st:47:5")]
    page = tmp_path / "report.html"
    report_html.write([_result("merged", trace, 2_000_000)], page)
    probe = tmp_path / "probe.html"
    probe.write_text(page.read_text().replace("</body>", """<script>
      const cells = document.querySelector('.violations-table tr.violation-row').querySelectorAll('td');
      document.body.setAttribute('data-layout', JSON.stringify({
        view: document.documentElement.clientWidth,
        location: cells[4].getBoundingClientRect().right,
        what: cells[2].getBoundingClientRect().width}));
    </script></body>"""))
    layout = json.loads(_rendered(probe.as_uri()).find(".//body").get("data-layout"))
    assert layout["location"] <= layout["view"], layout  # the ST location is in sight
    assert layout["what"] >= 200, layout  # the message reads as lines, not a column of words


def test_html_screenshot_is_taken(tmp_path):
    page = tmp_path / "report.html"
    report_html.write([bad_result()], page)
    shot = tmp_path / "shot.png"
    with tempfile.TemporaryDirectory() as profile:
        procs.run([_chromium(), *_chromium_flags(profile), f"--screenshot={shot}", page.as_uri()],
                  capture_output=True, timeout=120)
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and shot.stat().st_size > 10_000


def _rendered(uri: str) -> ET.Element:
    """The page at `uri` as Chromium laid it out, its script run (--dump-dom)."""
    with tempfile.TemporaryDirectory() as profile:
        dom = procs.run([_chromium(), *_chromium_flags(profile), "--dump-dom", uri],
                        capture_output=True, text=True, timeout=120).stdout
    return _parse_dom(dom)


def _count(root: ET.Element, tag: str, cls: str) -> int:
    return sum(1 for e in root.iter(tag) if cls in (e.get("class") or "").split())


VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}


class _Dom(HTMLParser):
    """Chromium's --dump-dom output as an ElementTree (tags and attributes; text kept)."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.root = ET.Element("document")
        self.stack = [self.root]

    def handle_starttag(self, tag, attrs):
        element = ET.SubElement(self.stack[-1], tag, {k: v or "" for k, v in attrs})
        if tag not in VOID:
            self.stack.append(element)

    def handle_startendtag(self, tag, attrs):
        ET.SubElement(self.stack[-1], tag, {k: v or "" for k, v in attrs})

    def handle_endtag(self, tag):
        for depth in range(len(self.stack) - 1, 0, -1):
            if self.stack[depth].tag == tag:
                del self.stack[depth:]
                return

    def handle_data(self, data):
        node = self.stack[-1]
        node.text = (node.text or "") + data


def _parse_dom(dom: str) -> ET.Element:
    parser = _Dom()
    parser.feed(dom)
    return parser.root


def test_the_docs_explain_every_rule():
    docs = (Path(__file__).resolve().parents[1] / "docs" / "verifier.md").read_text(encoding="utf-8")
    for rule in RULES:
        assert f"`{rule.id}`" in docs, f"docs/verifier.md does not explain {rule.id}"


def test_console_counts_one_request_in_the_singular():
    one = _result("one", _frames(0, STOP, protocol.ControlReply.echo(STOP)), 1_000_000)
    out = io.StringIO()
    report_console.render([one, good_result()], Console(file=out, width=200, color_system=None))
    text = out.getvalue()
    assert "on fx3u, 1 request in 1.000 s" in text and "on fx3u, 20 requests in 6.000 s" in text


def test_a_page_of_no_run_does_not_say_its_times_came_from_a_line():
    """The header said 'times from the line' (a monitor capture) for an empty list of runs:
    all() of nothing is True."""
    from verifier.verify import report_html

    page = report_html.render([])
    assert "virtual time · bytes at 9600 8N1" in page and "times from the line" not in page


def test_html_lists_the_rules_and_the_first_place_as_the_other_reports_do(tmp_path):
    """Before, the page's rule tiles came in the rules' own order (UITAMR-PACING before
    UITAMR-POWERON-STOP, which broke first and which the console and the JUnit list first),
    and a failed run said nowhere where to look first, while the JSON's `place` and the
    JUnit test case's file/line name its first finding's place."""
    bad = bad_result()
    page = tmp_path / "report.html"
    report_html.write([good_result(), bad], page)
    root = _rendered(page.as_uri())
    good_section, bad_section = [s for s in root.iter("section") if "scenario" in (s.get("class") or "")]
    tiles = [d.get("data-rule") for d in bad_section.iter("div") if "rule" in (d.get("class") or "").split()]
    (case,) = [c for c in report_junit.to_element([bad]).iter("testcase")]
    broken = [f.get("type") for f in case.findall("failure") if f.get("type") != "expectation"]
    assert broken == ["UITAMR-POWERON-STOP", "UITAMR-PACING"]
    assert tiles[:2] == broken  # as the JUnit (and the console) list them
    assert tiles[2:] == [r.id for r in RULES if r.id not in broken]
    out = io.StringIO()
    report_console.render([bad], Console(file=out, width=200, color_system=None))
    shown = [line.split()[0].rstrip(",") for line in out.getvalue().splitlines() if line.startswith("    UITAMR-")]
    assert shown == broken
    place = report_json.to_dict([bad])["scenarios"][0]["place"]
    assert place == "UITAMR_Engine.st:210:9" and (case.get("file"), case.get("line")) == ("UITAMR_Engine.st", "210")
    (said,) = [p for p in bad_section.iter("p") if p.get("class") == "first-finding"]
    assert said.find("code").text == place
    assert "UITAMR-POWERON-STOP" in "".join(said.itertext())
    assert not [p for p in good_section.iter("p") if p.get("class") == "first-finding"]  # a pass has none
    index = root.find(".//*[@id='index']")
    assert [(td.text or "") for td in index.iter("td") if "place" in (td.get("class") or "").split()] == ["", place]


def test_the_console_shows_the_head_of_a_long_frame_and_where_the_whole_is():
    """A G_OUTPUT held on by a level sent 400 stop frames back to back: verify printed them as
    one 3200-byte frame, all 9,600 characters of it, twice (the CRC and the format rule). The
    console shows its first 32 bytes and the count; --json, --trace and --html keep every byte."""
    data = protocol.encode(STOP, S) * 400
    trace = [TraceRecord(0, protocol.frame_time_us(len(data)), "tx", data, "Raw.st:18:1")]
    result = _result("raw", trace, 5_000_000)
    out = io.StringIO()
    report_console.render([result], Console(file=out, width=400, color_system=None))
    shown = [line for line in out.getvalue().splitlines() if "PLC→robot" in line]
    head = " ".join(["01 06 01 A0 00 00 88 14"] * 4)
    assert shown and all(f"PLC→robot {head} … (3200 bytes: every one in --json, --trace or --html)" in line
                         for line in shown), shown
    assert max(len(line) for line in out.getvalue().splitlines()) < 400


def test_violations_of_the_same_moment_are_listed_in_the_rules_order_everywhere():
    """The HTML and JSON lists broke a tie of time by the rule's name (HALF-DUPLEX before
    PACING), the console and the JUnit report by the rules' own order (PACING first)."""
    from verifier.verify.evidence import Violation

    result = bad_result()
    result.violations = {"UITAMR-PACING": [Violation("UITAMR-PACING", 500_000, "too soon")],
                         "UITAMR-HALF-DUPLEX": [Violation("UITAMR-HALF-DUPLEX", 100_000, "earlier"),
                                                Violation("UITAMR-HALF-DUPLEX", 500_000, "both talked")]}
    assert [v.message for v in result.all_violations()] == ["earlier", "too soon", "both talked"]
    assert [found[0].rule for found in result.broken_rules()] == ["UITAMR-HALF-DUPLEX", "UITAMR-PACING"]


def test_a_monitored_port_is_named_once_in_the_console():
    """`FAIL monitor /tmp/x (/tmp/x): the PLC on the line ...` named the port twice."""
    from dataclasses import replace

    from verifier.verify.result import LINE

    result = replace(bad_result(), name="monitor /dev/ttyUSB0", file="/dev/ttyUSB0", platform=LINE)
    out = io.StringIO()
    report_console.render([result, good_result()], Console(file=out, width=200, color_system=None))
    text = out.getvalue()
    assert "FAIL monitor /dev/ttyUSB0: the PLC on the line" in text, text
    assert "PASS healthy (plc/scenarios/healthy.toml): Main on fx3u" in text, text
