"""The Python API of docs/testing-st.md as an integrator uses it on their own ST: labels
of every class read and written by name, and a user's mistake in a call answered with
what to fix rather than an error from inside the toolkit."""
from __future__ import annotations

import verifier

from sim_helpers import FB_DELAY

GLOBALS_AND_FB = """
TYPE ST_Station :
STRUCT
    iX : INT;
    aiSlots : ARRAY[1..3] OF INT;
END_STRUCT
END_TYPE
VAR_GLOBAL
    g_iCycles : INT;
    g_stHome : ST_Station;
    g_bStop AT M5 : BOOL;
END_VAR
FUNCTION_BLOCK FB_Count
VAR_INPUT
    i_bPulse : BOOL;
END_VAR
VAR_EXTERNAL
    g_iCycles : INT;
    g_stHome : ST_Station;
    g_bStop : BOOL;
END_VAR
IF i_bPulse AND NOT g_bStop THEN
    g_iCycles := g_iCycles + 1;
    g_stHome.iX := g_iCycles;
    g_stHome.aiSlots[1] := g_iCycles * 2;
END_IF;
END_FUNCTION_BLOCK
"""


def test_an_fb_reads_and_writes_its_var_external_labels_by_name():
    """A VAR_EXTERNAL label read through the FB instance is the global (it used to raise
    AttributeError "'FB_FB_COUNT' object has no attribute 'g_iCycles'", and the pytest
    plugin's ST state showed that message in place of the value)."""
    project = verifier.load(sources={"FB_Count.st": GLOBALS_AND_FB})
    fb = project.instance("FB_Count")
    fb.i_bPulse = True
    fb.scan(3)
    assert fb.g_iCycles == 3 == project.globals.g_iCycles
    assert fb.g_stHome.iX == 3 and list(fb.g_stHome.aiSlots) == [6, 0, 0]
    assert fb.g_bStop is False
    fb.g_iCycles = 10                      # written through the FB: the global changes
    fb.g_bStop = True                      # a global at a device: the device changes
    assert project.globals.g_iCycles == 10 and project.devices["M5"] is True
    fb.scan()
    assert fb.g_iCycles == 10
    assert "g_iCycles=10" in repr(fb)
    from verifier.pytest_plugin import describe_project
    state = describe_project(project)
    assert "g_iCycles = 10  (FB_Count.st:9:5)" in state and "object has no attribute" not in state


def test_a_var_external_structure_taken_before_a_restart_is_the_cpus_after_it():
    project = verifier.load(sources={"FB_Count.st": GLOBALS_AND_FB})
    fb = project.instance("FB_Count")
    home = fb.g_stHome
    fb.i_bPulse = True
    fb.scan(2)
    assert home.iX == 2
    project.restart()
    assert home.iX == 0
    home.iX = 7
    assert project.globals.g_stHome.iX == 7


DELAY = FB_DELAY + """PROGRAM MAIN
VAR fb : FB_Delay; END_VAR
fb(i_bExecute := TRUE);
END_PROGRAM
"""


def _error(call) -> BaseException:
    try:
        call()
    except Exception as exc:  # the type and message are what the tests look at
        return exc
    raise AssertionError("no error")


def test_run_until_with_ms_or_scans_says_to_give_timeout_ms():
    """`fb.run(ms=100, until=...)` used to ignore ms and wait up to the default 60 s,
    then say "condition not met within 60000 ms" although the test said 100."""
    fb = verifier.load(sources={"d.st": DELAY}).instance("FB_Delay")
    fb.i_bExecute = True
    for kwargs in ({"ms": 100}, {"scans": 3}):
        err = _error(lambda: fb.run(until=lambda f: f.o_bDone, **kwargs))
        assert isinstance(err, TypeError)
        assert "give the most virtual time to wait as timeout_ms=..., not ms= or scans=" in str(err)
    assert fb._project.scan_count == 0
    err = _error(lambda: fb.run(until=lambda f: f.o_bDone, timeout_ms="5s"))
    assert isinstance(err, ValueError) and "timeout_ms must be a finite number of milliseconds" in str(err)
    fb.run(until=lambda f: f.o_bDone, timeout_ms=5000)
    assert fb._project.now_us == 3_010_000


