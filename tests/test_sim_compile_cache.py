"""The Python generated for a set of sources is made once per process and shared by every
project that loads them (issue 12: `uitamr verify` runs scenario after scenario on the same
library); each project still has its own labels, devices and run-time location table."""
from __future__ import annotations

import pytest

from verifier.sim.errors import SimulationError
from sim_helpers import load_st

SOURCE = """PROGRAM P
VAR
    nCount : INT;
    aData : ARRAY[0..3] OF INT;
    nIndex : INT := 0;
END_VAR
nCount := nCount + 1;
aData[nIndex] := nCount;
END_PROGRAM
"""


def test_two_projects_share_the_code_not_the_state():
    first, second = load_st(SOURCE), load_st(SOURCE)
    assert first.module.source is second.module.source  # generated once
    assert first.module.namespace is not second.module.namespace
    first.run_programs(["P"], scans=5)
    second.run_programs(["P"], scans=2)
    assert first.program("P").nCount == 5
    assert second.program("P").nCount == 2
    assert first.rt.locations == second.rt.locations and first.rt.locations is not second.rt.locations


def test_a_run_time_error_in_a_later_project_names_the_st_line():
    load_st(SOURCE).run_programs(["P"], scans=1)
    project = load_st(SOURCE)
    project.program("P").nIndex = 7
    with pytest.raises(SimulationError) as caught:
        project.run_programs(["P"], scans=1)
    assert "index 7 is outside aData[0..3]" in str(caught.value)
    assert "t.st:8" in str(caught.value)


def test_other_cpu_other_code():
    fx3 = load_st(SOURCE, target="gxworks2", cpu="fx3u")
    q = load_st(SOURCE, target="gxworks2", cpu="q")
    assert fx3.module.source is not q.module.source  # generated for each CPU
    assert fx3.module.namespace["_A_D"] is not q.module.namespace["_A_D"]
    assert len(fx3.module.namespace["_A_D"]) != len(q.module.namespace["_A_D"])
