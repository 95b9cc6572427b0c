"""`uitamr verify SOURCES --matrix`: the user's program under every bundled robot/fault set.

A bundled scenario is written for a bundled example program: its operator inputs press
that program's buttons (X20 starts the Q example's cycle), its expectations and watched
labels name that program's labels, its [initial] device values are that program's, and its
response signal is that program's error output. None of that means anything for another
program, so against user sources a bundled scenario keeps only what is about the robot,
the line and the serial module: the platform, the converter of the TCP route (only for
programs that use it: `platform.uses_tcp_route`; listening at whatever address the program
opens, as the example's converter address is the example's), the robot, the faults and their timing, the
protocol settings, the run and scan times, the QJ71C24N settings ([[c24]], which every
installation must make in GX Works — docs/import-gxworks2.md; made for the module the user's
program drives and the channel of the run, not for the example's slot and channel) and every rule. It expects what every program must do — send the
power-on stop and have it answered within 5 s — and UITAMR-RESPONSE-HANDLING watches
`o_bErr` when the program has it. Each result says what was left out.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from .conditions import parse_condition
from .scenario import DEFAULT_RESPONSE_SIGNAL, Scenario, scenario_power_on_stop


def for_user_sources(scenario: Scenario, sources: tuple[Path, ...], program: str | None,
                     channel: str | None) -> Scenario:
    """`scenario` (a bundled one) re-aimed at the user's sources, with a note on what it lost."""
    left_out = []
    if scenario.inputs:
        left_out.append(f"{len(scenario.inputs)} operator input(s)")
    if scenario.expectations:
        left_out.append(f"{len(scenario.expectations)} expectation(s)")
    if scenario.watch:
        left_out.append(f"{len(scenario.watch)} watched label(s)")
    if scenario.initial:
        left_out.append("its [initial] device values")
    # the example's own error output is the user's too when the user's program is that
    # example (--matrix on the bundled library): without it the persistent faults failed
    # UITAMR-RESPONSE-HANDLING for want of a signal
    same_program = (program is not None and scenario.program is not None
                    and program.upper() == scenario.program.upper())
    keep_signal = scenario.response_signal_given and same_program
    if scenario.response_signal_given and not keep_signal:
        left_out.append(f"its response signal ({scenario.options.response_signal})")
    converter = scenario.converter
    if converter is not None and not converter.any_address:
        # the example's CONVERTER_IP / CONVERTER_PORT are the example's: the converter
        # listens wherever the user's program opens
        left_out.append(f"its converter address ({converter.ip}:{converter.port})")
        converter = replace(converter, any_address=True)
    # the example's C24 sits at U0 and uses CH1; the user's may sit anywhere and use CH2:
    # the settings are the installation's, so they follow the module the program drives
    run_channel = int(channel.split(":")[1]) if channel and channel.startswith("q:") else None
    c24 = tuple(replace(setting, unit=None, channel=run_channel or setting.channel) for setting in scenario.c24)
    example = scenario.program or "the bundled example"
    note = (
        f"bundled scenario run against your sources: robot, faults, timing"
        f"{', C24 settings (on the module your program drives)' if scenario.c24 else ''} "
        f"and every rule applied, "
        f"plus the answered power-on stop; not applied, being written for {example}: "
        f"{', '.join(left_out) or 'nothing'}"
    )
    return replace(
        scenario.with_overrides(sources=sources),
        program=program,
        channel=None if scenario.converter is not None else channel,
        converter=converter,
        inputs=(),
        # a converter that refuses connections at first: the stop can only be answered after
        expectations=(scenario_power_on_stop(scenario),),
        watch=(),
        initial=(),
        c24=c24,
        options=scenario.options if keep_signal else replace(scenario.options,
                                                             response_signal=parse_condition(DEFAULT_RESPONSE_SIGNAL)),
        response_signal_given=keep_signal,
        # what is applied keeps its line (a fault that tested nothing is noted there); the rest
        # is not the run's
        key_lines={key: place for key, place in scenario.key_lines.items() if key.startswith("faults[")},
        notes=scenario.notes + (note,),
        for_sources=True,
    )


def without_repeats(scenarios: list[Scenario]) -> list[Scenario]:
    """Scenarios that became the same run (same robot, faults, protocol, rules and times)
    once their example-specific parts are gone run once; the kept one names the others."""
    kept: dict[str, Scenario] = {}
    for scenario in scenarios:
        identity = repr((scenario.platform, scenario.channel, scenario.converter, scenario.settings, scenario.robot,
                         scenario.faults,
                         scenario.duration_us, scenario.scan_us, scenario.scan_jitter_us, scenario.seed,
                         scenario.options))  # repr: some of these hold dicts
        if identity in kept:
            first = kept[identity]
            kept[identity] = replace(first, notes=first.notes + (f"also stands for {scenario.name!r} (the same run)",))
        else:
            kept[identity] = scenario
    return list(kept.values())
