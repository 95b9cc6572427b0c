"""Scripted faults: what goes wrong, and when.

A fault is triggered either at a virtual time (``at_s``) or by the N-th request the robot
receives (``on_request``: requests are counted from 1 after power-on; a request counts when
its CRC is good and it is addressed to this robot).

Two families:

* **state faults** change the robot: ``anti_collision`` (error 01, a running task stops;
  no effect while the anti-collision range is 0 m), ``off_tape`` (error 02, only while a
  magnetic-tape task runs; that task stops), ``low_battery`` (battery 1, error 03). With
  ``duration_s`` the condition clears by itself; without it, anti-collision and off-tape
  stay until the stop command (01/A0) and a low battery stays low.
* **reply faults** change the answer to requests: ``no_reply``, ``late_reply``
  (``delay_ms`` more), ``bad_crc`` (CRC bytes corrupted), ``exception`` (Modbus exception
  ``code`` instead of the reply), ``garbage`` (``data`` bytes ``instead`` of, ``before`` or
  ``after`` the reply), ``wrong_address`` (the reply carries ``address``). They hit
  ``count`` requests (default 1) or every request within ``duration_s``; ``requests``
  narrows them to ``"control"`` (FC06) or ``"status"`` (FC01) requests.
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Iterable, Mapping

from verifier.amr import schema
from verifier.tomlpos import shown

FAULT_KINDS: dict[str, str] = {
    "anti_collision": "obstacle: a running task stops, error 01",
    "off_tape": "robot leaves the magnetic tape: the tape task stops, error 02",
    "low_battery": "battery warning: battery query answers 1, error 03",
    "no_reply": "the robot does not answer",
    "late_reply": "the reply comes delay_ms later",
    "bad_crc": "the reply's CRC is corrupted",
    "exception": "a Modbus exception reply with the given code",
    "garbage": "garbage bytes instead of, before or after the reply",
    "wrong_address": "the reply carries another slave address",
}
STATE_KINDS = frozenset({"anti_collision", "off_tape", "low_battery"})
REPLY_KINDS = frozenset(FAULT_KINDS) - STATE_KINDS
REQUEST_FILTERS = ("any", "control", "status")
GARBAGE_POSITIONS = ("instead", "before", "after")

_COMMON_KEYS = ("kind", "at_s", "on_request", "duration_s")
_KIND_KEYS: dict[str, tuple[str, ...]] = {
    "anti_collision": (),
    "off_tape": (),
    "low_battery": (),
    "no_reply": ("count", "requests"),
    "late_reply": ("count", "requests", "delay_ms"),
    "bad_crc": ("count", "requests"),
    "exception": ("count", "requests", "code"),
    "garbage": ("count", "requests", "data", "position"),
    "wrong_address": ("count", "requests", "address"),
}
DEFAULT_GARBAGE = bytes.fromhex("A55AFF")


@dataclass(frozen=True)
class Fault:
    """One scripted fault; see the module docstring for the kinds and their keys."""

    kind: str
    at_s: float | None = None
    on_request: int | None = None
    duration_s: float | None = None
    count: int | None = None
    requests: str = "any"
    delay_ms: float = 0.0
    code: int = 4
    data: bytes = DEFAULT_GARBAGE
    position: str = "instead"
    address: int | None = None

    def __post_init__(self) -> None:
        if self.kind not in FAULT_KINDS:
            raise schema.ConfigError("fault.kind", _unknown_kind(self.kind))
        if (self.at_s is None) == (self.on_request is None):
            raise schema.ConfigError("fault", "give exactly one trigger: at_s or on_request")
        if self.kind in STATE_KINDS and self.count is not None:
            raise schema.ConfigError("fault.count", f"not used by fault '{self.kind}'")

    # ---- loading -----------------------------------------------------------------------

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], path: str = "fault") -> "Fault":
        """A fault from a TOML-style table; ConfigError names the key that is wrong."""
        data = schema.require_mapping(data, path)
        if "kind" not in data:
            raise schema.ConfigError(schema.join(path, "kind"),
                                     f"missing; expected one of {', '.join(FAULT_KINDS)}")
        kind = data["kind"]
        if not isinstance(kind, str):  # an array or a table is not hashable: no dict lookup
            raise schema.ConfigError(schema.join(path, "kind"),
                                     f"expected a string, got {shown(kind)}; one of {', '.join(FAULT_KINDS)}")
        kind = kind.replace("-", "_")
        if kind not in FAULT_KINDS:
            raise schema.ConfigError(schema.join(path, "kind"), _unknown_kind(data["kind"]))
        allowed = _COMMON_KEYS + _KIND_KEYS[kind]
        for key in data:
            if key not in allowed:
                known = {f.name for f in fields(cls)}
                message = (f"not used by fault '{kind}'; expected one of {', '.join(allowed)}" if key in known
                           else schema.unknown_key(key, allowed))
                raise schema.ConfigError(schema.join(path, str(key)), message, at_name=True)
        at_s = data.get("at_s")
        on_request = data.get("on_request")
        if (at_s is None) == (on_request is None):
            raise schema.ConfigError(path, "give exactly one trigger: at_s or on_request")
        values: dict[str, Any] = {"kind": kind}
        if at_s is not None:
            values["at_s"] = schema.as_number(at_s, schema.join(path, "at_s"), minimum=0.0)
        if on_request is not None:
            values["on_request"] = schema.as_int(on_request, schema.join(path, "on_request"), minimum=1)
        if "duration_s" in data:
            values["duration_s"] = schema.as_number(data["duration_s"], schema.join(path, "duration_s"),
                                                    strictly_positive=True)
        if "count" in data:
            values["count"] = schema.as_int(data["count"], schema.join(path, "count"), minimum=1)
        if "requests" in data:
            values["requests"] = schema.as_choice(data["requests"], schema.join(path, "requests"),
                                                  REQUEST_FILTERS, "request filter")
        if kind == "late_reply":
            if "delay_ms" not in data:
                raise schema.ConfigError(schema.join(path, "delay_ms"), "missing: how much later, in ms")
            values["delay_ms"] = schema.as_number(data["delay_ms"], schema.join(path, "delay_ms"),
                                                  strictly_positive=True)
        if "code" in data:
            values["code"] = schema.as_int(data["code"], schema.join(path, "code"), minimum=1, maximum=255)
        if "data" in data:
            values["data"] = schema.as_hex_bytes(data["data"], schema.join(path, "data"))
        if "position" in data:
            values["position"] = schema.as_choice(data["position"], schema.join(path, "position"),
                                                  GARBAGE_POSITIONS, "position")
        if "address" in data:
            values["address"] = schema.as_int(data["address"], schema.join(path, "address"),
                                              minimum=0, maximum=255)
        return cls(**values)

    # ---- derived -----------------------------------------------------------------------

    @property
    def is_state_fault(self) -> bool:
        return self.kind in STATE_KINDS

    @property
    def at_us(self) -> int | None:
        return None if self.at_s is None else round(self.at_s * 1_000_000)

    @property
    def duration_us(self) -> int | None:
        return None if self.duration_s is None else round(self.duration_s * 1_000_000)

    def describe(self) -> str:
        when = f"at {self.at_s:g} s" if self.at_s is not None else f"on request {self.on_request}"
        extent = ""
        if self.duration_s is not None and self.count is not None:  # both limit it
            extent = f" ×{self.count} within {self.duration_s:g} s"
        elif self.duration_s is not None:
            extent = f" for {self.duration_s:g} s"
        elif self.count is not None:
            extent = f" ×{self.count}"
        if self.requests != "any":
            extent += f", {self.requests} requests only"
        detail = {
            "late_reply": f" (+{self.delay_ms:g} ms)",
            "exception": f" (code {self.code:02X})",
            "garbage": f" ({self.data.hex(' ').upper()} {self.position})",
            "wrong_address": "" if self.address is None else f" (address {self.address})",
        }.get(self.kind, "")
        return f"{self.kind}{detail} {when}{extent}"


def faults_from_list(items: Any, path: str = "faults") -> list[Fault]:
    """A list of fault tables (a TOML ``[[faults]]`` array) → faults, errors name the index."""
    if not isinstance(items, list):
        raise schema.ConfigError(path, "expected a list of fault tables ([[faults]])")
    return [Fault.from_dict(item, schema.join(path, i)) for i, item in enumerate(items)]


def keys_no_fault_has(data: Mapping[str, Any], path: str = "fault") -> list[schema.ConfigError]:
    """The keys of a fault table that no fault kind takes (`at` for `at_s`), each its error:
    told beside an unknown `kind`, which hides which keys that kind would take."""
    known = list(dict.fromkeys(_COMMON_KEYS + tuple(k for keys in _KIND_KEYS.values() for k in keys)))
    # the guess among the keys every fault takes first (`at`: 'at_s', not 'data')
    return [schema.ConfigError(schema.join(path, str(key)),
                               f"unknown key; expected one of {', '.join(known)}"
                               f"{schema.did_you_mean(key, _COMMON_KEYS) or schema.did_you_mean(key, known)}",
                               at_name=True)
            for key in data if key not in known]


def check_fault_addresses(faults: Iterable[Fault], own_address: int, path: str = "faults") -> None:
    """A ``wrong_address`` fault must name another address than the robot's own: a reply
    from the robot's own address is the normal reply, so the fault would test nothing.
    ConfigError names the fault by its place in the list (``faults[2].address``)."""
    for index, fault in enumerate(faults):
        if fault.kind == "wrong_address" and fault.address == own_address:
            raise schema.ConfigError(
                schema.join(schema.join(path, index), "address"),
                f"{own_address} is the robot's own address, so the reply would be a normal one; "
                "give another address (0-255), or leave address out to get the next one")


def _unknown_kind(kind: Any) -> str:
    return f"unknown fault {kind!r}; expected one of {', '.join(FAULT_KINDS)}"


def describe_all(faults: Iterable[Fault]) -> list[str]:
    return [f.describe() for f in faults]