def test_run_until_a_value_rather_than_a_function_says_what_until_is():
    """`fb.run(until=fb.o_bDone)` (the value, not a function) used to fail inside the
    toolkit with "'bool' object is not callable"."""
    fb = verifier.load(sources={"d.st": DELAY}).instance("FB_Delay")
    err = _error(lambda: fb.run(until=fb.o_bDone))
    assert isinstance(err, TypeError)
    assert str(err) == ("until is a function of the instance that says when to stop, e.g. "
                        "until=lambda fb: fb.o_bDone; got False")


def test_a_run_given_two_lengths_says_to_give_one():
    """`run(ms=..., scans=...)` used to stop at whichever came first, silently. An instance's
    run was then told to give until_us=, which it does not take (it takes until=, the
    condition testing-st.md shows)."""
    project = verifier.load(sources={"d.st": DELAY})
    fb = project.instance("FB_Delay")
    err = _error(lambda: fb.run(ms=100, scans=5))
    assert isinstance(err, ValueError)
    assert str(err) == ("say how long to run once: ms= and scans= are both given; "
                        "give one of ms=..., scans=... or until=...")
    err = _error(lambda: project.run_programs(["MAIN"], scans=2, until_us=50_000))
    assert str(err) == ("say how long to run once: scans= and until_us= are both given; "
                        "give one of ms=..., scans=... or until_us=...")
    assert project.scan_count == 0
    project.run_programs(["MAIN"], scans=2)
    fb.run(scans=2)
    assert project.scan_count == 4


def test_a_device_set_from_python_to_a_value_of_the_wrong_kind_is_refused():
    """`devices["D10"] = 1.5` used to store 1, `devices["X0"] = 5` or `= 'a'` TRUE and
    `devices["D10"] = "7"` 7, silently, where a label refuses the same mistake."""
    project = verifier.load(sources={"d.st": DELAY})
    devices = project.devices
    refused = {
        ("D10", 1.5): "D10 is a word device: give a whole number, got the float 1.5",
        ("D10", True): "D10 is a word device: give a whole number, got True",
        ("D10", "7"): "D10 is a word device: give a whole number, got '7'",
        ("D10", None): "D10 is a word device: give a whole number, got None",
        ("X0", 5): "X0 is a bit device: give True or False (or 1/0), got 5",
        ("M0", "yes"): "M0 is a bit device: give True or False (or 1/0), got 'yes'",
        ("D10.3", 2): "D10.3 is a bit of a word device: give True or False (or 1/0), got 2",
        ("K4M0", 1.0): "K4M0 is a digit group of bit devices: give a whole number, got the float 1.0",
    }
    for (name, value), message in refused.items():
        err = _error(lambda: devices.__setitem__(name, value))
        assert isinstance(err, ValueError) and str(err) == message
    assert devices["D10"] == 0 and devices["X0"] is False and devices["K4M0"] == 0
    devices["X0"], devices["M100"], devices["D12.3"] = True, 1, True
    devices["D10"] = 0xFFFF
    devices["D11"] = 70000                 # wrapped to 16 bits, as an INT label is
    devices["K4M0"] = 0x1234
    assert devices["X0"] is True and devices["M100"] is True and devices["D12"] == 8
    assert devices["D10"] == -1 and devices["D11"] == 4464 and devices["K4M0"] == 0x1234


