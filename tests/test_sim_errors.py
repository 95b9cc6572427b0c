"""User mistakes get clear errors naming file, line and column — never a traceback."""
from __future__ import annotations

import pytest

import verifier
from sim_helpers import FakeEndpoint, load_st
from verifier.sim import LoadError, SimulationError


def test_missing_file_is_a_load_error(tmp_path):
    with pytest.raises(LoadError) as err:
        verifier.load(str(tmp_path / "nope.st"))
    assert "nope.st:0:0: error: cannot read" in str(err.value)


def test_unknown_target_and_cpu():
    with pytest.raises(LoadError) as err:
        load_st("PROGRAM P\nEND_PROGRAM\n", target="gxworks9")
    assert "unknown target" in str(err.value)
    with pytest.raises(LoadError) as err:
        load_st("PROGRAM P\nEND_PROGRAM\n", cpu="fx2n")
    assert "unknown CPU" in str(err.value)


@pytest.mark.parametrize("target, cpu, message", [
    ("gxworks2", "fx5u", "GX Works2 does not program the FX5U CPU (GX Works3 does): use target='gxworks3' "
                         "with cpu='fx5u', or a CPU GX Works2 programs: fx3u, fx3g, q"),
    ("gxworks2:fx5uc", None, "GX Works2 does not program the FX5U CPU (GX Works3 does)"),
    ("gxworks3", "fx3u", "GX Works3 does not program the FX3U CPU (GX Works2 does): use target='gxworks2' "
                         "with cpu='fx3u', or a CPU GX Works3 programs: fx5u"),
    ("gxworks3", "FX3G", "GX Works3 does not program the FX3G CPU (GX Works2 does)"),
    ("gxworks3:q", None, "GX Works3 does not program the Q CPU (GX Works2 does)"),
    ("gxworks2:q", "fx3u", "target 'gxworks2:q' and cpu='fx3u' name two CPUs; name the CPU once"),
    ("gxworks9", "q", "unknown target 'gxworks9'; use one of ['gxworks2', 'gxworks3']"),
])
def test_a_cpu_the_editor_does_not_program_is_refused(target, cpu, message):
    with pytest.raises(LoadError) as err:
        load_st("PROGRAM P\nEND_PROGRAM\n", target=target, cpu=cpu)
    given = f"target={target!r}" + ("" if cpu is None else f", cpu={cpu!r}")
    assert str(err.value).startswith(f"verifier.load was given an option it cannot use:\n"
                                     f"  verifier.load({given}): error: {message}")


@pytest.mark.parametrize("target, cpu", [("gxworks2", "fx3u"), ("gxworks2", "fx3gc"), ("gxworks2", "qnu"),
                                         ("gxworks2:q", "q"), ("gxworks2:Q", None), ("gxworks3", "fx5uc"),
                                         ("GXWorks2", None), ("GXWORKS3:FX5U", None)])
def test_the_cpus_each_editor_programs_load(target, cpu):
    load_st("PROGRAM P\nEND_PROGRAM\n", target=target, cpu=cpu)


def test_a_target_in_capitals_applies_its_editors_rules():
    """'GXWorks2' is GX Works2 for the dialect too, not only for the CPU: its label tables
    have no initial values."""
    with pytest.raises(LoadError, match="GX Works2 label tables have no initial value column"):
        load_st("PROGRAM P\nVAR w : INT := 5; END_VAR\nw := w + 1;\nEND_PROGRAM\n", target="GXWorks2")


def test_target_and_cpu_are_names():
    with pytest.raises(TypeError, match="target is a name such as 'gxworks2'; got 2"):
        load_st("PROGRAM P\nEND_PROGRAM\n", target=2)
    with pytest.raises(TypeError, match="cpu is a name such as 'fx3u'; got 5"):
        load_st("PROGRAM P\nEND_PROGRAM\n", cpu=5)


