"""The JUnit report of a run that cannot start (exit 2: `uitamr verify --junit`, `uitamr
replay --junit`): one error test case per mistake, at the place the mistake holds as data
(file, line, column), never at one read back from its text (docs/verifier.md `--junit`)."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from click.testing import CliRunner

from file_helpers import write_files
from verifier.cli import main
from verifier.place import Place
from verifier.verify.report_junit import unusable_element
from verifier.verify.result import Mistake
import procs

BROKEN = "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := ;\nEND_PROGRAM\n"
GOOD = "PROGRAM GOOD\nVAR\n    x : INT;\nEND_VAR\nx := 1;\nEND_PROGRAM\n"


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def cases(report) -> list[ET.Element]:
    return ET.parse(report).getroot().findall("./testsuite/testcase")


def test_a_message_that_holds_a_place_like_text_is_no_file(tmp_path):
    """`--program 'x:1:2: y'` names no file's line; the regex on the message took
    "--program: no PROGRAM 'x" for the file of the test case."""
    write_files(tmp_path, {"GOOD.st": GOOD})
    result = invoke("verify", tmp_path / "GOOD.st", "--program", "x:1:2: y", "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "v.xml")
    assert (case.get("name"), case.get("file")) == ("input", None)
    assert case.find("error").get("message").startswith("--program: no PROGRAM 'x:1:2: y' in the sources")


def test_st_that_loads_on_no_platform_is_at_its_own_file(tmp_path):
    """`--matrix` tells the platform from the sources; ST that loads on none said "the
    sources do not load: MAIN.st:5:6: ...", and the regex made the whole head of that line
    the file's name."""
    write_files(tmp_path, {"MAIN.st": BROKEN})
    source = tmp_path / "MAIN.st"
    result = invoke("verify", source, "--matrix", "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "v.xml")
    assert (case.get("name"), case.get("file")) == (f"{source}:5:6", str(source))
    assert case.find("error").get("message").startswith(f"{source}:5:6: error: expected an expression")
    assert case.find("error").text.startswith(f"the sources do not load: {source}:5:6: ")


def test_a_capture_of_bytes_that_are_not_text_is_at_its_line_and_column(tmp_path):
    capture = tmp_path / "site.txt"
    capture.write_bytes(b"0.000 01 06\n0.100 01 \xff\xfe\n")
    result = invoke("replay", capture, "--junit", tmp_path / "r.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "r.xml")
    assert (case.get("name"), case.get("file")) == (f"{capture}:2:10", str(capture))
    assert case.find("error").get("message").startswith(f"{capture}: line 2, column 10 (byte 21)")


def test_a_capture_name_too_long_for_the_file_system_is_the_junits_error(tmp_path):
    """`uitamr replay` asks whether a capture it cannot read is a serial port; with a name
    the file system refuses (longer than NAME_MAX) that question raised OSError itself: the
    command's own "cannot read" and its JUnit test case were lost to the generic path error."""
    capture = tmp_path / ("c" * 5000)
    result = invoke("replay", capture, "--junit", tmp_path / "r.xml")
    assert result.exit_code == 2, result.output
    assert "cannot read: File name too long" in result.output
    (case,) = cases(tmp_path / "r.xml")
    assert "cannot read: File name too long" in case.find("error").get("message")


def test_the_place_is_the_mistakes_data_not_its_text():
    root = unusable_element([Mistake("no place, though it reads a:1:2: like one"),
                             Mistake("the sources do not load: dir: x/M.st:3:4: error: bad", Place("dir: x/M.st", 3, 4))])
    unplaced, placed = root.findall("./testsuite/testcase")
    assert (unplaced.get("name"), unplaced.get("file")) == ("input", None)
    assert unplaced.find("error").get("message") == "no place, though it reads a:1:2: like one"
    assert (placed.get("name"), placed.get("file")) == ("dir: x/M.st:3:4", "dir: x/M.st")
    assert placed.find("error").get("message") == "dir: x/M.st:3:4: error: bad"


def test_mistakes_of_one_file_are_test_cases_of_their_own_names(tmp_path):
    """Each mistake's test case was named by its file alone: two of one file were two test
    cases of one name, which CI summaries merge or hide. Named by place now, numbered when
    they share it (one scenario file given twice), the same on every run."""
    write_files(tmp_path, {"a.toml": 'program = "P"\nduration = "5q"\n', "b.toml": 'duration = "1s"\nscan = "x"\n'})
    report = tmp_path / "v.xml"
    for _ in range(2):
        result = invoke("verify", "--scenario", tmp_path / "a.toml", "--scenario", tmp_path,
                        "--junit", report)
        assert result.exit_code == 2, result.output
        names = [case.get("name") for case in cases(report)]
        assert names == [f"{tmp_path / 'a.toml'}:2:12 #1", f"{tmp_path / 'a.toml'}:2:12 #2",
                         f"{tmp_path / 'b.toml'}:2:8"]
    assert [case.get("file") for case in cases(report)] == [str(tmp_path / "a.toml")] * 2 + [str(tmp_path / "b.toml")]
    numbered = unusable_element([Mistake("x"), Mistake("y"), Mistake("s.toml:1:1: z", Place("s.toml", 1, 1))])
    assert [c.get("name") for c in numbered.findall("./testsuite/testcase")] == ["input #1", "input #2", "s.toml:1:1"]


OLD_RUN = "<testsuites name='an earlier run'/>"


def _refused(tmp_path, *args):
    """`uitamr verify GOOD.st ... --junit v.xml` over an earlier run's JUnit file."""
    write_files(tmp_path, {"GOOD.st": GOOD, "v.xml": OLD_RUN})
    result = invoke("verify", tmp_path / "GOOD.st", "--duration", "1s", *args, "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    return result


def test_another_reports_refused_path_is_the_junits_error(tmp_path):
    """Exit 2 for --json's missing folder, two reports given one file or a report over an
    input file left the earlier run's JUnit file as it was, and CI showed its results as
    this run's; now the JUnit holds the mistake."""
    source = tmp_path / "GOOD.st"
    for args, said in [(["--json", tmp_path / "gone" / "r.json"], f"cannot write {tmp_path / 'gone' / 'r.json'}: "
                                                                   "the folder"),
                       (["--json", tmp_path / "r.out", "--html", tmp_path / "r.out"], "are the same file"),
                       (["--json", source], f"{source} is one of the run's input files")]:
        result = _refused(tmp_path, *args)
        assert f"wrote {tmp_path / 'v.xml'} (these errors as test cases)" in result.output
        (case,) = cases(tmp_path / "v.xml")
        error = case.find("error")
        assert (case.get("name"), error.get("type")) == ("input", "unusable-input")
        assert said in error.get("message"), error.get("message")
        assert source.read_text(encoding="utf-8") == GOOD


def test_a_report_that_cannot_be_written_after_the_run_is_the_junits_error(tmp_path):
    """--json to a full disk (/dev/full) fails after the run, before the JUnit was written:
    exit 2, and the JUnit says why rather than holding the earlier run; the run's own test
    case stays beside the error (it was lost: the error was the file's one test case)."""
    result = _refused(tmp_path, "--json", "/dev/full")
    root = ET.parse(tmp_path / "v.xml").getroot()
    run, refused = root.findall("./testsuite")
    (case,) = run.findall("testcase")
    assert case.get("classname") == "uitamr.verify.fx3u" and "requests" in case.find("system-out").text
    (error_case,) = refused.findall("testcase")
    assert error_case.find("error").get("message").startswith("cannot write /dev/full: ")
    assert (root.get("tests"), root.get("errors"), root.get("failures")) == (
        "2", str(int(run.get("errors")) + 1), run.get("failures"))
    assert f"wrote {tmp_path / 'v.xml'} (the runs' results, and this error as a test case)" in result.output


def test_a_junit_whose_own_path_is_refused_is_not_written(tmp_path):
    """Two reports given the JUnit's own file: neither is written, and the file stays."""
    result = _refused(tmp_path, "--json", tmp_path / "v.xml")
    assert "are the same file" in result.output and "wrote" not in result.output
    assert (tmp_path / "v.xml").read_text(encoding="utf-8") == OLD_RUN


def test_replay_writes_another_reports_refusal_to_its_junit(tmp_path):
    capture = tmp_path / "site.txt"
    capture.write_text("0.000 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    (tmp_path / "r.xml").write_text(OLD_RUN, encoding="utf-8")
    result = invoke("replay", capture, "--json", tmp_path / "gone" / "r.json", "--junit", tmp_path / "r.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "r.xml")
    assert case.get("classname") == "uitamr.replay.input"
    assert case.find("error").get("message").startswith(f"cannot write {tmp_path / 'gone' / 'r.json'}: the folder")


def test_monitor_writes_another_reports_refusal_to_its_junit(tmp_path):
    """Refused before the line is opened: no port is listened to."""
    (tmp_path / "m.xml").write_text(OLD_RUN, encoding="utf-8")
    result = invoke("monitor", "--tcp", "127.0.0.1:1", "--json", tmp_path / "gone" / "m.json",
                    "--junit", tmp_path / "m.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "m.xml")
    assert case.get("classname") == "uitamr.monitor.input"
    assert case.find("error").get("message").startswith(f"cannot write {tmp_path / 'gone' / 'm.json'}: the folder")


TWO_ERRORS = "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := y;\nx := z;\nEND_PROGRAM\n"


def test_each_error_of_st_that_does_not_load_is_a_test_case_at_its_place(tmp_path):
    """ST with two errors was one test case at the first error's place, so a CI summary (and
    its annotations) showed one of them; now one test case each, while the console still
    lists them under one heading."""
    write_files(tmp_path, {"MAIN.st": TWO_ERRORS, "a.toml": 'sources = ["MAIN.st"]\nduration = "1s"\n'})
    source = tmp_path / "MAIN.st"
    for args in ([source], ["--scenario", tmp_path / "a.toml", "--scenario", tmp_path / "a.toml", "--jobs", "2"]):
        result = invoke("verify", *args, "--junit", tmp_path / "v.xml")
        assert result.exit_code == 2, result.output
        assert result.output.count("ST sources have errors:") == 1, result.output
        found = [(case.get("name"), case.get("file"), case.find("error").get("message")) for case in cases(tmp_path / "v.xml")]
        assert found == [(f"{source}:5:6", str(source), f"{source}:5:6: error: undefined label 'y'; declare it in a VAR block"),
                         (f"{source}:6:6", str(source), f"{source}:6:6: error: undefined label 'z'; declare it in a VAR block")]


def test_the_places_of_an_unusable_input_cross_worker_processes():
    """--jobs sends a worker's UnusableInput back pickled: its place and its several
    mistakes come with it."""
    import pickle

    from verifier.verify.result import UnusableInput, mistakes_of

    each = [Mistake("M.st:1:2: error: a", Place("M.st", 1, 2)), Mistake("M.st:3:4: error: b", Place("M.st", 3, 4))]
    error = pickle.loads(pickle.dumps(UnusableInput("ST sources have errors: ...", at=Place("M.st", 1, 2), mistakes=each)))
    assert (error.place, mistakes_of(error)) == (Place("M.st", 1, 2), each)
    alone = pickle.loads(pickle.dumps(UnusableInput("s.toml:2:3: program: x", at=Place("s.toml", 2, 3))))
    assert mistakes_of(alone) == [Mistake("s.toml:2:3: program: x", Place("s.toml", 2, 3))]


def _monitor_of_a_closed_stream(tmp_path, *args):
    """`uitamr monitor --tcp` against a server that sends the stop and its echo, then closes
    the connection (the session ends by itself), over an earlier run's JUnit file."""
    import socket
    import threading

    (tmp_path / "m.xml").write_text(OLD_RUN, encoding="utf-8")
    stop = bytes.fromhex("01 06 01 A0 00 00 88 14")
    with socket.create_server(("127.0.0.1", 0)) as server:
        def stream():
            connection, _ = server.accept()
            with connection:
                connection.sendall(stop)
                connection.sendall(stop)

        thread = threading.Thread(target=stream, daemon=True)
        thread.start()
        result = invoke("monitor", "--tcp", f"127.0.0.1:{server.getsockname()[1]}", "--duration", "5s", *args,
                        "--junit", tmp_path / "m.xml")
        thread.join(timeout=5)
    assert result.exit_code == 2, result.output
    return result


def test_a_monitor_capture_that_cannot_be_written_is_the_junits_error(tmp_path):
    """--capture to a full disk exits 2 after the reports were written: the JUnit held the
    session's test case alone, so CI read a run that exits 2 as its verdict, without the
    reason; now the capture's error follows the session's test case, as a report's does.
    With --json failing too, both errors are in the file."""
    result = _monitor_of_a_closed_stream(tmp_path, "--capture", "/dev/full")
    assert "cannot write the capture /dev/full" in result.output
    root = ET.parse(tmp_path / "m.xml").getroot()
    run, refused = root.findall("./testsuite")
    assert [case.get("classname") for case in run.findall("testcase")] == ["uitamr.monitor.line"]
    (error_case,) = refused.findall("testcase")
    assert error_case.find("error").get("message").startswith("cannot write the capture /dev/full: ")
    assert root.get("tests") == "2" and root.get("errors") == str(int(run.get("errors")) + 1)
    result = _monitor_of_a_closed_stream(tmp_path, "--json", "/dev/full", "--capture", "/proc/version")
    assert "the runs' results, and these errors as test cases" in result.output
    root = ET.parse(tmp_path / "m.xml").getroot()
    messages = [case.find("error").get("message") for case in root.findall("./testsuite")[1].findall("testcase")]
    assert [m.split(":", 1)[0] for m in messages] == ["cannot write /dev/full", "cannot write the capture /proc/version"]
    page = " ".join((Path(__file__).parents[1] / "docs" / "verifier.md").read_text(encoding="utf-8").split())
    assert "`uitamr monitor`'s `--capture` too: a capture it cannot write is an error after the session's test case" in page


def test_every_exception_of_placed_mistakes_keeps_them_through_pickle():
    """UnusableInput's pickling rebuilt an exception by calling its class with (message, at,
    mistakes): ScenarioMistakes, whose constructor takes the errors, could not be rebuilt
    (TypeError), and CaptureError, whose place became constructor arguments, neither."""
    import pickle

    from verifier.commands.verify import ScenarioMistakes
    from verifier.monitor.capture import CaptureError
    from verifier.verify.result import UnusableInput, mistakes_of

    several = ScenarioMistakes([UnusableInput("a.toml:1:2: program: x", at=Place("a.toml", 1, 2)),
                                UnusableInput("--scan 5s: longer than the run")])
    capture = CaptureError(Place("c.txt", 2, 3), "'0G' is not a byte in hex")
    unreadable = CaptureError(Place("c.txt", 2, 10), "", message="c.txt: line 2, column 10 (byte 21): not UTF-8")
    for error in (several, capture, unreadable, CaptureError(None, "c.txt: no such file")):
        again = pickle.loads(pickle.dumps(error))
        assert (type(again), str(again), mistakes_of(again)) == (type(error), str(error), mistakes_of(error))
    assert mistakes_of(pickle.loads(pickle.dumps(capture))) == [
        Mistake("c.txt:2:3: '0G' is not a byte in hex", Place("c.txt", 2, 3))]


def test_a_monitor_whose_line_cannot_be_opened_writes_that_to_its_junit(tmp_path):
    """A converter that refuses the connection (or a serial port another program holds)
    ended the monitor with exit 2 and left the earlier run's JUnit file as it was: CI showed
    that run's results as this one's. Now the file holds the error."""
    import socket

    (tmp_path / "m.xml").write_text(OLD_RUN, encoding="utf-8")
    with socket.create_server(("127.0.0.1", 0)) as server:
        port = server.getsockname()[1]
    result = invoke("monitor", "--tcp", f"127.0.0.1:{port}", "--junit", tmp_path / "m.xml")
    assert result.exit_code == 2, result.output
    assert f"wrote {tmp_path / 'm.xml'} (these errors as test cases)" in result.output
    (case,) = cases(tmp_path / "m.xml")
    assert case.get("classname") == "uitamr.monitor.input"
    assert case.find("error").get("message").startswith(f"cannot connect to 127.0.0.1:{port}: ")
    page = " ".join((Path(__file__).parents[1] / "docs" / "verifier.md").read_text(encoding="utf-8").split())
    assert "`uitamr monitor --junit` for a line it cannot open" in page


def test_matrix_on_st_that_loads_nowhere_names_every_error(tmp_path):
    """`--matrix` tells the platform from the sources; ST with two errors said only the first
    ('the sources do not load: ...:5:6: ...'), on the console and in the JUnit, where a run
    without --matrix lists both: now both, one test case each."""
    write_files(tmp_path, {"MAIN.st": TWO_ERRORS})
    source = tmp_path / "MAIN.st"
    result = invoke("verify", source, "--matrix", "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    assert f"the sources do not load: {source}:5:6: error: undefined label 'y'" in result.output
    assert f"{source}:6:6: error: undefined label 'z'" in result.output
    assert [case.get("name") for case in cases(tmp_path / "v.xml")] == [f"{source}:5:6", f"{source}:6:6"]


def test_a_command_line_mistake_is_the_junits_error(tmp_path):
    """An unknown option, `--duration 5q`, an option without its value or a --platform that
    is none exited 2 before the run was set up, and left the earlier run's JUnit file as it
    was (or none): CI showed that run's results as this one's. Now click's message, naming
    the option, is the file's error test case; click's usage message and exit 2 stay."""
    capture = tmp_path / "site.txt"
    capture.write_text("0.000 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    report = tmp_path / "r.xml"
    for args, said in [(["verify", "--duration", "5q"], "Invalid value for '--duration': '5q' is not a duration"),
                       (["verify", "--bogus"], "No such option '--bogus'"),
                       (["verify", "--platform", "fx9"], "Invalid value for '--platform': 'fx9' is not one of"),
                       (["verify", "--junit", report, "--scan"], "Option '--scan' requires an argument."),
                       (["replay", capture, "--tolerance", "5q"], "Invalid value for '--tolerance'"),
                       (["monitor", "--tcp", "127.0.0.1:1", "--baud", "7"], "Invalid value for '--baud': '7'")]:
        report.write_text(OLD_RUN, encoding="utf-8")
        result = invoke(*args[:1], "--junit", report, *args[1:])
        assert result.exit_code == 2, result.output
        assert f"Error: {said}" in result.stderr and f"wrote {report} (these errors as test cases)" in result.stderr
        (case,) = cases(report)
        error = case.find("error")
        assert (case.get("classname"), case.get("name"), error.get("type")) == (
            f"uitamr.{args[0]}.input", "input", "unusable-input")
        assert error.get("message").startswith(said), error.get("message")
        if args[-1] != "--scan":  # click shows no usage line for an option without its value
            assert f"Usage: main {args[0]} [OPTIONS]" in error.text, error.text
    assert capture.read_text(encoding="utf-8") == "0.000 01 06 01 A0 00 00 88 14\n"
    page = " ".join((Path(__file__).parents[1] / "docs" / "verifier.md").read_text(encoding="utf-8").split())
    assert "refused by click before the run is set up, is an error test case too, for all three commands" in page


def test_a_command_line_mistake_is_not_written_over_an_input_file(tmp_path):
    """The JUnit of a refused command line keeps the rule of every exit 2: never over a
    scenario, a source or a capture the command names; `--junit` without its file names
    none, and click's message is all."""
    write_files(tmp_path, {"a.toml": 'duration = "1s"\n', "site.txt": "0.000 01 06 01 A0 00 00 88 14\n"})
    for args, kept in [(["verify", "--scenario", tmp_path / "a.toml", "--junit", tmp_path / "a.toml", "--bogus"],
                        tmp_path / "a.toml"),
                       (["replay", tmp_path / "site.txt", "--junit", tmp_path / "site.txt", "--bogus"],
                        tmp_path / "site.txt")]:
        before = kept.read_text(encoding="utf-8")
        result = invoke(*args)
        assert result.exit_code == 2, result.output
        assert f"the JUnit report was not written: {kept} is one of the run's input files" in result.stderr
        assert "Error: No such option '--bogus'" in result.stderr
        assert kept.read_text(encoding="utf-8") == before
    result = invoke("verify", "--bogus", "--junit")
    assert result.exit_code == 2 and "JUnit" not in result.stderr, result.output


def test_monitors_own_command_line_checks_are_the_junits_error(tmp_path):
    """Neither --serial nor --tcp, or a --serial URL without its port, is refused by the
    monitor itself after click's parse, with click's usage message: it left the earlier
    run's JUnit file as it was, as click's own refusals did."""
    report = tmp_path / "m.xml"
    for args, said in [([], "give exactly one of --serial PORT or --tcp HOST:PORT"),
                       (["--serial", "socket://localhost"], "Invalid value for --serial: socket://localhost needs")]:
        report.write_text(OLD_RUN, encoding="utf-8")
        result = invoke("monitor", *args, "--junit", report)
        assert result.exit_code == 2, result.output
        assert f"Error: {said}" in result.stderr and "Usage: main monitor [OPTIONS]" in result.stderr
        (case,) = cases(report)
        assert case.get("classname") == "uitamr.monitor.input"
        assert case.find("error").get("message").startswith(said)
        assert "Usage: main monitor [OPTIONS]" in case.find("error").text


def test_a_scenario_error_keeps_its_parts_through_pickle(tmp_path):
    """ScenarioError could not be unpickled (its constructor takes file, key, message and
    place, pickle gave it the message alone: TypeError), where UnusableInput and CaptureError
    cross --jobs' worker processes; now it comes back whole, its place with it."""
    import pickle

    from verifier.verify.result import mistakes_of
    from verifier.verify.scenario import ScenarioError, load_scenario

    (tmp_path / "a.toml").write_text('duration = "1s"\nscan = "x"\n', encoding="utf-8")
    try:
        load_scenario(tmp_path / "a.toml")
    except ScenarioError as exc:
        read = exc
    for error in (read, ScenarioError(None, "", "no sources"), ScenarioError(Path("b.toml"), "seed", "not a number")):
        again = pickle.loads(pickle.dumps(error))
        assert type(again) is ScenarioError
        assert (str(again), again.file, again.key, again.message, again.place) == (
            str(error), error.file, error.key, error.message, error.place)
        assert mistakes_of(again) == mistakes_of(error)
    assert read.place == Place(str(tmp_path / "a.toml"), 2, 8)


def test_a_name_too_long_beside_a_command_line_mistake_keeps_clicks_message(tmp_path):
    """Naming the inputs of a refused command line (so as not to write the JUnit over one)
    met the file system's 'File name too long' and that OSError took the place of click's
    message; the names count as given then, and click's message is the one shown."""
    report = tmp_path / "v.xml"
    result = invoke("verify", "--junit", report, "--bogus", "a" * 5000)
    assert result.exit_code == 2, result.output
    assert "Error: No such option '--bogus'" in result.stderr and "File name too long" not in result.stderr
    assert cases(report)[0].find("error").get("message").startswith("No such option '--bogus'")


def test_a_report_is_not_written_to_a_file_named_like_an_option(tmp_path, monkeypatch):
    """`--junit --duration 5q`: click took `--duration` for --junit's file, and the JUnit
    (of the usage mistake, or of a capture "5q" that cannot be read) went to a file of that
    name in the working folder. A report's file that begins with '-' is refused now, as a
    usage mistake that names it; with a file given the JUnit is written."""
    monkeypatch.chdir(tmp_path)
    for command in ("monitor", "replay", "verify"):
        for report in ("--junit", "--html"):
            result = invoke(command, report, "--duration", "5q")
            assert result.exit_code == 2, result.output
            assert list(tmp_path.iterdir()) == [], (command, result.output)
            assert f"Invalid value for '{report}': '--duration' is an option, not a file" in result.output
        result = invoke(command, "--junit", "j.xml", "--duration", "5q")
        assert result.exit_code == 2 and (tmp_path / "j.xml").is_file(), (command, result.output)
        (tmp_path / "j.xml").unlink()


def test_a_mistake_before_the_command_is_the_junits_error(tmp_path):
    """`uitamr --bogus verify --junit report.xml` (an option `uitamr` itself does not have)
    or `uitamr verfy --junit report.xml` (a command it does not know) exited 2 with click's
    message and wrote no JUnit: CI published an earlier run's file as this one's, or none.
    The mistake is now the file's error test case, for the command click's resilient parse
    finds after `uitamr`'s options; click's message and exit 2 stay."""
    write_files(tmp_path, {"a.toml": 'duration = "1s"\n', "site.txt": "0.000 01 06 01 A0 00 00 88 14\n"})
    report = tmp_path / "r.xml"
    for args, classname, said in [
            (["--bogus", "verify", "--scenario", tmp_path / "a.toml"], "uitamr.verify.input", "No such option '--bogus'."),
            (["-x", "replay", tmp_path / "site.txt"], "uitamr.replay.input", "No such option '-x'."),
            (["--bogus", "monitor", "--tcp", "127.0.0.1:1"], "uitamr.monitor.input", "No such option '--bogus'."),
            (["verfy", "--scenario", tmp_path / "a.toml"], "uitamr.verfy.input", "No such command 'verfy'.")]:
        report.write_text(OLD_RUN, encoding="utf-8")
        result = invoke(*args, "--junit", report)
        assert result.exit_code == 2, result.output
        assert f"Error: {said}" in result.stderr and f"wrote {report} (these errors as test cases)" in result.stderr
        (case,) = cases(report)
        error = case.find("error")
        assert (case.get("classname"), case.get("name"), error.get("type"), error.get("message")) == (
            classname, "input", "unusable-input", said)
        assert "Usage: main [OPTIONS] COMMAND [ARGS]..." in error.text
    page = " ".join((Path(__file__).parents[1] / "docs" / "verifier.md").read_text(encoding="utf-8").split())
    assert "So is a mistake in `uitamr`'s own part of the command line, before the command" in page


def test_a_mistake_before_the_command_keeps_the_rules_of_every_junit(tmp_path):
    """Never over an input file (the command's own, or any file that holds no XML for a
    command `uitamr` does not know), nothing without a --junit file, and `uitamr --help`,
    `--version` and a command without a JUnit (`check`) as they were."""
    write_files(tmp_path, {"a.toml": 'duration = "1s"\n', "site.txt": "0.000 01 06 01 A0 00 00 88 14\n"})
    for args, kept, why in [(["--bogus", "replay", tmp_path / "site.txt", "--junit", tmp_path / "site.txt"],
                             tmp_path / "site.txt", "is one of the run's input files"),
                            (["verfy", tmp_path / "a.toml", "--junit", tmp_path / "a.toml"],
                             tmp_path / "a.toml", "exists and holds no XML")]:
        before = kept.read_text(encoding="utf-8")
        result = invoke(*args)
        assert result.exit_code == 2, result.output
        assert f"the JUnit report was not written: {kept} {why}" in result.stderr
        assert kept.read_text(encoding="utf-8") == before
    for args in (["--bogus", "verify", "--junit"], ["--bogus", "check", "--junit", tmp_path / "c.xml"], ["--bogus"],
                 ["--junit", tmp_path / "c.xml"]):
        result = invoke(*args)
        assert result.exit_code == 2 and "JUnit" not in result.stderr and "wrote" not in result.stderr, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.toml", "site.txt"]
    for args, said in [(["--help"], "Usage: main [OPTIONS] COMMAND [ARGS]..."), (["--version"], "uitamr, version ")]:
        result = invoke(*args, "verify", "--junit", tmp_path / "c.xml")
        assert result.exit_code == 0 and result.output.startswith(said), result.output
    assert not (tmp_path / "c.xml").exists()


#: a name longer than any file system takes (255 bytes a name; 4096 a path on Linux)
VERY_LONG = "a" * 5000


def test_an_input_name_too_long_is_the_junits_error(tmp_path):
    """`uitamr verify <5000 characters>.st --junit v.xml`: asking whether the name is a folder
    of scenarios raised the file system's OSError (ENAMETOOLONG), which only `uitamr`'s
    generic path error caught: exit 2, but no JUnit, so CI showed an earlier run's file.
    Now the name is an unusable input as any other, named with what is wrong."""
    report = tmp_path / "v.xml"
    for args, said in [([tmp_path / f"{VERY_LONG}.st"], f"{tmp_path / VERY_LONG}.st: File name too long"),
                       (["--scenario", tmp_path / f"{VERY_LONG}.toml"],
                        f"{tmp_path / VERY_LONG}.toml: cannot read: File name too long")]:
        report.write_text(OLD_RUN, encoding="utf-8")
        result = invoke("verify", *args, "--junit", report)
        assert result.exit_code == 2, result.output
        assert f"error: {said}" in result.output and f"wrote {report} (these errors as test cases)" in result.output
        (case,) = cases(report)
        assert case.find("error").get("message") == said


def test_a_report_name_too_long_is_refused_before_the_run(tmp_path):
    """A --junit (or --json) name the file system refuses was found only when the report was
    written, after the whole run; now before it, as a folder that does not exist is, with
    the name and what is wrong, and another report's refusal is the JUnit's error."""
    write_files(tmp_path, {"GOOD.st": GOOD})
    long_report = tmp_path / f"{VERY_LONG}.xml"
    capture = tmp_path / "site.txt"
    capture.write_text("0.000 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    for args in (["verify", tmp_path / "GOOD.st", "--duration", "1s"], ["replay", capture],
                 ["monitor", "--tcp", "127.0.0.1:1"]):
        for report in (long_report, tmp_path / VERY_LONG / "v.xml"):
            result = invoke(*args, "--junit", report)
            assert result.exit_code == 2, result.output
            assert f"cannot write {report}: File name too long" in result.output
            assert "requests" not in result.output and "wrote" not in result.output  # no run, no report
    result = invoke("verify", tmp_path / "GOOD.st", "--duration", "1s", "--json", tmp_path / f"{VERY_LONG}.json",
                    "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "v.xml")
    assert case.find("error").get("message") == f"cannot write {tmp_path / VERY_LONG}.json: File name too long"


def test_a_path_the_file_system_refuses_anywhere_in_a_judging_command_is_the_junits_error(tmp_path, monkeypatch):
    """Whatever path of the run the file system refuses where no code expected it (an
    OSError that names its file), the command says `uitamr`'s generic path error, exit 2,
    and its JUnit holds that error too."""
    import errno

    import verifier.commands.verify as verify

    def refused(*_args, **_kw):
        raise OSError(errno.ENAMETOOLONG, "File name too long", str(tmp_path / "deep.st"))

    monkeypatch.setattr(verify, "_scenarios", refused)
    report = tmp_path / "v.xml"
    result = invoke("verify", "--junit", report)
    assert result.exit_code == 2, result.output
    assert f"Error: {tmp_path / 'deep.st'}: File name too long" in result.output
    assert cases(report)[0].find("error").get("message") == f"{tmp_path / 'deep.st'}: File name too long"


def test_a_junit_that_is_a_pipe_is_written_to_its_reader_not_read(tmp_path):
    """`--junit` naming a FIFO (a CI uploader reading it): before writing the JUnit of a run
    that cannot start, the file was opened to read, to see it holds no input, and that open
    waited for a writer that never came - the command hung, with the pipe's reader waiting
    too. A pipe is not read now; the report goes to its reader."""
    import os
    import sys
    import threading

    fifo = tmp_path / "junit.fifo"
    os.mkfifo(fifo)
    got: list[bytes] = []

    def reader():
        with open(fifo, "rb") as pipe:
            got.append(pipe.read())

    thread = threading.Thread(target=reader, daemon=True)
    thread.start()
    try:
        done = procs.run([sys.executable, "-m", "verifier.cli", "replay", str(tmp_path / "gone.txt"),
                               "--junit", str(fifo)], capture_output=True, text=True, timeout=60)
    finally:
        if thread.is_alive():  # whatever happened, the reader is let go
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        thread.join(timeout=10)
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"wrote {fifo} (these errors as test cases)" in done.stderr
    assert got and b'type="unusable-input"' in got[0] and b"gone.txt" in got[0]


def test_an_empty_report_name_is_a_command_line_mistake(tmp_path, monkeypatch):
    """`--junit "$REPORT"` with REPORT unset gave --junit an empty name, which was taken for
    no report at all: the run went on, exit 0 or 1, and CI found no file (or an earlier
    one). An empty name is a usage mistake now, named with its option, in the JUnit file
    when another option names one. `monitor --capture` takes its file so too (it took
    `--json` for the capture's name in `--capture --json r.json`)."""
    monkeypatch.chdir(tmp_path)
    capture = tmp_path / "site.txt"
    capture.write_text("0.000 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    runs = {"verify": ["--duration", "1s"], "replay": [capture], "monitor": ["--tcp", "127.0.0.1:1"]}
    for command, args in runs.items():
        for option in ("--json", "--junit", "--trace", "--html") + (("--capture",) if command == "monitor" else ()):
            given = [option, ""] if option == "--junit" else [option, "", "--junit", tmp_path / "j.xml"]
            result = invoke(command, *args, *given)
            assert result.exit_code == 2, (command, option, result.output)
            said = f"Invalid value for '{option}': the file's name is empty"
            assert said in result.stderr, result.output
            if option != "--junit":
                assert cases(tmp_path / "j.xml")[0].find("error").get("message").startswith(said)
    result = invoke("monitor", "--tcp", "127.0.0.1:1", "--capture", "--json", "r.json")
    assert result.exit_code == 2 and "Invalid value for '--capture': '--json' is an option, not a file" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["j.xml", "site.txt"]


def test_st_that_does_not_load_is_named_as_the_command_line_reaches_it(tmp_path, monkeypatch):
    """`uitamr verify plc/*.st` in the repository named a syntax error
    `/home/runner/work/.../plc/MAIN.st:5:6` on the console and in the JUnit test case's name
    and `file`, while `uitamr check`, the frames' "sent by" and every scenario mistake name
    it from the working folder: `plc/MAIN.st:5:6`. The ST's own path now, with the platform
    given and told from the sources alike."""
    (tmp_path / "plc").mkdir()
    write_files(tmp_path, {"plc/MAIN.st": BROKEN})
    monkeypatch.chdir(tmp_path)
    for platform in (["--platform", "fx3u"], ["--matrix"]):
        result = invoke("verify", "plc/MAIN.st", *platform, "--junit", "v.xml")
        assert result.exit_code == 2, result.output
        assert "plc/MAIN.st:5:6: error: expected an expression" in result.output
        assert str(tmp_path) not in result.output, result.output
        (case,) = cases(tmp_path / "v.xml")
        assert (case.get("name"), case.get("file")) == ("plc/MAIN.st:5:6", "plc/MAIN.st")


def test_a_mistake_test_case_carries_its_line_for_the_annotation(tmp_path):
    """A typo in a scenario key (`duraton`) was the test case `x.toml:4:1` with `file` but
    no `line`: GitHub's JUnit actions read `file` and `line` and put the annotation on
    line 1 of the file. The line is now the mistake's own; a file that cannot be read at
    all (its place 0:0) gets none."""
    write_files(tmp_path, {"GOOD.st": GOOD, "x.toml": 'name = "x"\nprogram = "GOOD"\n\nduraton = "30s"\n'})
    result = invoke("verify", tmp_path / "GOOD.st", "--scenario", tmp_path / "x.toml", "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    (case,) = cases(tmp_path / "v.xml")
    assert (case.get("file"), case.get("line")) == (str(tmp_path / "x.toml"), "4")
    result = invoke("verify", tmp_path / "MISSING.st", tmp_path / "GOOD.st", "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    assert all(case.get("line") is None for case in cases(tmp_path / "v.xml"))
