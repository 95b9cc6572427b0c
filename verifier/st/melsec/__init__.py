"""The MELSEC instruction names of each CPU family, which GX Works refuses as label names
(docs/st-dialect.md section 4): one module a family (fx3, fx5, q), each the manual's
instruction list as data, expanded here into every name a program may write (MOV, MOVP,
DMOV, DMOVP).

A family's names are what `uitamr check --platform` refuses on that CPU; without
--platform, the names every family the target's editor programs has (GX Works2: those of
both FX3 and Q; GX Works3: FX5's): "without --platform nothing is asked of the CPU", and
those are refused whichever CPU the file goes to.
"""
from __future__ import annotations

import re
from types import MappingProxyType

from verifier.plcfacts import PLATFORM_FAMILY

from . import fx3, fx5, q

#: family -> (the CPUs, the editor that refuses the names)
FAMILIES = MappingProxyType({
    "fx3": ("FX3U/FX3G", "GX Works2"),
    "fx5": ("FX5U", "GX Works3"),
    "q": ("Q", "GX Works2"),
})
#: `--platform` -> family: verifier.plcfacts.PLATFORM_FAMILY (shared with the scenario reader)
#: `--target` -> the families its editor programs (those of verifier.sim.cpu.TARGET_CPUS;
#: kept equal by tests/test_check_reserved.py: verifier.st does not import the simulator)
TARGET_FAMILIES = MappingProxyType({"gxworks2": ("fx3", "q"), "gxworks3": ("fx5",)})

_LINE = re.compile(r"([A-Z][A-Z0-9_]*)(?:\s+([dp]+))?")


def expand(text: str, where: str) -> frozenset[str]:
    """Every name the lines of `text` stand for ('MOV dp': MOV, MOVP, DMOV, DMOVP).
    A malformed line is a mistake in the data module `where`: ValueError."""
    names: set[str] = set()
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        m = _LINE.fullmatch(line)
        if m is None or len(set(m.group(2) or "")) != len(m.group(2) or ""):
            raise ValueError(f"{where}: line {number} {raw!r} is not 'MNEMONIC [d][p]'")
        name, flags = m.group(1), m.group(2) or ""
        names.add(name)
        if "p" in flags:
            names.add(name + "P")
        if "d" in flags:
            names.add("D" + name)
            if "p" in flags:
                names.add("D" + name + "P")
    return frozenset(names)


NAMES = MappingProxyType({family: expand(module.NAMES, module.__name__)
                          for family, module in (("fx3", fx3), ("fx5", fx5), ("q", q))})


def families_for(target: str, platform: str | None) -> tuple[str, ...]:
    """The families whose instruction names a label may not take when checked for
    `target` (gxworks2|gxworks3) on `platform` (a CPU profile name, or None: every family
    the target's editor programs, of which `instruction_family` asks all)."""
    if platform is not None:
        family = PLATFORM_FAMILY.get(str(platform).lower())
        if family is None:
            raise ValueError(f"unknown platform {platform!r}; use one of {', '.join(PLATFORM_FAMILY)}")
        return (family,)
    return TARGET_FAMILIES.get(target, ())


def instruction_family(name: str, families: tuple[str, ...]) -> str | None:
    """The first of `families` when each of them has an instruction called `name` (any
    case), else None: a name GX Works refuses whichever of those CPUs the file goes to
    (without --platform, GX Works2's FX3 and Q both; an FX3 project takes a label `IX`,
    a Q instruction, which `--platform q` refuses)."""
    key = name.upper()
    if families and all(key in NAMES[f] for f in families):
        return families[0]
    return None