def test_instruction_of_another_cpu_is_refused_at_its_location():
    src = ("PROGRAM P\nVAR c : ARRAY[0..2] OF WORD; d : ARRAY[0..3] OF WORD; b : ARRAY[0..1] OF BOOL; END_VAR\n"
           "G_OUTPUT(TRUE, 16#0, c, d, b);\nEND_PROGRAM\n")
    with pytest.raises(LoadError) as err:
        load_st(src)  # FX3U by default
    assert "t.st:3:1: error: G_OUTPUT does not exist on the fx3u" in str(err.value)
    load_st(src, cpu="q")  # fine on a Q CPU


@pytest.mark.parametrize("cpu, fits", [("fx3u", False), ("fx3g", False), ("q", True)])
def test_an_index_register_the_cpu_lacks_is_refused_at_load_not_at_run_time(cpu, fits):
    # FX3U/FX3G have Z0..Z7, the Q Z0..Z19: D0Z8 used to load on an FX3U and fail in the scan
    src = "PROGRAM P\nVAR x : INT; END_VAR\nx := D10Z8;\nEND_PROGRAM\n"
    if fits:
        load_st(src, cpu=cpu).run_programs(["P"], scans=1)
        return
    with pytest.raises(LoadError) as err:
        load_st(src, cpu=cpu)
    assert f"t.st:3:6: error: device D10Z8: index register Z8 does not exist on the {cpu} (Z0..Z7)" in str(err.value)


def test_rs2_on_a_channel_the_cpu_lacks():
    src = ("PROGRAM P\nVAR s, r : ARRAY[0..3] OF WORD; END_VAR\n"
           "RS2(TRUE, s[0], 4, 4, 3, r[0]);\nEND_PROGRAM\n")
    project = load_st(src)
    with pytest.raises(SimulationError) as err:
        project.run_programs(["P"], scans=1)
    assert err.value.location == "t.st:3:1"
    assert "channel n1=3 does not exist" in str(err.value)


def test_attach_serial_checks_the_channel():
    project = load_st("PROGRAM P\nEND_PROGRAM\n")
    with pytest.raises(ValueError, match="unknown serial channel"):
        project.attach_serial("com1", FakeEndpoint())
    with pytest.raises(ValueError, match="does not exist on the fx3u"):
        project.attach_serial("q:1", FakeEndpoint())
    with pytest.raises(TypeError, match=r"needs a send\(\) method"):
        project.attach_serial("fx3:1", object())


def test_serial_log_of_a_channel_the_cpu_lacks_names_the_ones_it_has():
    project = load_st("PROGRAM P\nEND_PROGRAM\n")
    assert project.serial_channels() == ["fx3:1", "fx3:2", "adp:1"]
    assert project.serial_log("fx3:2") == []           # a channel nothing sent on yet
    with pytest.raises(ValueError) as err:
        project.serial_log("nope")
    assert str(err.value) == "unknown serial channel 'nope'; the fx3u CPU has fx3:1, fx3:2, adp:1"
    with pytest.raises(ValueError, match="channel q:1 does not exist on the fx3u CPU; the fx3u CPU has fx3:1"):
        project.serial_log("q:1")
    q = load_st("PROGRAM P\nEND_PROGRAM\n", cpu="q")  # no ADPRW on a Q CPU
    assert q.serial_channels() == ["q:1", "q:2"]
    with pytest.raises(ValueError, match="channel adp:1 does not exist on the q CPU; the q CPU has q:1, q:2"):
        q.attach_serial("adp:1", FakeEndpoint())
    fx5 = load_st("PROGRAM P\nEND_PROGRAM\n", target="gxworks3")
    assert fx5.serial_channels() == ["fx5:1", "fx5:2", "adp:1"]


def test_a_second_modbus_master_channel_is_refused_not_left_silent():
    """ADPRW drives adp:1 only: a robot attached to adp:2 would never hear a frame."""
    project = load_st("PROGRAM P\nEND_PROGRAM\n")
    with pytest.raises(ValueError) as err:
        project.attach_serial("adp:2", FakeEndpoint())
    assert str(err.value) == ("channel adp:2 is not simulated: the simulated ADPRW is the MODBUS master on adp:1 "
                              "only (docs/instructions.md, ADPRW); the fx3u CPU has fx3:1, fx3:2, adp:1")


