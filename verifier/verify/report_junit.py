"""`--junit FILE`: JUnit XML as GitHub, GitLab and Jenkins read it.

One <testcase> per scenario, its `file` and `line` where its first finding is (the ST
statement that sent a broken rule's frame, a failed expectation's line: ScenarioResult.
first_place); one <failure> per broken rule (type = the rule id) and per
failed expectation (type = "expectation"); an <error> when the simulation stopped, or when
a monitored line or a capture had no bytes (type = "no-traffic") or its port went away
(type = "cut-short"; with the rules' failures when its frames broke some). A run that could not
start (exit 2) gets one <error type="unusable-input"> per mistake instead.
"""
from __future__ import annotations

import re
from collections import Counter
import xml.etree.ElementTree as ET
from pathlib import Path

from verifier.textfile import escape_chars, whole_file

from .durations import format_seconds
from .result import Mistake, ScenarioResult, run_names
from .rules import RULES_BY_ID

MAX_LISTED = 50  # violations written out per rule and scenario


def _failure(parent: ET.Element, kind: str, message: str, text: str) -> None:
    element = ET.SubElement(parent, "failure", message=message, type=kind)
    element.text = text


def _rule_failure_text(rule_id: str, result: ScenarioResult) -> str:
    found = result.violations[rule_id]
    lines = [RULES_BY_ID[rule_id].explanation, ""]
    for violation in found[:MAX_LISTED]:
        origin = f" [{violation.origin}]" if violation.origin else ""
        lines.append(f"{format_seconds(violation.t_us)}: {violation.message}{origin}")
        for frame in violation.frames:
            arrow = "PLC->robot" if frame.direction == "tx" else "robot->PLC"
            lines.append(f"    {format_seconds(frame.t_us)} {arrow} {frame.hex}  {frame.meaning}")
    if len(found) > MAX_LISTED:
        lines.append(f"... and {len(found) - MAX_LISTED} more")
    return "\n".join(lines)


def to_element(results: list[ScenarioResult], command: str = "uitamr verify") -> ET.Element:
    """The report; `command`: the one that made it, the suite's name and the start of each
    test case's class (`uitamr replay`, uitamr.replay.line, for a capture it re-checked)."""
    suites = ET.Element("testsuites", name=command)
    suite = ET.SubElement(suites, "testsuite", name=command)
    failures = errors = 0
    for result, name in zip(results, run_names(results)):
        case = ET.SubElement(
            suite,
            "testcase",
            classname=command.replace(" ", ".") + "." + (result.platform or "plc"),
            name=name,
            time=f"{result.wall_s:.3f}",
        )
        # one place a JUnit reader (GitHub's actions) annotates: the first finding's that has
        # one (ScenarioResult.first_place), else the scenario file, the program's ST file or
        # the capture file; no port a monitor listened to (file_to_annotate)
        place = result.first_place
        if place is not None:
            case.set("file", place.file)
            case.set("line", str(place.line))
        elif result.file_to_annotate is not None:
            case.set("file", result.file_to_annotate)
        if result.aborted:
            errors += 1
            # the message is what a CI server lists: the ST place and the reason, as for a rule
            first = result.aborted.splitlines()[0]
            element = ET.SubElement(case, "error", message=f"simulation stopped: {first}", type="simulation")
            element.text = result.aborted
        for kind, said in result.unverified:
            errors += 1  # nothing, or not the whole session, was verified: not a pass, and not a rule broken
            element = ET.SubElement(case, "error", message=f"{kind.replace('-', ' ')}: {said}", type=kind)
            element.text = said
        for found in result.broken_rules():  # as the console lists them: the first one first
            rule_id = found[0].rule
            failures += 1
            _failure(
                case, rule_id,
                f"{rule_id}: {len(found)} violation(s); first at {format_seconds(found[0].t_us)}: {found[0].message}",
                _rule_failure_text(rule_id, result),
            )
        for outcome in result.failed_expectations:
            failures += 1
            place = result.place_of(outcome.expectation)
            at = f"  at {place}" if place is not None else ""
            # the text starts at the scenario's line, as a compiler's message does
            text = f"{place}: {outcome.expectation.key}: {outcome.detail}" if place is not None else outcome.detail
            _failure(case, "expectation", f"expected {outcome.expectation.label}: {outcome.detail}{at}", text)
        out = ET.SubElement(case, "system-out")
        tx, rx = result.tx_count, result.rx_count
        out.text = "\n".join(
            [
                *([result.description] if result.description else []),
                result.run_line,
                f"{tx} requests, {rx} replies",
                *(f"note: {note}" for note in result.notes),
                *(f"simulator {line}" for line in result.diagnostic_summary),
                *(f"fault: {fault}" for fault in result.faults),
                *([result.converter] if result.converter else []),
                *(f"expectation met: {e.expectation.label}: {e.detail}" for e in result.expectations if e.passed),
            ]
        )
    suite.set("tests", str(len(results)))
    suite.set("failures", str(failures))
    suite.set("errors", str(errors))
    suites.set("tests", str(len(results)))
    suites.set("failures", str(failures))
    suites.set("errors", str(errors))
    return suites


