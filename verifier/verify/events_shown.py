"""Thinning a long run's events to those a report can show, while the run goes.

The HTML page draws at most EVENTS_AT_MOST of a run's line and robot events:
the scenario's faults first, then the others, each in the run's order (time, then the
line's own events before the robot's, then the converter's). A run whose only report of
events is the page (`Keep.events_at_most`) need not hold the rest: in each list of events,
an event with `at_most` events of its class (fault or not) before it, in that list, can
never be among those the page draws, whatever comes later, since the lists are merged in
time order. `keep_first` drops such events (only those up to `until_us`, which the run has
passed) and says how many it dropped, for the page's "N events not shown".
"""
from __future__ import annotations

from typing import Callable, Sequence

EVENTS_AT_MOST = 2000  # line and robot events the HTML page draws of a run (the scenario's faults first)


#: the events of the faults a scenario scripts: the robot's [[faults]], and the converter's
#: `drops` (the TCP route's dropped connection strikes as one event, like a robot fault)
SCRIPTED = frozenset({"robot.fault", "converter.dropped"})


def event_class(kind: str) -> str:
    """Faults the scenario injected, trouble on the line, or the robot's ordinary doings
    (`kind` as a run's result has it: the robot's own kinds prefixed with ``robot.``)."""
    if kind in SCRIPTED:
        return "fault"
    if not kind.startswith("robot."):
        return "line"
    return "info"


def keep_first(events: list, at_most: int, until_us: int, is_fault: Callable[[object], bool]) -> int:
    """Remove from `events` (in place) each event at or before `until_us` that has
    `at_most` events of its own class before it in time order (equal times: list order).
    Returns how many were removed."""
    order = sorted(range(len(events)), key=lambda k: events[k].t_us)
    seen = {False: 0, True: 0}
    dropped: set[int] = set()
    for k in order:
        event = events[k]
        if event.t_us > until_us:
            break  # later ones: not yet known to be past the first `at_most`
        fault = is_fault(event)
        seen[fault] += 1
        if seen[fault] > at_most:
            dropped.add(k)
    if dropped:
        events[:] = [e for k, e in enumerate(events) if k not in dropped]
    return len(dropped)


def keep_first_of_each(lists: Sequence[tuple[list, Callable[[object], bool]]], at_most: int, until_us: int) -> int:
    """`keep_first` on each (events, is_fault) pair; the number dropped in all."""
    return sum(keep_first(events, at_most, until_us, is_fault) for events, is_fault in lists)


def thin_line_events(line, at_most: int, until_us: int) -> int:
    """`keep_first` on a line's own events and its robot's (verifier.link.Line), a fault
    being what the page calls one (`event_class`); the number dropped."""
    own, robots = line.event_lists()
    return keep_first_of_each([(own, lambda e: event_class(e.kind) == "fault"),
                               (robots, lambda e: event_class(f"robot.{e.kind}") == "fault")], at_most, until_us)