def test_configure_c24_needs_a_q_cpu_and_a_channel_and_unit_the_module_has():
    with pytest.raises(ValueError) as err:
        load_st("PROGRAM P\nEND_PROGRAM\n").configure_c24(0, 1, byte_units=True)
    assert str(err.value) == ("the QJ71C24N is a Q-series module and this project's CPU is fx3u: configure_c24 "
                              "needs a Q CPU (verifier.load(..., cpu='q'))")
    q = load_st("PROGRAM P\nEND_PROGRAM\n", cpu="q")
    with pytest.raises(ValueError, match="the QJ71C24N has channels 1 and 2; got channel=3"):
        q.configure_c24(0, 3, byte_units=True)
    with pytest.raises(ValueError, match=r"un is the module's start I/O number without its last digit, "
                                         r"0..1FFH \(0 for X/Y000, 2 for X/Y020\); got un=-1"):
        q.configure_c24(-1, 1)
    q.configure_c24(2, 2, receive_count=8)
    assert q.c24_buffer(2)[0x144] == 8


def test_api_misuse_names_what_exists():
    project = load_st("FUNCTION F : INT\nVAR_INPUT a : INT; END_VAR\nF := a;\nEND_FUNCTION\n"
                      "FUNCTION_BLOCK FB\nEND_FUNCTION_BLOCK\n")
    with pytest.raises(KeyError, match="loaded: F, FB"):
        project.instance("NOPE")
    with pytest.raises(TypeError, match="use project.call"):
        project.instance("F")
    with pytest.raises(TypeError, match="use project.instance"):
        project.call("FB")
    with pytest.raises(TypeError, match="takes 1 input"):
        project.call("F", 1, 2)
    with pytest.raises(ValueError, match="F.a is INT"):
        project.call("F", 1.5)


ADD3 = ("FUNCTION Add3 : INT\nVAR_INPUT a : INT; b : INT; c : INT; END_VAR\nAdd3 := a + b + c;\nEND_FUNCTION\n"
        "PROGRAM P\nVAR x : INT; END_VAR\nx := {call};\nEND_PROGRAM\n")


@pytest.mark.parametrize("call, message", [
    ("Add3(1, 2)", "t.st:7:6: error: Add3 takes 3 argument(s) (a, b, c), 2 given: input c missing; "
                   "GX Works needs every input of a function"),
    ("Add3(a := 1)", "t.st:7:6: error: Add3 is called without inputs b, c; GX Works needs every input of a "
                     "function: add b := ..., c := ..."),
])
def test_a_function_call_without_an_input_does_not_load(call, message):
    with pytest.raises(LoadError) as err:
        load_st(ADD3.format(call=call))
    assert message in str(err.value)


def test_the_simulator_never_runs_a_function_call_without_an_input(monkeypatch):
    import verifier.sim.project

    monkeypatch.setattr(verifier.sim.project, "_run_checker", lambda files, target, platform=None: [])  # the checker would stop it
    with pytest.raises(LoadError) as err:
        load_st(ADD3.format(call="Add3(a := 1, c := 3)"))
    assert "t.st:7:6: error: Add3 is called without input b; GX Works needs every input of a function" \
        in str(err.value)


def test_project_call_without_an_input_says_which_and_the_call():
    project = load_st(ADD3.format(call="Add3(1, 2, 3)"))
    with pytest.raises(TypeError) as err:
        project.call("Add3", 1, c=3)
    assert str(err.value) == ("Add3 is called without input b; GX Works needs every input of a function: "
                              "call('Add3', a, b, c)")
    assert project.call("Add3", 1, 2, c=3) == 6


def test_operand_block_past_an_array_through_a_function_local():
    src = ("FUNCTION F : WORD\nVAR_INPUT n : INT; END_VAR\nVAR b : ARRAY[0..1] OF WORD; c : WORD; END_VAR\n"
           "CRC(TRUE, b[0], n, c);\nF := c;\nEND_FUNCTION\n")
    project = load_st(src)
    assert project.call("F", 4) == project.call("F", 4)
    with pytest.raises(SimulationError) as err:
        project.call("F", 5)
    assert err.value.location == "t.st:4:11"