def test_load_options_of_the_wrong_type_are_load_errors_naming_the_option():
    """`verifier.load(..., scan_ms="10")` failed inside the toolkit ("type str doesn't
    define __round__ method"), `scan_ms=inf` with OverflowError, `target=None` with
    AttributeError, and `stop_on_operation_error="yes"` was taken as True."""
    from verifier.sim import LoadError

    cases = {
        "scan_ms": ("10", "scan_ms must be a finite number of milliseconds; got '10'"),
        "jitter_ms": (None, "jitter_ms must be a finite number of milliseconds; got None"),
        "stop_on_operation_error": ("yes", "stop_on_operation_error is True, False or None (the CPU's "
                                           "default); got 'yes'"),
    }
    for option, (value, message) in cases.items():
        err = _error(lambda: verifier.load(sources={"d.st": DELAY}, **{option: value}))
        assert isinstance(err, LoadError) and str(err) == ("verifier.load was given an option it cannot use:\n"
                                                           f"  verifier.load({option}={value!r}): error: {message}")
    err = _error(lambda: verifier.load(sources={"d.st": DELAY}, scan_ms=float("inf")))
    assert isinstance(err, LoadError) and "scan_ms must be a finite number" in str(err)
    err = _error(lambda: verifier.load(sources={"d.st": DELAY}, target=None))
    assert isinstance(err, TypeError) and str(err) == "target is a name such as 'gxworks2'; got None"
    assert verifier.load(sources={"d.st": DELAY}, scan_ms=2.5).rt.scan_us == 2500


def test_a_folder_without_st_files_of_its_own_is_a_load_error_naming_the_subfolders(tmp_path):
    """`verifier.load("plc")` loaded nothing, silently: the next `instance("UITAMR_Stop")`
    said only "no POU named 'UITAMR_Stop'; loaded: " (an empty list)."""
    from verifier.sim import LoadError

    (tmp_path / "lib" / "core").mkdir(parents=True)
    (tmp_path / "lib" / "core" / "FB_Delay.st").write_text(DELAY, encoding="utf-8")
    (tmp_path / "empty").mkdir()
    err = _error(lambda: verifier.load(tmp_path / "lib"))
    assert isinstance(err, LoadError)
    assert str(err).endswith(f"{tmp_path / 'lib'}:0:0: error: no .st files in this folder (load reads a "
                             "folder's own *.st files, not its subfolders); name the folders that hold "
                             f"them: '{tmp_path / 'lib' / 'core'}'")
    err = _error(lambda: verifier.load(tmp_path / "empty"))
    assert isinstance(err, LoadError) and str(err).endswith("not its subfolders)")
    assert "FB_Delay" in verifier.load(tmp_path / "lib" / "core").pou_names()


def test_an_instance_or_structure_read_as_a_value_says_which_label_to_read():
    """`assert fb.fbTimer` (meant: fbTimer.Q) passed whatever the timer did, and
    `fb.fbTimer == True` was silently False: a proxy was truthy and compared by identity."""
    text = DELAY + ("TYPE ST_Pos :\nSTRUCT\n    iX : INT;\nEND_STRUCT\nEND_TYPE\n"
                    "FUNCTION_BLOCK FB_Holder\nVAR_OUTPUT o_bOk : BOOL; END_VAR\n"
                    "VAR fbDelay : FB_Delay; stPos : ST_Pos; fbEdge : R_TRIG; END_VAR\n"
                    "fbDelay(i_bExecute := TRUE);\nfbEdge(CLK := fbDelay.o_bDone);\nEND_FUNCTION_BLOCK\n")
    project = verifier.load(sources={"d.st": text})
    fb = project.instance("FB_Holder")
    expected = {
        "FB_Holder.fbDelay.fbTimer": "FB_Holder.fbDelay.fbTimer is an instance of TON, not a value: read one "
                                     "of its labels, e.g. FB_Holder.fbDelay.fbTimer.Q",
        "FB_Holder.fbEdge": "FB_Holder.fbEdge is an instance of R_TRIG, not a value: read one of its labels, "
                            "e.g. FB_Holder.fbEdge.Q",
        "FB_Holder.fbDelay": "FB_Holder.fbDelay is an instance of FB_Delay, not a value: read one of its "
                             "labels, e.g. FB_Holder.fbDelay.o_bDone",
        "FB_Holder.stPos": "FB_Holder.stPos is a structure, not a value: read one of its labels, "
                           "e.g. FB_Holder.stPos.iX",
        "MAIN": "MAIN is the PROGRAM MAIN, not a value: read one of its labels, e.g. MAIN.fb",
    }
    views = {"FB_Holder.fbDelay.fbTimer": fb.fbDelay.fbTimer, "FB_Holder.fbEdge": fb.fbEdge,
             "FB_Holder.fbDelay": fb.fbDelay, "FB_Holder.stPos": fb.stPos, "MAIN": project.program("MAIN")}
    for label, view in views.items():
        for misuse in (lambda: bool(view), lambda: view == 1, lambda: view != True):  # noqa: E712
            err = _error(misuse)
            assert isinstance(err, TypeError) and str(err) == expected[label]
    assert fb.fbDelay.fbTimer == fb.fbDelay.fbTimer           # the same memory: equal
    assert fb.fbDelay.fbTimer in {fb.fbDelay.fbTimer}
    assert fb.fbDelay.fbTimer != project.instance("FB_Delay").fbTimer


