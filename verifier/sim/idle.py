"""Skipping idle scans: a run that waits (a pace timer, a reply time-out, the next input)
jumps over the scans that cannot change anything, in one step.

A scan is a pure function of the state before it and of what it reads from outside: the
virtual clock (timers, clock relays), the I/O models polled at END, and the inputs a
scenario writes.  So when one scan left every piece of state exactly as it found it, the
next scans do the same, until the first instant at which something outside can differ:

- a running TON/TOF/TP reaches PT (its Q changes);
- a clock relay the program (or a watch) reads toggles;
- an I/O model has something to do (a byte arrives, a receive time-out runs out);
- the scenario's next input, or the end of the run.

`IdleScans.after_scan` decides this after every scan, cheaply enough to run on each one:
the expensive comparison (every label of the program tree, the device and buffer cells
the generated code names, every cell an instruction operand has written, the I/O models'
own state) only runs when the I/O models say they are quiet, and two quiet scans in a
row with equal state make an idle one.  The jump moves the clock over the skipped scans
(with jitter, the generator is drawn once per skipped scan, exactly as those scans would
have drawn it), so the next scan that runs starts at the same instant as in a plain run.

What is left out of the comparison, and why that is sound:
- a timer's ET, which changes on every scan while the timer runs.  The run is only
  allowed to skip when no generated code reads ET (checked on the generated source); a
  watched ET makes the runner's samples change on every scan, which is never idle;
- the absolute scan number a port remembers (`last_call_scan`): compared relative to the
  scan count, and moved on with the jump (`skipped`).

Every I/O model takes part through three methods; a model without them keeps the run
scan by scan (safe by default).  RS2, C24, ADPRW and the Ethernet ports have them:
- `idle_deadline(now)`: the first instant `poll` can change anything, never later than
  the truth; None when it may change something at `now` (sending, a completion pulse);
- `idle_state()`: a comparable tuple of everything its instruction calls and `poll`
  change (operands as the memory they name, `refs.operand_key`; scan numbers relative);
- `skipped(scan_count, scans)`: fix what counts scans after a jump.

The first quiet scan.  The state is taken after every quiet scan (no input written, no
watched label changed, every I/O model quiet) and compared with the one before.  The state
of the first quiet scan after a busy one can only be of use if the next scan leaves it
unchanged; on the TCP route it never does (the port FB hands the reply to the engine, and
the engine's one-scan re-arm pulse follows), so that state (about 13 µs of the 30 a scan
costs there) was taken for nothing once per request.  A score kept per run says whether it
was of use lately (one use counts as four wasted ones); when it was not, it is left out
(`_previous` stays None, so the next quiet scan cannot jump: leaving a state out can only
cost a scan, never make a wrong jump), and every eighth is still taken to see whether it
has become of use.  Which states are taken changes which scans run at most, never what
they do (tests/test_idle_skip.py).

The scan a jump lands on.  A jump goes to the first instant something can change (a timer
reaching PT, a byte, a time-out, an input), and the scan there usually does change
something: on the TCP route the engine builds its next request when the pace timer ends,
while no watched label moves and the port is quiet, so that scan counts as quiet and its
state (about 9 µs there) was taken to differ from the next scan's, once a request.  A
second score, kept apart from the first quiet scan's and judged the same way (of use if it
equals the state before the jump or the next quiet scan's), leaves it out when it was of
no use lately: `_previous` is set to None, so the next quiet scan takes its state and the
one after compares, exactly as after a busy scan (at most two scans more, never a
wrong jump); every eighth is still taken.  A jump cut short by the caller's stop (`uitamr verify`
runs a virtual second at a time) is not to a change: the scan there usually leaves the
state as it was and lets the run jump on at once, so its state is always taken.

Not skippable (the run then goes scan by scan, as before): a program that reads a timer's
ET, arrays of arrays, and labels of a type the walk does not know.  `IdleScans.reason`
says which.

The equivalence with a plain scan-by-scan run is tested on every bundled scenario and on
random ones (tests/test_idle_skip.py): same report bytes.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

from .refs import Ref
from .stdfbs import StdFB, TOF, TON, TP

INFINITY = float("inf")
# the first quiet scan's state is left out once it was of no use this many times more
# than it was of use (FIRST_USEFUL counts a use); every FIRST_PROBE_EVERY-th is still taken
FIRST_SKIP_SCORE = 4
FIRST_USEFUL = 4
FIRST_PROBE_EVERY = 8
# the cells instruction operands wrote are read by a generated function up to this many
OPERAND_CELLS_GENERATED = 64
_CONST_CELL = re.compile(r"\b(_A_[A-Z]+|_U[0-9A-F]+)\[(\d+)\]")
_ANY_USE = re.compile(r"\b(_A_[A-Z]+|_U[0-9A-F]+)\b(?!\[\d+\])")
_OPERAND_CONSTRUCTORS = ("_Ref(", "_BitRef(", "_DwordRef(")
# a read of a timer's ET: `.ET` not followed by an assignment, or the name as an operand
_ET_READ = re.compile(r"\.ET\b(?!\s*=[^=])|['\"]ET['\"]")


@dataclass(frozen=True)
class SourceFacts:
    """What the idle check needs to know of the generated code (worked out once per source)."""
    reads_et: bool
    constant: dict[str, tuple[int, ...]]  # memory holder -> the indexes named as constants
    whole: tuple[str, ...]  # holders reached by an index expression or a helper
    reached: frozenset[str]  # device areas used other than by a constant index


@lru_cache(maxsize=8)
def _source_facts(source: str) -> SourceFacts:
    constant: dict[str, set[int]] = {}
    for holder, index in _CONST_CELL.findall(source):
        constant.setdefault(holder, set()).add(int(index))
    whole: list[str] = []
    reached: set[str] = set()
    for match in _ANY_USE.finditer(source):
        holder = match.group(1)
        if holder.startswith("_A_"):
            reached.add(holder[3:])
        if not source.endswith(_OPERAND_CONSTRUCTORS, 0, match.start()) and holder not in whole:
            whole.append(holder)  # not an instruction operand (whose writes are logged)
    return SourceFacts(bool(_ET_READ.search(source)), {h: tuple(sorted(i)) for h, i in constant.items()},
                       tuple(whole), frozenset(reached))


def _generated(name: str, expression: str, env: dict[str, object], filename: str) -> Callable[[], tuple]:
    """`def name(): return expression`, compiled, with each object of `env` it reads bound as a
    default argument: a local variable of the function, read faster than a global (the
    state is some 300 loads, taken twice per idle stretch). Called with no arguments."""
    defaults = "".join(f"{key}={key}, " for key in env)
    source = f"def {name}({defaults}):\n    return {expression}\n"
    exec(compile(source, filename, "exec"), env)
    return env[name]


class _StateScore:
    """Whether taking one kind of state (a first quiet scan's, a landing scan's: the module
    docstring) has been of use lately: of no use FIRST_SKIP_SCORE times more than of use
    (a use counts FIRST_USEFUL), it is left out, every FIRST_PROBE_EVERY-th still taken."""

    __slots__ = ("score", "skipped", "states_skipped")

    def __init__(self):
        self.score = 0
        self.skipped = 0  # the states this score could have left out
        self.states_skipped = 0  # those it did

    def leave_out(self) -> bool:
        """Whether to leave this state out (not take it)."""
        if self.score < FIRST_SKIP_SCORE:
            return False
        self.skipped += 1
        if self.skipped % FIRST_PROBE_EVERY == 0:
            return False  # a probe: has it become of use?
        self.states_skipped += 1
        return True

    def useful(self) -> None:
        self.score = max(0, self.score - FIRST_USEFUL)

    def wasted(self) -> None:
        self.score = min(FIRST_SKIP_SCORE + 2, self.score + 1)


def _never_idle(now: int) -> None:
    """The idle deadline of an I/O model that cannot tell: it may change something at
    every scan."""
    return None


class IdleScans:
    """Decides after each scan whether the run is idle, and jumps when it is."""

    def __init__(self, project, roots: list, *, read_devices: tuple[str, ...] = (),
                 next_input_us: Callable[[], float] = lambda: INFINITY):
        self.rt = rt = project.rt
        self.next_input_us = next_input_us
        self.busy = False  # set by the caller for a scan it wrote inputs in, or sampled a change
        self.skipped_scans = 0
        self.jumps = 0
        self._previous = None
        # how many quiet scans in a row so far; whether the scan that just ran is one a jump
        # landed on (set by `_jump` when it went to a change, not to the caller's stop)
        self._quiet = 0
        self._landing = False
        # whether to take the state of a first quiet scan (module docstring, "The first quiet
        # scan") and of the scan a jump lands on ("The scan a jump lands on"), and the score
        # of the one taken that is still to be judged
        self._first = _StateScore()
        self._landed = _StateScore()
        self._judging: _StateScore | None = None
        self.states_taken = 0
        self._deadlines: list[Callable[[int], float | None]] = []  # each poller's idle_deadline
        # cells instruction operands have written: compared by value from then on, whoever
        # writes them later (cells list id -> (cells, indexes))
        self._operand_cells: dict[int, tuple[list, set[int]]] = {}
        facts = _source_facts(project.module.source)
        self.reason: str | None = None
        if facts.reads_et:
            self.reason = "the program reads a timer's ET"
        self._holders = self._memory_holders(project)
        self._objects: list[tuple[object, list[str]]] = []
        self._arrays: list[tuple[object, str]] = []
        self._timers: list[StdFB] = []
        self._walk(roots)
        self._labels = self._label_reader()
        self._constant_cells, self._whole = self._device_footprint(facts)
        # the whole state as one generated function (`_state_reader`), made again when a port
        # is made on its first call; it reads the cells operands wrote through `_operands[0]`,
        # made again (`_operand_reader`) when an operand writes a new cell
        self._layout = 0
        self._operands = [lambda: ()]
        self._state = self._state_reader()
        self._clocks = self._relevant_clocks(facts, read_devices)
        if self.reason is None:
            rt.dirty_log = []

    # ---- what the program can change --------------------------------------------------
    @staticmethod
    def _memory_holders(project) -> dict[str, list]:
        rt = project.rt
        holders = {f"_A_{area}": cells for area, cells in rt.dev.areas.items()}
        holders.update({f"_U{module:X}": cells for module, cells in rt.buffers.items()})
        return holders

    def _walk(self, roots: list) -> None:
        """Every object of the program tree, and which of its slots hold state."""
        seen: set[int] = set()
        memory = {id(cells) for cells in self._holders.values()}
        stack = list(roots)
        while stack:
            obj = stack.pop()
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            slots = [s for cls in type(obj).__mro__ for s in getattr(cls, "__slots__", ()) if s != "_rt"]
            if isinstance(obj, (TON, TOF, TP)):
                self._timers.append(obj)
                if self.reason is None:  # ET is not state when nothing reads it (module docstring)
                    slots = [s for s in slots if s != "ET"]
            scalars = []
            for slot in slots:
                value = getattr(obj, slot)
                if isinstance(value, list):
                    if id(value) in memory:
                        continue  # device memory handed to an FB: compared as devices
                    self._arrays.append((obj, slot))
                    for item in value:
                        if isinstance(item, list):
                            self.reason = self.reason or "an array of arrays"
                        elif hasattr(type(item), "__slots__") and not isinstance(item, (str, Ref)):
                            stack.append(item)
                elif isinstance(value, Ref):
                    continue  # an operand handle, fixed at load
                elif isinstance(value, (bool, int, float, str, type(None))):
                    scalars.append(slot)
                elif hasattr(type(value), "__slots__"):
                    scalars.append(slot)  # compared by identity; its own state is walked
                    stack.append(value)
                else:
                    self.reason = self.reason or f"a label of a kind the idle check does not know ({type(value).__name__})"
            if scalars:
                self._objects.append((obj, scalars))

    def _label_parts(self, env: dict[str, object]) -> list[str]:
        """The expressions reading every label slot and copying every array (their objects
        put in `env`)."""
        parts = []
        for k, (obj, slots) in enumerate(self._objects):
            env[f"o{k}"] = obj
            parts += [f"o{k}.{slot}" for slot in slots]
        for k, (obj, slot) in enumerate(self._arrays):
            env[f"a{k}"] = obj
            parts.append(f"a{k}.{slot}[:]")
        return parts

    def _label_reader(self) -> Callable[[], tuple]:
        """One generated function reading every label slot and copying every array (what
        bench/cycle_recurrence.py compares)."""
        env: dict[str, object] = {}
        parts = self._label_parts(env)
        return _generated("labels", "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")", env,
                          "<idle-labels>")

    def _state_reader(self) -> Callable[[], tuple]:
        """The state `after_scan` compares, as one generated function of plain loads: every
        label slot and array (`_label_parts`), the device and buffer cells named with a
        constant index, those operands wrote (`_operand_reader`, one item), the areas
        reached any other way (copied), every I/O model's `idle_state()` and the count of
        diagnostics. It runs twice per idle stretch. Made again when a port is made; its
        first item is the layout's number, so a state taken with another layout never
        equals one taken with this."""
        self._layout += 1
        env: dict[str, object] = {"operands": self._operands}
        parts = [str(self._layout)] + self._label_parts(env)
        for k, (memory, indexes) in enumerate(self._constant_cells):
            env[f"c{k}"] = memory
            parts += [f"c{k}[{index}]" for index in indexes]
        parts.append("operands[0]()")
        for k, memory in enumerate(self._whole):
            env[f"w{k}"] = memory
            parts.append(f"w{k}[:]")
        self._state_pollers = len(self.rt.pollers)
        for k, poller in enumerate(self.rt.pollers):
            env[f"p{k}"] = poller.idle_state
            parts.append(f"p{k}()")
        env["diagnostics"] = self.rt.diagnostics
        parts.append("len(diagnostics)")
        return _generated("state", "(" + ", ".join(parts) + ")", env, "<idle-state>")

    def _operand_reader(self) -> Callable[[], tuple]:
        """The values of the cells operands wrote, in order (cells list by cells list, each
        by index): a generated function of plain loads while they are few, a loop beyond
        OPERAND_CELLS_GENERATED (made again each time a cell is added, so a program filling
        a large area through an operand would compile it once per new cell)."""
        known = [(cells, sorted(indexes)) for cells, indexes in self._operand_cells.values()]
        if sum(len(indexes) for _, indexes in known) > OPERAND_CELLS_GENERATED:
            return lambda: tuple([cells[index] for cells, indexes in known for index in indexes])
        env: dict[str, object] = {}
        parts = []
        for k, (cells, indexes) in enumerate(known):
            env[f"k{k}"] = cells
            parts += [f"k{k}[{index}]" for index in indexes]
        return _generated("cells", "(" + "".join(f"{part}, " for part in parts) + ")", env, "<idle-operand-cells>")

    def _device_footprint(self, facts: "SourceFacts"):
        """The device and buffer cells the generated code names with a constant index, and
        the whole areas it reaches any other way (an index expression). Cells written
        through an instruction operand are logged by the operand (`Runtime.dirty_log`)."""
        cells = [(self._holders[holder], ordered) for holder, ordered in facts.constant.items()]
        whole = [self._holders[holder] for holder in facts.whole if holder in self._holders]
        return cells, whole

    def _relevant_clocks(self, facts: "SourceFacts", read_devices: tuple[str, ...]):
        """The clock relays that can matter: named in the program or read by the caller, or
        in an area the program reaches through an operand or an index."""
        rt = self.rt
        named = {(holder[3:], index) for holder, indexes in facts.constant.items() if holder.startswith("_A_")
                 for index in indexes}
        reached = facts.reached
        for name in read_devices:
            try:
                a = rt.dev.address(name)
            except (KeyError, ValueError):
                continue
            named.update((a.area, a.index + k) for k in range(max(1, (a.digits or 0) * 4)))
        clocks = []
        for cells, index, half_us in rt._clocks:
            area = next(name for name, c in rt.dev.areas.items() if c is cells)
            if (area, index) in named or area in reached:
                clocks.append(("fixed", half_us, None))
        for relay, register, unit_us, _ in rt._settable_clocks:
            if (relay.area, relay.index) in named or relay.area in reached:
                clocks.append(("settable", unit_us, (rt.dev.areas[register.area], register.index)))
        return clocks

    # ---- after every scan ---------------------------------------------------------------
    def after_scan(self, started_us: int, stop_us: int | None) -> None:
        """Called after each scan (the clock already at the next one); `started_us` is when
        the scan that just ran started."""
        if self.reason is not None:
            return
        rt = self.rt
        changed = self._new_operand_cells() if rt.dirty_log else False
        busy, self.busy = self.busy, False
        landing, self._landing = self._landing, False
        if busy or changed or rt.scan_count < 2:
            self._previous, self._quiet = None, 0
            self._judged(useful=False)
            return
        now = rt.now_us
        pollers = rt.pollers
        if len(pollers) != len(self._deadlines):  # a port is made on its first call
            self._deadlines = [getattr(p, "idle_deadline", None) or _never_idle for p in pollers]
        deadline = INFINITY
        for idle_deadline in self._deadlines:
            until = idle_deadline(now)
            if until is None or until <= now:
                self._previous, self._quiet = None, 0
                self._judged(useful=False)
                return
            if until < deadline:
                deadline = until
        deadline = min(deadline, self.next_input_us())
        self._quiet += 1
        # the score of the kind of state this one is, when it is to be judged
        judged = self._first if self._quiet == 1 else self._landed if landing else None
        if judged is not None and judged.leave_out():
            # not taken: with `_previous` None (a first quiet scan's already is) the next
            # quiet scan takes its state
            self._previous = None
            return
        if len(pollers) != self._state_pollers:
            self._state = self._state_reader()
        state = self._state()
        self.states_taken += 1
        same = state == self._previous
        self._judged(useful=same)  # the state before, a first or landing one: was it worth taking?
        if not same:
            self._judging = judged  # of use if the next quiet scan's state equals it
            self._previous = state
            return
        if judged is self._landed:  # equal to the state before the jump: of use at once
            judged.useful()
        deadline = min(deadline, self._timer_deadline_us(), self._clock_deadline_us(started_us))
        to_change = True
        if stop_us is not None and stop_us <= deadline:
            deadline, to_change = stop_us, False  # the caller's stop: nothing need change there
        if now < deadline < INFINITY:
            self._jump(deadline, to_change)

    def _judged(self, useful: bool) -> None:
        """The state still to be judged (`_judging`, a first quiet scan's or a landing one's),
        if any, was worth taking (the next quiet scan's state equals it) or not (that scan
        is not quiet, or its state differs)."""
        if self._judging is None:
            return
        if useful:
            self._judging.useful()
        else:
            self._judging.wasted()
        self._judging = None

    @property
    def first_states_skipped(self) -> int:
        """First quiet scans whose state was left out."""
        return self._first.states_skipped

    @property
    def landing_states_skipped(self) -> int:
        """Scans a jump landed on whose state was left out."""
        return self._landed.states_skipped

    def _new_operand_cells(self) -> bool:
        """Take in the cells instruction operands wrote since the last scan; True when one
        was not compared before (the comparison with the previous scan is then not valid)."""
        log = self.rt.dirty_log
        if not log:
            return False
        known, grew = self._operand_cells, False
        for cells, index in log:
            entry = known.get(id(cells))
            if entry is None:
                entry = known[id(cells)] = (cells, set())
            if index not in entry[1]:
                entry[1].add(index)
                grew = True
        log.clear()
        if grew:
            self._operands[0] = self._operand_reader()
        return grew

    def _timer_deadline_us(self) -> float:
        """The first instant a running timer's Q can change (timers read whole ticks)."""
        rt = self.rt
        first_ms = INFINITY
        for t in self._timers:
            if t._start is None:
                continue
            running = (t.IN and not t.Q) if isinstance(t, TON) else (not t.IN and t.Q) if isinstance(t, TOF) else t.Q
            if running:
                first_ms = min(first_ms, t._start + t.PT)
        if first_ms == INFINITY:
            return INFINITY
        resolution = rt.timer_resolution_ms
        return -(-first_ms // resolution) * resolution * 1000

    def _clock_deadline_us(self, started_us: int) -> float:
        """The first toggle of a relevant clock relay after the idle scan read it."""
        first = INFINITY
        for kind, unit_us, register in self._clocks:
            if kind == "fixed":
                half = unit_us
            else:
                cells, index = register
                if cells[index] <= 0:
                    continue  # out of range: the relay keeps its state (Runtime)
                half = cells[index] * unit_us
            first = min(first, (started_us // half + 1) * half)
        return first

    def _jump(self, deadline: float, to_change: bool = False) -> None:
        """Move on over every scan that would start before `deadline`, as those scans would.
        `to_change`: `deadline` is the first instant something can change (not the
        caller's stop), so the scan landed on is judged as a landing one."""
        rt = self.rt
        count = rt.scan_count
        now, step, jitter = rt.now_us, rt.scan_us, rt.jitter_us
        scans = 0
        if jitter:
            draw = rt.rng.randint
            while now < deadline:
                now += step + draw(-jitter, jitter)
                scans += 1
        else:
            scans = max(0, int(-(-(deadline - now) // step)))
            now += scans * step
        if scans == 0:
            return
        rt.scan_count = count + scans
        rt.advance_to(now)
        for poller in rt.pollers:
            poller.skipped(count, scans)
        self.skipped_scans += scans
        self.jumps += 1
        self._landing = to_change
