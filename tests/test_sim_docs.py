"""The examples of docs/testing-st.md run as written (ST blocks become files, Python
blocks run in order, from a folder that also holds the repository's plc/)."""
from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from doc_helpers import code_blocks
import procs

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "testing-st.md"


def blocks(kind: str) -> list[str]:
    return code_blocks(DOC.read_text(encoding="utf-8"), kind)


def test_quick_start_runs(tmp_path, monkeypatch):
    st_block = blocks("iecst")[0]
    name = re.search(r"FUNCTION_BLOCK (\w+)", st_block).group(1)
    (tmp_path / f"{name}.st").write_text(st_block, encoding="utf-8")
    os.symlink(ROOT / "plc", tmp_path / "plc")
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks("python")[0], str(DOC), "exec"), {})



def test_quick_start_runs_outside_the_toolkit_with_the_library_named_by_plc_dir(tmp_path, monkeypatch):
    # testing-st.md: in your own project, name the library where it is (no plc/ beside it)
    st_block = blocks("iecst")[0]
    name = re.search(r"FUNCTION_BLOCK (\w+)", st_block).group(1)
    (tmp_path / f"{name}.st").write_text(st_block, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    doc_path = '"plc/core/UITAMR_CRC16.st"'
    documented = 'verifier.bundled.plc_dir() / "core" / "UITAMR_CRC16.st"'
    assert documented in DOC.read_text(encoding="utf-8")
    code = blocks("python")[0]
    assert doc_path in code
    # in a fresh interpreter, as a user's script runs: the block's own `import verifier` is
    # all it imports, so `verifier.bundled` must come with it (a pytest process has it already)
    script = tmp_path / "quick_start.py"
    script.write_text(code.replace(doc_path, documented), encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = procs.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                     capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_serial_example_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    code = blocks("python")[1].replace("ms=60_000", "ms=3_000")
    code = code.replace("for frame in line.trace:\n    print(", "for frame in line.trace[:2]:\n    (")
    namespace: dict = {}
    exec(compile(code, str(DOC), "exec"), namespace)
    assert namespace["project"].get("UITAMR_ExampleFx3.fbEngine.o_bInitDone") is True


pytest_plugins = ["pytester"]


def test_pytest_example_passes(pytester):
    st_block = blocks("iecst")[0]
    pytester.makefile(".st", FB_Delay=st_block)
    os.symlink(ROOT / "plc", pytester.path / "plc")
    pytester.makepyfile(test_doc_example=blocks("python")[2])
    result = pytester.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2)


def test_restart_puts_the_instances_the_test_holds_back_to_their_initial_values():
    """testing-st.md, Time: `project.restart()` powers the CPU off and on, labels back to
    their initial values. The FB instance and the PROGRAM a test got before the restart
    used to keep their old values (and the held PROGRAM ran apart from the CPU's)."""
    import verifier

    delay = blocks("iecst")[0]
    main = "PROGRAM MAIN\nVAR\n    n : INT;\nEND_VAR\nn := n + 1;\nEND_PROGRAM\n"
    project = verifier.load(sources={"FB_Delay.st": delay, "MAIN.st": main})
    fb = project.instance("FB_Delay")
    program = project.program("MAIN")
    fb.i_bExecute = True
    fb.run(ms=3000).scan()
    project.run_programs(["MAIN"], scans=5)
    assert fb.o_bDone and program.n == 5
    project.restart(off_ms=100)
    assert (fb.i_bExecute, fb.o_bDone, fb.fbTimer.ET, program.n) == (False, False, 0, 0)
    project.run_programs(["MAIN"], scans=2)
    assert program.n == project.get("MAIN.n") == 2 and project.program("MAIN") is program
    fb.i_bExecute = True
    fb.scan()
    assert not fb.o_bDone and fb.fbTimer.ET == 0  # a new timer: it starts counting now


def test_restart_puts_a_held_globals_view_back_and_keeps_it_the_cpus():
    """`g = project.globals` taken before `project.restart()`: after it, `g` shows the
    initial values and what a test writes through it is what the programs read (it used to
    keep the old values and write to memory no program read any more)."""
    import verifier

    text = ("VAR_GLOBAL g_nStep : INT; END_VAR\n"
            "PROGRAM MAIN\nVAR\n    n : INT;\nEND_VAR\nn := n + g_nStep;\nEND_PROGRAM\n")
    project = verifier.load(sources={"MAIN.st": text})
    g = project.globals
    g.g_nStep = 2
    project.run_programs(["MAIN"], scans=3)
    assert project.get("MAIN.n") == 6
    project.restart()
    assert g.g_nStep == 0 == project.get("GLOBAL.g_nStep")
    g.g_nStep = 5
    project.run_programs(["MAIN"], scans=2)
    assert project.get("MAIN.n") == 10 and project.get("GLOBAL.g_nStep") == 5


def test_restart_finds_the_memory_again_for_views_taken_from_other_views():
    """An FB, an array, a structure and an element of an array of FBs taken out of a PROGRAM
    (`t = main.fbTimer`) before `project.restart()`: after it they show the initial values
    and what a test writes through them is what the program reads (they used to hold the
    memory of the CPU before the restart)."""
    import verifier

    text = """
TYPE Pair :
STRUCT
    wA : INT;
    wB : INT;
END_STRUCT
END_TYPE
FUNCTION_BLOCK Counter
VAR_INPUT
    i_wStep : INT;
END_VAR
VAR_OUTPUT
    o_wCount : INT;
END_VAR
o_wCount := o_wCount + i_wStep;
END_FUNCTION_BLOCK
PROGRAM MAIN
VAR
    fbOne : Counter;
    aFbs : ARRAY[1..2] OF Counter;
    aWords : ARRAY[0..3] OF INT;
    stPair : Pair;
    wStep : INT := 1;
END_VAR
fbOne(i_wStep := wStep);
aFbs[2](i_wStep := aWords[1]);
stPair.wB := stPair.wA + fbOne.o_wCount;
END_PROGRAM
"""
    project = verifier.load(sources={"MAIN.st": text}, target="gxworks3", cpu="fx5u")
    main = project.program("MAIN")
    one, fbs, words, pair = main.fbOne, main.aFbs, main.aWords, main.stPair
    second = fbs[2]
    words[1] = 7
    pair.wA = 100
    project.run_programs(["MAIN"], scans=3)
    assert (one.o_wCount, second.o_wCount, pair.wB) == (3, 21, 103)
    project.restart()
    assert (one.o_wCount, second.o_wCount, list(words), pair.wA, pair.wB) == (0, 0, [0, 0, 0, 0], 0, 0)
    assert [fb.o_wCount for fb in fbs] == [0, 0]
    words[1] = 2
    pair.wA = 10
    project.run_programs(["MAIN"], scans=2)
    assert (one.o_wCount, second.o_wCount, pair.wB) == (2, 4, 12)
    assert (project.get("MAIN.fbOne.o_wCount"), main.aFbs[2].o_wCount) == (2, 4)


def test_the_st_state_shown_in_the_doc_is_what_a_failing_test_prints(pytester):
    """The ST state block of the pytest section, for the doc's `test_delay` failing right
    after `fb.run(ms=1000)`: a TON shows IN/PT/Q/ET (it used to show `'<instance>'`, and
    `repr(fb.fbTimer)` was `<FB_Delay.fbTimer: >`, hiding the ET a timer test needs)."""
    st_block = blocks("iecst")[0]
    pytester.makefile(".st", FB_Delay=st_block)
    test = blocks("python")[2].split("def test_delay")[1]
    test = "def test_delay" + test.replace("    fb.scan()\n", "")
    assert "fb.run(ms=3000)" in test
    pytester.makepyfile(test_doc_example=test.replace("fb.run(ms=3000)", "fb.run(ms=1000)"))
    result = pytester.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(failed=1)
    shown = re.search(r"```\n(-+ ST state 1 -+\n.*?)```", DOC.read_text(encoding="utf-8"), re.S).group(1)
    out = result.stdout.str()
    for line in shown.splitlines()[1:]:
        assert line in out, line
