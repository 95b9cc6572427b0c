"""Reading plain dicts (from TOML scenarios or a ``--faults`` file) into dataclasses.

Every problem becomes a :class:`ConfigError` that names the offending key by its path, e.g.
``faults[2].kind: unknown fault 'x'; expected one of anti_collision, off_tape, …`` — the
caller adds the file name; nobody sees a traceback for a typo in a scenario.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from verifier.digits import digit_problem
from verifier.tomlpos import shown


class ConfigError(ValueError):
    """A bad value in a robot configuration or fault list; ``path`` names the key."""

    def __init__(self, path: str, message: str, at_name: bool = False) -> None:
        super().__init__(f"{path}: {message}" if path else message)
        self.path = path
        self.message = message
        self.at_name = at_name  # the key itself is the mistake (unknown key): point at its name


def join(path: str, key: str | int) -> str:
    """``path`` extended by a key (``robot.turnaround_ms``) or an index (``faults[2]``)."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def require_mapping(value: Any, path: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise ConfigError(path, f"expected a table of keys, got {shown(value)}")
    return value


def did_you_mean(word: str, candidates: Iterable[str]) -> str:
    """'; did you mean 'scan'?' when one of `candidates` is spelt nearly as `word`, else ''.

    The one guess for every misspelt name a scenario can hold: a key (`scna` -> 'scan',
    `at` -> 'at_s') and a label or member (`fbEngin` -> 'fbEngine', `PTT` -> 'PT'). A name
    that differs in case only is the guess (`SCAN` -> 'scan': a TOML key is case-sensitive,
    an ST label is not; either way the user meant the name there is). Otherwise at least two
    thirds of the characters must match (difflib's ratio), and two of them at least: enough
    for a short key's missing suffix, not for one letter in common (`QQ` is not 'Q'). The
    capitals count where the user wrote some: they mark where the words of a label start,
    so names of a large FB that share only their prefix are not alike (`o_bNope` is not
    'o_bENO', `i_bStart` not 'KIND_STATUS'); a name written in one case (`FBENGIN`,
    `fbengin`) is compared case aside."""
    import difflib

    word = str(word)
    candidates = list(candidates)
    same = [name for name in candidates if name.casefold() == word.casefold()]
    if same:
        return f"; did you mean '{same[0]}'?"
    one_case = word == word.upper() or word == word.lower()
    shown = (lambda name: name.casefold()) if one_case else (lambda name: name)
    matcher = difflib.SequenceMatcher()
    matcher.set_seq2(shown(word))
    best: tuple[float, str] | None = None
    for name in candidates:
        matcher.set_seq1(shown(name))
        if matcher.real_quick_ratio() < 2 / 3 or matcher.quick_ratio() < 2 / 3:
            continue
        score = matcher.ratio()
        common = sum(block.size for block in matcher.get_matching_blocks())
        if score >= 2 / 3 and common >= 2 and (best is None or (score, name) > best):
            best = (score, name)
    return f"; did you mean '{best[1]}'?" if best else ""


def unknown_key(key: str, allowed: Iterable[str]) -> str:
    """The message for a key not in `allowed`: the keys there are, and the one probably
    meant when one is spelt nearly so (`scna` -> 'scan', `battery_percent` -> 'battery_pct')."""
    allowed = list(allowed)
    return f"unknown key; expected one of {', '.join(allowed)}{did_you_mean(key, allowed)}"


def reject_unknown_keys(data: Mapping[str, Any], allowed: Iterable[str], path: str) -> None:
    allowed = list(allowed)
    for key in data:
        if key not in allowed:
            raise ConfigError(join(path, str(key)), unknown_key(key, allowed), at_name=True)


# no setting needs more: times are turned into microseconds (x 1e6) and must stay integers
LARGEST = 1e9


def as_number(value: Any, path: str, *, minimum: float | None = None,
              maximum: float | None = None, strictly_positive: bool = False) -> float:
    """A finite int or float (not a bool) within the given bounds (and within +-1e9)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(path, f"expected a number, got {shown(value)}")
    if abs(value) > LARGEST:
        raise ConfigError(path, f"{value:g} is out of range (at most {LARGEST:g} either way)")
    if strictly_positive and value <= 0:
        raise ConfigError(path, f"must be greater than 0, got {value}")
    if minimum is not None and value < minimum:
        raise ConfigError(path, f"must be at least {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise ConfigError(path, f"must be at most {maximum}, got {value}")
    return float(value)


def as_int(value: Any, path: str, *, minimum: int | None = None,
           maximum: int | None = None) -> int:
    """An integer (not a bool) within the given bounds."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(path, f"expected a whole number, got {shown(value)}")
    if minimum is not None and value < minimum:
        raise ConfigError(path, f"must be at least {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise ConfigError(path, f"must be at most {maximum}, got {value}")
    return value


def as_bool(value: Any, path: str) -> bool:
    if not isinstance(value, bool):
        raise ConfigError(path, f"expected true or false, got {shown(value)}")
    return value


def as_choice(value: Any, path: str, choices: Iterable[str], what: str = "value") -> str:
    choices = list(choices)
    if not isinstance(value, str) or value not in choices:
        raise ConfigError(path, f"unknown {what} {shown(value)}; expected one of {', '.join(choices)}")
    return value


def as_hex_bytes(value: Any, path: str) -> bytes:
    """Bytes written as hex text ("A5 5A ff", "a55aff") or as a list of 0-255 numbers."""
    if isinstance(value, str):
        text = value.replace(" ", "").replace(":", "")
        try:
            data = bytes.fromhex(text)
        except ValueError:
            raise ConfigError(path, f"expected hex bytes like \"A5 5A FF\", got {shown(value)}") from None
    elif isinstance(value, list):
        data = bytes(as_int(v, join(path, i), minimum=0, maximum=255) for i, v in enumerate(value))
    else:
        raise ConfigError(path, f"expected hex bytes like \"A5 5A FF\", got {shown(value)}")
    if not data:
        raise ConfigError(path, "needs at least one byte")
    return data


def as_int_keyed(value: Any, path: str) -> dict[int, Any]:
    """A table whose keys are whole numbers written with 0-9 ("3" = 3; TOML keys are
    strings). A bad key is the mistake, so its error points at the key's name."""
    table = require_mapping(value, path)
    result: dict[int, Any] = {}
    for key, item in table.items():
        if isinstance(key, str) and (problem := digit_problem(key)):  # int() reads "٣" as 3
            raise ConfigError(join(path, key), f"key {key!r}: {problem}", at_name=True)
        if not (isinstance(key, str) and key.isascii() and key.isdigit()):  # int() takes " 4", "+4", "4_0"
            raise ConfigError(join(path, str(key)), f"key {key!r} must be a whole number written with 0-9, "
                                                    'e.g. "3"', at_name=True)
        number = int(key)
        result[number] = item
    return result

