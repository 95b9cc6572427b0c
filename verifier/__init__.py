"""UITAMR PLC toolkit verifier: parse GX Works ST, simulate it, check its robot traffic."""

__version__ = "0.1.0"

# `verifier.bundled.plc_dir()` names the library in a user's own tests (docs/testing-st.md)
# after a plain `import verifier`; it only builds a path, so the import stays cheap.
from verifier import bundled  # noqa: E402,F401


def load(*paths, **options):
    """Load GX Works ST files into a simulated CPU (see docs/testing-st.md).

    `verifier.load("FB_X.st", target="gxworks2", scan_ms=10)` parses and checks the files
    and compiles them; the simulator is imported only when this is called, so `import
    verifier` stays cheap."""
    from verifier.sim import load as _load

    return _load(*paths, **options)
