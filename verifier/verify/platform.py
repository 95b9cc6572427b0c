"""Which PLC platform a set of ST sources is written for, when the user does not say.

The sources are loaded for every platform's CPU (its engineering tool's dialect, its
devices and its instructions). Serial programs use instructions and special devices that
exist on one CPU only — RS2 with M8402/D8403 (FX3U), RS2 with SM/SD (FX5U), G_OUTPUT /
G_INPUT (Q with QJ71C24N) — so exactly one load succeeds. A program that uses nothing
platform-specific loads everywhere and the platform cannot be told. The FX3G is never told
from the sources (scenario.TOLD_PLATFORMS): what loads on it loads on the FX3U too.
"""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import TYPE_CHECKING

from .result import Mistake, UnusableInput
from .scenario import PLATFORMS, TOLD_PLATFORMS, bundled_platform

if TYPE_CHECKING:
    from verifier.sim.errors import LoadError


class PlatformUnknown(UnusableInput):
    """The sources load on several platforms (or none); the message says which and why."""


def platforms_that_load(sources: tuple[Path, ...]) -> tuple[list[str], dict[str, "LoadError"]]:
    """(platforms whose CPU loads the sources, {platform: its LoadError} for the others),
    of the platforms sources are told apart by (TOLD_PLATFORMS: not the FX3G)."""
    import verifier
    from verifier.sim.errors import LoadError

    fits, errors = [], {}
    for platform in TOLD_PLATFORMS:
        try:
            verifier.load(*[str(p) for p in sources], target=PLATFORMS[platform][0], cpu=platform)
        except LoadError as exc:
            errors[platform] = exc.shown_from(os.getcwd())  # the paths as the reports show them
            continue
        fits.append(platform)
    return fits, errors


def _first_error(exc: "LoadError") -> str:
    """A LoadError's first diagnostic, whatever its severity (the one the platforms' loads
    are compared by: not `LoadError.located`'s first, which passes over warnings), as its
    line of the message shows it; the message when it holds none."""
    lines = exc.lines()
    return lines[0] if lines else str(exc)


def infer_platform(sources: tuple[Path, ...]) -> str:
    """The one platform the sources are written for; PlatformUnknown otherwise."""
    fits, errors = platforms_that_load(sources)
    if len(fits) == 1:
        return fits[0]
    if not fits:
        first = {platform: _first_error(exc) for platform, exc in errors.items()}
        if len(set(first.values())) == 1:  # the same mistake everywhere: an ST error
            exc = next(iter(errors.values()))
            # every error of the sources, as a run without --matrix lists them; one JUnit test case each
            located = exc.located()
            if not located:
                raise UnusableInput(f"the sources do not load: {_first_error(exc)}", at=exc.place())
            each = [Mistake(f"the sources do not load: {text}", place) for place, text in located]
            raise UnusableInput("the sources do not load: " + "\n  ".join(text for _, text in located),
                                at=located[0][0], mistakes=each)
        reasons = "; ".join(f"{platform}: {error}" for platform, error in first.items())
        raise UnusableInput(f"the sources load on no platform ({reasons})")
    # the platforms named only, never told (an FX3G), beside the one whose scenarios they run
    say = [named for platform in fits for named in PLATFORMS if bundled_platform(named) == platform]
    raise PlatformUnknown(
        f"cannot tell the platform from the sources: they load on {', '.join(fits)} alike (they use no "
        "device or instruction of one platform only); say --platform " + "|".join(say)
    )


_COMMENT = re.compile(r"\(\*.*?\*\)|//[^\n]*", re.DOTALL)


def uses_tcp_route(sources: tuple[Path, ...], program: str | None = None) -> bool:
    """Does the PROGRAM that runs (`program`, else every PROGRAM in the sources) reach an
    Ethernet instruction (FX5U socket, QJ71E71 fixed buffer), through the FB instances it
    declares? Then it reaches the robot over TCP, through a converter (bundled `*-tcp-*`
    scenarios). A library folder holding serial and Ethernet port FBs side by side does
    not make a serial program a TCP one."""
    from verifier import st
    from verifier.sim.instructions import ETHERNET
    from verifier.st.ast import ArrayType, NamedType
    from verifier.st.source import read_source
    from verifier.textfile import text_lines

    ethernet_call = re.compile(r"\b(?:" + "|".join(sorted(ETHERNET)) + r")\s*\(", re.IGNORECASE)
    pous, calls = {}, set()
    for path in sources:
        text, _ = read_source(path)  # an unreadable file is reported where the sources load
        parsed = st.parse(text, str(path))
        lines = text_lines(parsed.text)
        for pou in parsed.pous:
            pous[pou.key] = pou
            own = "\n".join(lines[pou.span.line - 1:pou.span.end_line]) if pou.span.line else text
            if ethernet_call.search(_COMMENT.sub(" ", own)):
                calls.add(pou.key)
    if program is not None:
        todo = [program.upper()]
    else:
        todo = [key for key, pou in pous.items() if pou.kind == "PROGRAM"]
    seen = set()
    while todo:
        key = todo.pop()
        if key in seen or key not in pous:
            continue
        seen.add(key)
        if key in calls:
            return True
        for var in pous[key].variables:
            kind = var.type
            while isinstance(kind, ArrayType):
                kind = kind.element
            if isinstance(kind, NamedType):
                todo.append(kind.name.upper())
    return False