def test_an_array_indexed_by_something_else_than_a_whole_number_says_so():
    """`fb.a["1"]` failed inside the toolkit ("'<=' not supported between instances of
    'int' and 'str'"), `fb.a[1.0]` with "list indices must be integers", and `fb.a[True]`
    read element 1."""
    text = ("FUNCTION_BLOCK FB_A\nVAR a : ARRAY[1..4] OF INT; m : ARRAY[0..1, 1..2] OF INT; END_VAR\n"
            "a[2] := 7;\nEND_FUNCTION_BLOCK\n")
    fb = verifier.load(sources={"a.st": text}).instance("FB_A")
    fb.scan()
    for index in ("1", 1.0, True):
        for use in (lambda: fb.a[index], lambda: fb.a.__setitem__(index, 3)):
            err = _error(use)
            assert isinstance(err, TypeError)
            assert str(err) == f"FB_A.a is indexed by whole numbers within its ST bounds [1..4]; got {index!r}"
    err = _error(lambda: fb.m[0, "2"])
    assert str(err) == "FB_A.m is indexed by whole numbers within its ST bounds [0..1, 1..2]; got '2'"
    assert fb.a[2] == 7 and list(fb.a) == [0, 7, 0, 0]
    fb.m[1, 2] = 5
    assert fb.m[1, 2] == 5


def test_an_array_slice_counts_in_st_indexes_as_an_index_does():
    """`fb.a[1:3]` of ARRAY[1..4] gave Python positions 1 and 2 (elements 2 and 3) while
    `fb.a[1]` is element 1: the doc promises a view indexed by the ST bounds."""
    text = ("FUNCTION_BLOCK FB_A\nVAR a : ARRAY[1..4] OF INT; b : ARRAY[-2..2] OF INT; END_VAR\n"
            "a[1] := 1; a[2] := 2; a[3] := 3; a[4] := 4; b[-2] := -2; b[0] := 10;\nEND_FUNCTION_BLOCK\n")
    fb = verifier.load(sources={"a.st": text}).instance("FB_A")
    fb.scan()
    assert fb.a[1:3] == [1, 2] and fb.a[2:] == [2, 3, 4] and fb.a[:] == [1, 2, 3, 4]
    assert fb.a[0:10] == [1, 2, 3, 4] and fb.a[::-1] == [4, 3, 2, 1] and fb.a[4:1:-1] == [4, 3, 2]
    assert fb.b[-2:1] == [-2, 0, 10] and fb.b[:0] == [-2, 0]
    err = _error(lambda: fb.a["1":])
    assert isinstance(err, TypeError)
    assert str(err) == "FB_A.a is sliced by whole numbers within its ST bounds [1..4]; got '1'"


