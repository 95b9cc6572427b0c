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

__all__ = ["load", "Project", "Instance", "LoadError", "SimulationError", "SimDiagnostic"]


def __getattr__(name: str):
    # load, Project and Instance come from the compiler's side of the package, imported on
    # first use: what only needs the CPU profiles (verifier.sim.cpu: `uitamr check`'s
    # --platform choices) does not pay for the compiler.
    if name in ("load", "Project", "Instance"):
        from . import project

        return getattr(project, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
