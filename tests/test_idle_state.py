"""The idle check's state as one generated function (verifier.sim.idle, `_state_reader`):
at every state it takes, on the bundled scenarios of every kind of port, it holds exactly
what the state was made of before it was one function (every label slot and array, the
named and operand-written cells, the areas reached whole, each I/O model's `idle_state()`,
the count of diagnostics), read at that moment from the ports and cells there are then;
and two states taken with different layouts never compare equal.

tests/test_idle_skip.py runs the same scenarios skipping and scan by scan and compares the
reports byte for byte; this file checks the state itself, so that a stale layout (a port
made, or a cell written through an operand, after the function was generated) cannot hide
behind a run whose result happens to be the same.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from verifier.sim import idle as idle_module
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent
# one of each kind of I/O model: RS2, ADPRW, QJ71C24N, the FX5U socket and the QJ71E71 fixed buffers
KINDS = ["fx3u-healthy", "fx3u-adprw-healthy", "q-healthy", "fx5u-tcp-split", "q-tcp-no-reply"]


def _parts(idle) -> tuple:
    """The state as its parts are: what `_state` held before it was one generated function."""
    rt = idle.rt
    parts = list(idle._labels())
    for cells, indexes in idle._constant_cells:
        parts += [cells[index] for index in indexes]
    parts.append(tuple(cells[index] for cells, indexes in idle._operand_cells.values() for index in sorted(indexes)))
    parts += [cells[:] for cells in idle._whole]
    parts += [poller.idle_state() for poller in rt.pollers]
    parts.append(len(rt.diagnostics))
    return tuple(parts)


@pytest.mark.parametrize("name", KINDS)
def test_every_state_taken_holds_exactly_its_parts(name, monkeypatch):
    _check_every_state(name, monkeypatch)


def test_many_operand_cells_are_read_by_a_loop_with_the_same_values(monkeypatch):
    """Beyond OPERAND_CELLS_GENERATED the operand cells are read by a loop (no function
    compiled per new cell): the same values, in the same order."""
    monkeypatch.setattr(idle_module, "OPERAND_CELLS_GENERATED", 0)
    assert _check_every_state("q-tcp-no-reply", monkeypatch) > 20


def _check_every_state(name, monkeypatch) -> int:
    """Run a bundled scenario checking every state taken; how many held operand cells."""
    taken = []
    with_operands = []
    original = idle_module.IdleScans._state_reader

    def checked(self):
        generated = original(self)

        def state():
            value = generated()
            assert value[0] == self._layout
            assert value[1:] == _parts(self)
            taken.append(value)
            if self._operand_cells:
                with_operands.append(value)
            return value

        return state

    monkeypatch.setattr(idle_module.IdleScans, "_state_reader", checked)
    result = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml"))
    assert result.trace or result.frame_counts
    assert len(taken) > 20, "hardly any state taken: the check proves nothing"
    return len(with_operands)


def test_states_of_different_layouts_never_compare_equal():
    scenario = load_scenario(ROOT / "plc" / "scenarios" / "fx3u-healthy.toml")
    made = []
    original = idle_module.IdleScans.__init__

    def recording(self, *args, **kwargs):
        original(self, *args, **kwargs)
        made.append(self)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(idle_module.IdleScans, "__init__", recording)
        run_scenario(scenario)
    idle = made[-1]
    before = idle._state()
    assert idle._state() == before  # nothing ran between: the same state
    idle._state = idle._state_reader()  # the same cells and ports, a new layout
    assert idle._state()[1:] == before[1:]
    assert idle._state() != before
