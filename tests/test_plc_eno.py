"""Mitsubishi FB-library convention for every function block of plc/: the first input is
the execution command i_bEN, the first output the execution status o_bENO, and o_bENO
mirrors i_bEN (QA finding 26: it used to be always TRUE)."""
from __future__ import annotations

from pathlib import Path

import pytest

import verifier
from verifier import st
from verifier.st import ast

PLC = Path(__file__).resolve().parents[1] / "plc"
SETS = {   # platform: (editor, CPU, folders that load together)
    "fx3u": ("gxworks2", "fx3u", ["core", "fx3", "examples/common", "examples/fx3"]),
    "q": ("gxworks2", "q", ["core", "q", "examples/common", "examples/q"]),
    "fx5u": ("gxworks3", "fx5u", ["core", "fx5", "examples/common", "examples/fx5"]),
}


def _files(parts):
    return [p for part in parts for p in sorted((PLC / part).glob("*.st"))]


def _function_blocks():
    seen = {}
    for platform, (target, _, parts) in SETS.items():
        for path in _files(parts):
            source = st.parse(path.read_text(), str(path), target)
            for pou in source.pous:
                if pou.kind == "FUNCTION_BLOCK" and pou.name not in seen:
                    seen[pou.name] = (platform, pou)
    return seen


FBS = _function_blocks()


def _labels(pou, section):
    return [d.name for block in pou.var_blocks if block.keyword == section for d in block.variables]


def test_the_library_has_function_blocks():
    assert {"UITAMR_Command", "UITAMR_Engine", "UITAMR_PortFx3", "UITAMR_PortFx5",
            "UITAMR_PortQC24", "UITAMR_PointCycle"} <= set(FBS)


@pytest.mark.parametrize("name", sorted(FBS))
def test_en_is_the_first_input_and_eno_the_first_output(name):
    _, pou = FBS[name]
    assert _labels(pou, "VAR_INPUT")[0] == "i_bEN"
    assert _labels(pou, "VAR_OUTPUT")[0] == "o_bENO"


@pytest.fixture(scope="module")
def projects():
    return {platform: verifier.load(*[PLC / part for part in parts], target=target, cpu=cpu)
            for platform, (target, cpu, parts) in SETS.items()}


@pytest.mark.parametrize("name", sorted(FBS))
def test_eno_mirrors_en(projects, name):
    platform, _ = FBS[name]
    fb = projects[platform].instance(name)
    seen = []
    for en in (True, False, True, False):
        fb.i_bEN = en
        fb.scan()
        seen.append(bool(fb.o_bENO))
    assert seen == [True, False, True, False]


def _says_outputs_go_to_zero(name):
    """The FBs whose header says what i_bEN FALSE leaves on the outputs ("outputs FALSE /
    0"), and the command FBs, which docs/plc-library.md's i_bEN table says it of."""
    _, pou = FBS[name]
    header = " ".join(next(PLC.rglob(f"{name}.st")).read_text(encoding="utf-8").split("*)", 1)[0].split())
    return "FALSE / 0" in header or "fbCmd" in _labels(pou, "VAR")


ZEROED = sorted(name for name in FBS if _says_outputs_go_to_zero(name))


def test_the_fbs_that_say_their_outputs_go_to_zero_are_found():
    assert {"UITAMR_PointCycle", "UITAMR_Command", "UITAMR_RunPoint", "UITAMR_BuildControl",
            "UITAMR_PortLink"} <= set(ZEROED)


@pytest.mark.parametrize("name", ZEROED)
def test_en_off_leaves_every_output_false_or_zero(projects, name):
    """UITAMR_PointCycle's header said "outputs go FALSE / 0" with i_bEN off, but o_wPoint
    kept the point of the stopped cycle (D100 in the examples). Every FB that says so,
    run with its inputs set and then disabled, now shows FALSE / 0 on every output."""
    platform, pou = FBS[name]
    fb = projects[platform].instance(name)
    for block in pou.var_blocks:
        if block.keyword != "VAR_INPUT":
            continue
        for label in block.variables:
            kind = getattr(label.type, "name", None)
            value = {"BOOL": True, "INT": 2, "WORD": 2, "REAL": 0.4}.get(kind)
            if value is not None:
                setattr(fb, label.name, value)
    fb.scan(3)
    fb.i_bEN = False
    fb.scan(2)
    left = {label: getattr(fb, label) for label in _labels(pou, "VAR_OUTPUT") if getattr(fb, label)}
    assert not left, f"{name} with i_bEN FALSE: {left}"
