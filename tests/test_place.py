"""verifier.place.Place: the one shape of a place in a file that messages, JUnit test cases
and the exit-2 paths are made from, and that crosses --jobs' worker processes."""
from __future__ import annotations

import pickle
import subprocess
import sys

import pytest

from verifier.place import Place


def test_a_place_prints_as_file_line_col_and_without_a_file_as_line_col():
    assert str(Place("plc/MAIN.st", 5, 6)) == "plc/MAIN.st:5:6"
    assert str(Place(None, 5, 6)) == "5:6"
    assert Place(None, 5, 6).in_file("s.toml") == Place("s.toml", 5, 6)


def test_a_place_crosses_processes_as_it_is():
    place = Place("s.toml", 2, 3)
    assert pickle.loads(pickle.dumps(place)) == place


def test_the_place_module_imports_no_other_module_of_the_toolkit():
    """The command line's exit-2 paths import it: it must stay quick to import."""
    code = "import sys, verifier.place; print(sorted(m for m in sys.modules if m.startswith('verifier')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["['verifier',", "'verifier.bundled',", "'verifier.place']"], out


def test_every_error_of_unusable_input_holds_its_place_as_a_place(tmp_path):
    """A scenario's key, a capture's bad byte, the first error of ST that does not load and
    the UnusableInput the runner makes of a scenario's key: one shape, `place`, with the
    file its message names, printed as the message prints it."""
    import verifier
    from verifier.monitor.capture import CaptureError, read_capture
    from verifier.sim.errors import LoadError
    from verifier.verify.result import Mistake, mistakes_of
    from verifier.verify.scenario import ScenarioError, load_scenario

    (tmp_path / "s.toml").write_text('duration = "1s"\nscan = "x"\n', encoding="utf-8")
    (tmp_path / "c.txt").write_text("0.000 01 06\n0.100 01 0G\n", encoding="utf-8")
    with pytest.raises(ScenarioError) as scenario:
        load_scenario(tmp_path / "s.toml")
    with pytest.raises(CaptureError) as capture:
        read_capture(tmp_path / "c.txt")
    scenario, capture = scenario.value, capture.value
    assert scenario.place == Place(str(tmp_path / "s.toml"), 2, 8)
    assert capture.place == Place(str(tmp_path / "c.txt"), 2, 10)
    for error in (scenario, capture):
        assert str(error).startswith(f"{error.place}: ")
        assert mistakes_of(error) == [Mistake(str(error), error.place)]
    with pytest.raises(LoadError) as loaded:
        verifier.load(sources={"MAIN.st": "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := y;\nEND_PROGRAM\n"})
    assert loaded.value.place() == Place("MAIN.st", 5, 6)
    assert loaded.value.located() == [(Place("MAIN.st", 5, 6), "MAIN.st:5:6: error: undefined label 'y'; declare it in a VAR block")]
