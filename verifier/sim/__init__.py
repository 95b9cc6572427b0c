"""Scan-cycle simulator for GX Works structured text.

    import verifier
    project = verifier.load("FB_X.st", target="gxworks2", scan_ms=10)
    fb = project.instance("FB_X"); fb.i_bExecute = True; fb.run(ms=3000)

The checked AST is compiled to Python source (`compiler`, `codegen`), run scan by scan on
a virtual clock (`runtime`) with MELSEC device memory (`devices`), standard FBs
(`stdfbs`), standard functions (`stdfuncs`) and instruction models (`instructions`) whose
serial output is a timed byte stream (`serial`).  docs/testing-st.md is the user guide.
"""
from .errors import LoadError, SimDiagnostic, SimulationError
from .project import Instance, Project, load

__all__ = ["load", "Project", "Instance", "LoadError", "SimulationError", "SimDiagnostic"]
