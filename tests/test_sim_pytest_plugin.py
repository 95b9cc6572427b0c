"""The pytest plugin integrators use: fixtures load ST, and a failing assertion shows the
ST labels' values with their declaration locations."""
from __future__ import annotations

import re
import textwrap

from sim_helpers import FB_DELAY

pytest_plugins = ["pytester"]

# an index out of range in the third scan: a SimulationError at FB_OOB.st:4:3
FB_OOB = textwrap.dedent("""
    FUNCTION_BLOCK FB_OOB
    VAR i : INT; a : ARRAY[0..1] OF INT; END_VAR
    i := i + 1;
    a[i] := 1;
    END_FUNCTION_BLOCK
""")



def test_fixtures_run_st_and_failures_show_st_state(pytester):
    pytester.makefile(".st", FB_DELAY=FB_DELAY)
    pytester.makepyfile(test_delay=textwrap.dedent("""
        import pytest

        @pytest.mark.st("FB_DELAY.st", target="gxworks2", scan_ms=10)
        def test_done_after_3s(st_project):
            fb = st_project.instance("FB_DELAY")
            fb.i_bExecute = True
            fb.run(ms=3000)          # scans starting at 0, 10, ..., 2990 ms
            assert not fb.o_bDone
            fb.scan()                # the scan starting at 3000 ms sees the timer done
            assert fb.o_bDone

        def test_wrong_expectation(st_load):
            fb = st_load("FB_DELAY.st").instance("FB_DELAY")
            fb.i_bExecute = True
            fb.run(ms=1000)
            assert fb.o_bDone
    """))
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    assert "ST state 1" in out
    assert "o_bDone = False  (FB_DELAY.st:3:12)" in out
    assert "virtual time 1.000000 s after 100 scans" in out


def test_simulation_error_location_is_reported(pytester):
    pytester.makefile(".st", FB_OOB=FB_OOB)
    pytester.makepyfile(test_oob=textwrap.dedent("""
        def test_oob(st_load):
            st_load("FB_OOB.st").instance("FB_OOB").scan(3)
    """))
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(failed=1)
    assert "FB_OOB.st:4:3: index 2 is outside a[0..1]" in result.stdout.str()


def test_st_that_does_not_load_is_reported_at_its_line_not_with_the_simulators_traceback(pytester):
    """An integrator's ST with a syntax error, or a file named wrong in @pytest.mark.st: the
    failure shows the test's own line and the LoadError's file:line:col, not pages of
    traceback through verifier/sim (docs/testing-st.md: errors point at ST lines)."""
    pytester.makefile(".st", Broken="FUNCTION_BLOCK Broken\nVAR\n    n : INT;\nEND_VAR\nn := n + ;\nEND_FUNCTION_BLOCK\n")
    pytester.makepyfile(test_broken=textwrap.dedent("""
        import pytest

        def test_syntax(st_load):
            st_load("Broken.st")

        @pytest.mark.st("Missing.st")
        def test_missing(st_project):
            pass
    """))
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(failed=1, errors=1)
    out = result.stdout.str()
    assert "Broken.st:5:" in out and "Missing.st:0:0: error: cannot read" in out
    assert 'st_load("Broken.st")' in out          # the test's own line stays
    # the mark that named the missing file, where the fixture loaded it: no line of the
    # user's was left at all, only the ERROR header's test name
    assert re.search(r'test_broken\.py:6: @pytest\.mark\.st\("Missing\.st"\)', out), out
    assert "verifier/sim/" not in out and "pytest_plugin.py" not in out, out


def test_a_load_error_report_keeps_the_users_fixture_line_and_whole_tracebacks_on_request(pytester):
    """The short report of ST that does not load kept only the test file's lines: a load in
    a conftest fixture showed no line of the user's at all; and --full-trace / --tb=long,
    asked for to see inside the loader, still gave the short report."""
    pytester.makefile(".st", Broken="FUNCTION_BLOCK Broken\nVAR\n    n : INT;\nEND_VAR\nn := n + ;\nEND_FUNCTION_BLOCK\n")
    pytester.makeconftest(textwrap.dedent("""
        import pytest

        @pytest.fixture
        def broken(st_load):
            return st_load("Broken.st")
    """))
    pytester.makepyfile(test_broken="def test_fixture(broken):\n    pass\n")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(errors=1)
    out = result.stdout.str()
    assert "Broken.st:5:" in out and 'conftest.py:5: return st_load("Broken.st")' in out, out
    assert "verifier/sim/" not in out and "_pytest" not in out, out
    for asked in ("--full-trace", "--tb=long"):
        result = pytester.runpytest_subprocess("-p", "no:cacheprovider", asked)
        result.assert_outcomes(errors=1)
        assert "verifier/sim/" in result.stdout.str() and "Broken.st:5:" in result.stdout.str(), asked


def test_the_st_state_reaches_the_junit_xml_a_ci_server_shows(pytester):
    """With `pytest --junitxml`, as a CI job runs the integrator's ST tests, the <failure>
    held only `assert False` and the traceback: the ST state and the ST location went to the
    terminal alone (report sections --junitxml does not write). They are now in the
    failure's text, once, also from an xdist worker; the terminal shows them once, as before."""
    pytester.makefile(".st", FB_DELAY=FB_DELAY, FB_OOB=FB_OOB)
    pytester.makepyfile(test_ci=textwrap.dedent("""
        def test_wrong_expectation(st_load):
            fb = st_load("FB_DELAY.st").instance("FB_DELAY")
            fb.i_bExecute = True
            fb.run(ms=1000)
            assert fb.o_bDone

        def test_oob(st_load):
            st_load("FB_OOB.st").instance("FB_OOB").scan(3)
    """))
    import xml.etree.ElementTree as ET

    for workers in ([], ["-n", "1"]):
        result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--junitxml=junit.xml", *workers)
        result.assert_outcomes(failed=2)
        assert result.stdout.str().count("ST state 1") == 2, result.stdout.str()
        failures = {case.get("name"): case.find("failure").text
                    for case in ET.parse(pytester.path / "junit.xml").getroot().iter("testcase")}
        delay, oob = failures["test_wrong_expectation"], failures["test_oob"]
        assert delay.count("ST state 1") == 1 and "o_bDone = False  (FB_DELAY.st:3:12)" in delay, delay
        assert "virtual time 1.000000 s after 100 scans" in delay
        assert "ST location" in oob and "FB_OOB.st:4:3: index 2 is outside a[0..1]" in oob, oob


def test_st_project_without_its_mark_says_what_to_add_at_the_test(pytester):
    """A test that asks for st_project without @pytest.mark.st got the plugin's fixture
    source and `pytest.UsageError` (a command-line error's class) as its report. It now
    gets the test's place and what to write, without the plugin's traceback."""
    pytester.makepyfile(test_nomark="def test_nomark(st_project):\n    pass\n")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(errors=1)
    out = result.stdout.str()
    assert "test_nomark.py:1: test_nomark uses the st_project fixture but has no @pytest.mark.st(" in out, out
    assert "pytest_plugin.py" not in out and "UsageError" not in out, out