# characters XML 1.0 cannot hold at all, not even escaped (control characters, surrogates)
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def _xml_safe(text: str | None) -> str | None:
    """`text` without the characters XML cannot hold (shown as \\xNN / \\uNNNN instead)."""
    return None if text is None else escape_chars(text, lambda c: not _NOT_XML.match(c))


def unusable_element(mistakes: list[Mistake], command: str = "uitamr verify",
                     results: list[ScenarioResult] = ()) -> ET.Element:
    """The report of a run that exits 2 (it could not start, or a report could not be written
    after the runs): one test case per mistake, an
    `<error type="unusable-input">` whose message is the mistake's line that names its place
    (file:line:col), from the place on, and whose text is the whole message, so that the CI
    server shows what to fix instead of a missing report (or the last run's). The places are
    the mistakes' own (`Mistake.place`), never read back from their text.
    `results`: the runs that were done before the mistake (another report that could not be
    written after them), kept as their own test suite before the mistakes' one."""
    suites = to_element(results, command) if results else ET.Element("testsuites", name=command, tests="0",
                                                                      failures="0", errors="0")
    suite = ET.SubElement(suites, "testsuite", name=command, tests=str(len(mistakes)), failures="0",
                          errors=str(len(mistakes)))
    for total, added in (("tests", len(mistakes)), ("errors", len(mistakes))):
        suites.set(total, str(int(suites.get(total)) + added))
    for mistake, name in zip(mistakes, _mistake_names(mistakes)):
        case = ET.SubElement(suite, "testcase", classname=command.replace(" ", ".") + ".input",
                             name=name, time="0.000")
        if mistake.place is not None:
            case.set("file", mistake.place.file)
            if mistake.place.line > 0:  # where a JUnit reader (GitHub's actions) annotates the file
                case.set("line", str(mistake.place.line))
        element = ET.SubElement(case, "error", message=_headline(mistake), type="unusable-input")
        element.text = mistake.message
    return suites


def _mistake_names(mistakes: list[Mistake]) -> list[str]:
    """Each mistake's test case name: its place, `file:line:col` (`input` when it has none),
    so that two mistakes of one file are two test cases a CI summary keeps apart, each named
    the same from run to run while it stays; mistakes that share a place (or have none) are
    numbered in order, `input #1`, `input #2`."""
    names = [str(m.place) if m.place is not None else "input" for m in mistakes]
    count, seen = Counter(names), Counter()
    numbered = []
    for name in names:
        seen[name] += 1
        numbered.append(f"{name} #{seen[name]}" if count[name] > 1 else name)
    return numbered


def _headline(mistake: Mistake) -> str:
    """The line of the message that shows the mistake's place, from the place on (`  plc/MAIN.st:5:6:
    error: ...` under `ST sources have errors:`); the first line when it shows none."""
    if mistake.place is not None:
        shown = f"{mistake.place}: "
        at = mistake.message.find(shown)
        if at >= 0:
            return mistake.message[at:].splitlines()[0]
    return (mistake.message.splitlines() or [""])[0]


def write_unusable(mistakes: list[Mistake], path: Path, command: str = "uitamr verify",
                   results: list[ScenarioResult] = ()) -> None:
    _write_tree(unusable_element(mistakes, command, results), path)


def write(results: list[ScenarioResult], path: Path, command: str = "uitamr verify") -> None:
    _write_tree(to_element(results, command), path)


def _write_tree(root: ET.Element, path: Path) -> None:
    for element in root.iter():
        element.text, element.tail = _xml_safe(element.text), _xml_safe(element.tail)
        for name, value in element.attrib.items():
            element.set(name, _xml_safe(value))
    tree = ET.ElementTree(root)
    ET.indent(tree)
    with whole_file(path, "wb") as out:
        tree.write(out, encoding="utf-8", xml_declaration=True)