def test_fx5u_sources_loaded_without_a_target_name_the_target_that_loads_them():
    """An FX5U integrator's `st_load("vendor/uitamr/plc/core", ".../UITAMR_PortFx5.st",
    "src")` (testing-st.md, no target: GX Works2 and the FX3U) failed with errors inside the
    library's port FB (`device SM8561: the fx3u has no SM devices ...`) and nothing about the
    target to give. Now the errors end with a note naming target='gxworks3'; with a target
    given, the errors are the target's alone."""
    from pathlib import Path

    import pytest
    from verifier.sim.errors import LoadError

    plc = Path(__file__).resolve().parents[1] / "plc"
    main = ("PROGRAM Main\nVAR\n    fbPort : UITAMR_PortFx5;\n    uPort : ARRAY[0..39] OF WORD;\nEND_VAR\n"
            "fbPort(i_bEN := NOT SM402, i_wChannel := 1, io_uPort := uPort);\nEND_PROGRAM\n")
    paths = [plc / "core", plc / "fx5" / "UITAMR_PortFx5.st"]
    with pytest.raises(LoadError) as caught:
        verifier.load(*paths, sources={"Main.st": main})
    lines = caught.value.lines()
    assert any("SM8561" in line for line in lines[:-1])
    assert lines[-1] == ("verifier.load(target='gxworks2'): note: the sources load with target='gxworks3' "
                         "(the fx5u CPU): give target='gxworks3'")
    assert caught.value.place() is not None and "SM" in str(caught.value)  # still placed by its first ST error
    with pytest.raises(LoadError) as told:
        verifier.load(*paths, sources={"Main.st": main}, target="gxworks2")
    assert not any("note:" in line for line in told.value.lines())
    # a program with an error on every CPU gets no note
    with pytest.raises(LoadError) as broken:
        verifier.load(*paths, sources={"Main.st": main.replace("uPort);", "uPortt);")})
    assert not any("note:" in line for line in broken.value.lines())
    # and the sources load as the note says
    assert verifier.load(*paths, sources={"Main.st": main}, target="gxworks3").cpu.name == "fx5u"


def test_a_misspelt_label_read_from_python_offers_the_label_meant():
    """`main.fbEngin.o_bErr` in an integrator's pytest said only "Main has no label
    'fbEngin'", where the same name in a scenario offers 'fbEngine': now the API guesses
    too, for a label of one's own POU and for a standard FB's input/output."""
    import pytest

    project = verifier.load(sources={"d.st": FB_DELAY})
    fb = project.instance("FB_Delay")
    with pytest.raises(AttributeError) as caught:
        fb.fbTimr
    assert str(caught.value) == "FB_Delay has no label 'fbTimr'; did you mean 'fbTimer'?"
    with pytest.raises(AttributeError) as caught:
        fb.fbTimer.PTT
    assert str(caught.value) == "FB_Delay.fbTimer (TON) has no input/output PTT; did you mean 'PT'?"
    with pytest.raises(AttributeError) as caught:
        fb.zzz
    assert str(caught.value) == "FB_Delay has no label 'zzz'"
    assert not hasattr(fb, "zzz")


def test_in_asks_whether_the_cpu_has_a_device():
    """`"Y6" in project.devices` in a test ended in an AttributeError traceback ('int' object
    has no attribute 'strip': Python tried devices[0], devices[1] ...); now True for a
    device this CPU has, False for one it has not or a name that is none."""
    project = verifier.load(sources={"P.st": "PROGRAM P\nY6 := X0;\nEND_PROGRAM\n"})
    assert "Y6" in project.devices and "d100" in project.devices
    assert "Y8" not in project.devices and "D9000" not in project.devices  # octal Y; past D8511 on the FX3U
    assert "fbEngine" not in project.devices and 6 not in project.devices