def test_import_verifier_stays_cheap():
    import subprocess
    import sys

    code = "import verifier, sys; print('verifier.sim' in sys.modules, 'lark' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_the_cpu_profiles_do_not_import_the_compiler():
    # uitamr check lists the CPU profiles as its --platform choices on every run
    import subprocess
    import sys

    code = ("import sys, verifier.sim.cpu, verifier.sim; print('verifier.sim.project' in sys.modules); "
            "verifier.sim.load; print('verifier.sim.project' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True"]


def test_load_reads_files_as_check_does(tmp_path):
    """QA 24: one ST reader (verifier.st.read_source) for check, export and load."""
    from verifier.st.source import read_source

    good = tmp_path / "sjis.st"
    good.write_bytes("PROGRAM P\n(* 搬送ロボット *)\nVAR n : INT; END_VAR\nn := 1;\nEND_PROGRAM\n".encode("cp932"))
    project = verifier.load(str(good))
    assert project.files[0].pous[0].name == "P" and not read_source(good)[1]
    bad = tmp_path / "bad.st"
    bad.write_bytes(b"PROGRAM P\n(* \x80\x80 *)\nEND_PROGRAM\n")
    (expected,) = read_source(bad)[1]
    with pytest.raises(LoadError) as err:
        verifier.load(str(bad))
    assert str(expected) in str(err.value) and "bad.st:2:4" in str(err.value)


FB_T = ("FUNCTION_BLOCK FB_T\nVAR_INPUT i_nVal : INT; i_rVal : REAL; i_aArr : ARRAY[0..3] OF INT; END_VAR\n"
        "END_FUNCTION_BLOCK\nPROGRAM Main\nVAR x : INT; END_VAR\nx := x + 1;\nEND_PROGRAM\n")


@pytest.mark.parametrize("how", [
    {}, {"scans": -1}, {"scans": 1.5}, {"scans": "3"}, {"ms": float("nan")}, {"ms": -5}, {"until_us": 2.5},
])
def test_a_run_that_would_never_end_or_makes_no_sense_is_refused(how):
    """run_programs() with no limit, or scans=-1 / 1.5, looped for ever (a hung test)."""
    project = verifier.sim.load(sources={"t.st": FB_T})
    with pytest.raises(ValueError, match="ms=|scans must|ms must|until_us must"):
        project.run_programs(["Main"], **how)
    with pytest.raises(ValueError):  # Instance.run takes ms and scans (no until_us)
        project.instance("FB_T").run(**{k: v for k, v in how.items() if k != "until_us"})
    project.run_programs(["Main"], scans=2)
    project.run_programs(["Main"], ms=0)
    assert project.program("Main").x == 2


@pytest.mark.parametrize("label, value, message", [
    ("i_nVal", None, "FB_T.i_nVal is INT; give a whole number, got None"),
    ("i_nVal", "12", "FB_T.i_nVal is INT; give a whole number, got '12'"),
    ("i_rVal", "x", "FB_T.i_rVal is REAL; give a finite number, got 'x'"),
    ("i_rVal", float("inf"), "FB_T.i_rVal is REAL; give a finite number, got inf"),
    ("i_aArr", 5, "FB_T.i_aArr is an array of 4; give a list of values, got 5"),
    ("i_aArr", {1: 2}, "FB_T.i_aArr is an array of 4; give a list of values"),
    ("i_aArr", ["a"], "FB_T.i_aArr[0] is INT; give a whole number, got 'a'"),
])
def test_a_label_set_from_python_with_the_wrong_kind_says_which_and_what(label, value, message):
    fb = verifier.sim.load(sources={"t.st": FB_T}).instance("FB_T")
    with pytest.raises(ValueError) as caught:
        setattr(fb, label, value)
    assert str(caught.value).startswith(message)


