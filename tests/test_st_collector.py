"""`uitamr check` holds the cyclic garbage collector off while it reads and checks (its
passes walked every tree and symbol again and freed nothing: a tenth of the time), and
leaves it as it found it."""
import gc
from pathlib import Path

import pytest

from verifier.commands.check import check_findings

PLC = Path(__file__).resolve().parent.parent / "plc"


def _library() -> list[Path]:
    return sorted((PLC / "core").glob("*.st")) + sorted((PLC / "fx3").glob("*.st"))


def test_the_collector_is_held_off_while_the_library_is_read_and_checked(monkeypatch):
    import verifier.st as st

    seen = []

    def watched(function):
        def call(*args, **kwargs):
            seen.append((function.__name__, gc.isenabled()))
            return function(*args, **kwargs)
        return call

    monkeypatch.setattr(st, "parse", watched(st.parse))
    monkeypatch.setattr(st, "check", watched(st.check))
    files, findings = check_findings(_library(), "gxworks2", "fx3u")
    assert len(files) > 20 and not [f for f in findings if f.diagnostic.is_error]
    assert len(seen) == len(files) + 1
    assert seen == [(name, False) for name, _enabled in seen]
    assert gc.isenabled()


@pytest.mark.parametrize("enabled", [True, False])
def test_the_collector_is_left_as_it_was(enabled):
    (gc.enable if enabled else gc.disable)()
    try:
        check_findings(_library()[:3], "gxworks2", "fx3u")
        assert gc.isenabled() is enabled
    finally:
        gc.enable()
