"""The Python API of docs/testing-st.md as an integrator uses it on their own ST: labels
of every class read and written by name, and a user's mistake in a call answered with
what to fix rather than an error from inside the toolkit."""
from __future__ import annotations

import verifier

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