def test_api_calls_in_the_wrong_shape_say_the_right_shape():
    with pytest.raises(TypeError, match=r"load\(\) takes the files as separate arguments"):
        verifier.sim.load(["a.st"])
    with pytest.raises(TypeError, match="sources maps file names to ST text"):
        verifier.sim.load(sources=["x"])
    project = verifier.sim.load(sources={"t.st": FB_T})
    with pytest.raises(TypeError, match=r"run_programs takes a list of PROGRAM names: run_programs\(\['Main'\]"):
        project.run_programs("Main", scans=1)
    with pytest.raises(KeyError, match="no POU named 'NOPE' and not a device; the POUs are FB_T, Main"):
        project.get("NOPE.x")
    assert project.get("D100.5") is False and project.get("Main.x") == 0


def test_attaching_a_second_line_to_a_channel_is_refused_not_silent():
    """A second attach used to replace the first line: a fixture's line then never heard
    another frame, with no word why. The same line twice is harmless."""
    from verifier.amr import Robot
    from verifier.link import Line
    from verifier.link.converter import Converter, ConverterConfig

    project = load_st("PROGRAM P\nEND_PROGRAM\n")
    first = FakeEndpoint()
    project.attach_serial("fx3:1", first)
    project.attach_serial("fx3:1", first)
    with pytest.raises(ValueError) as err:
        project.attach_serial("fx3:1", FakeEndpoint())
    assert str(err.value) == ("channel fx3:1 is already attached to a FakeEndpoint; a channel has one line: "
                              "load the project again (verifier.load) to attach another")
    project.attach_serial("fx3:2", Line(Robot()))  # the other channel is free
    project.run_programs(["P"], scans=1)

    fx5 = load_st("PROGRAM P\nEND_PROGRAM\n", target="gxworks3")
    peer = Converter(Line(Robot()), ConverterConfig())
    fx5.attach_tcp(peer)
    fx5.attach_tcp(peer)
    with pytest.raises(ValueError) as err:
        fx5.attach_tcp(Converter(Line(Robot()), ConverterConfig()))
    assert str(err.value) == ("the Ethernet port is already attached to a Converter; it has one peer: "
                              "load the project again (verifier.load) to attach another")


@pytest.mark.parametrize("options, place, message", [
    ({"scan_ms": 0}, "scan_ms=0", "the scan time must be at least 0.001 ms"),
    ({"scan_ms": 0.0004}, "scan_ms=0.0004", "the scan time must be at least 0.001 ms"),
    ({"jitter_ms": 10}, "jitter_ms=10, scan_ms=10", "the jitter must be at least 0 and less than the scan time (10 ms)"),
    ({"jitter_ms": -1, "scan_ms": 5}, "jitter_ms=-1, scan_ms=5",
     "the jitter must be at least 0 and less than the scan time (5 ms)"),
])
def test_a_bad_load_option_is_named_with_its_value_not_placed_in_the_sources(options, place, message):
    """These said `<options>:0:0: error: scan time must be positive` under "ST sources have
    errors": no option name, no value, and a place in no file."""
    with pytest.raises(LoadError) as err:
        load_st("PROGRAM P\nEND_PROGRAM\n", **options)
    assert str(err.value).startswith(f"verifier.load was given an option it cannot use:\n"
                                     f"  verifier.load({place}): error: {message}")
    assert "<options>" not in str(err.value) and ":0:0" not in str(err.value)


def test_a_load_error_keeps_its_message_through_pickle():
    """A LoadError was pickled as its message and rebuilt by calling the class with it: the
    message's characters became diagnostics ('?:0:0: error: S', ...), and str() was that; now
    its diagnostics, and the message made from them, come back as they were."""
    import pickle

    with pytest.raises(LoadError) as err:
        verifier.load(sources={"MAIN.st": "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := y;\nEND_PROGRAM\n"})
    again = pickle.loads(pickle.dumps(err.value))
    assert (type(again), str(again), again.diagnostics, again.located()) == (
        LoadError, str(err.value), err.value.diagnostics, err.value.located())
    assert "MAIN.st:5:6: error: undefined label 'y'" in str(again)
