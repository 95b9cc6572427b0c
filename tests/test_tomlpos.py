"""verifier.tomlpos: the line of a key in a TOML file, shared by every TOML loader."""
from __future__ import annotations

import tomllib

import pytest

from verifier.tomlpos import Place, decode_error_position, line_of_key, place_of_key

TEXT = """\
name = "bench"
duration = "60s"

[robot]
turnaround_ms = 8
"pacing" = "late"

[[faults]]
kind = "no_reply"
on_request = 1

[[faults]]
kind = "late_reply"
on_request = 2

[[inputs]]
at = "1s"
[inputs.set]
X0 = true
"""
LINES = TEXT.splitlines()


@pytest.mark.parametrize("key, line", [
    ("name", 1),
    ("duration", 2),
    ("robot", 4),
    ("robot.turnaround_ms", 5),
    ("robot.pacing", 6),          # a quoted key
    ("faults", 8),                # the first table of the array
    ("faults[0]", 8),
    ("faults[0].on_request", 10),
    ("faults[1].kind", 13),
    ("faults[1].delay_ms", 12),   # missing in its table: its header, not a later table's key
    ("faults[0].delay_ms", 8),
    ("inputs[0].set", 16),        # sub-tables belong to their table
    ("nosuch", None),
    ("", None),
])
def test_line_of_key(key, line):
    assert line_of_key(LINES, key) == line


def test_a_missing_key_never_points_into_a_later_table():
    lines = ["[[faults]]", "kind = 'late_reply'", "", "[[faults]]", "kind = 'late_reply'", "delay_ms = 5"]
    assert line_of_key(lines, "faults[0].delay_ms") == 1
    assert line_of_key(lines, "faults[1].delay_ms") == 6


def test_decode_error_position_moves_line_and_column_out_of_the_message():
    with pytest.raises(tomllib.TOMLDecodeError) as caught:
        tomllib.loads('a = 1\n[[faults]\nkind = "x"\n')
    message, place = decode_error_position(caught.value)
    assert (place.line, place.col) == (2, 9) and str(place) == "2:9"
    assert message == "Expected ']]' at the end of an array declaration"


def test_keys_in_inline_tables_point_at_the_line_that_holds_them():
    lines = ['name = "x"', 'faults = [{ kind = "no_reply", on_request = 1 },', '  { kind = "x", at_s = 1 }]',
             'robot = { pacing = "sometimes" }']
    assert line_of_key(lines, "faults[1].kind") == 2
    assert line_of_key(lines, "robot.pacing") == 4
    assert line_of_key(lines, "nosuch.key") is None


def test_places_point_at_the_value_the_item_or_the_key():
    lines = ['name = "x"', 'watch = ["a", "b.c", [1, 2], { x = 1 }]', "", "[robot]", "  pacing = 'sometimes'",
             "[[inputs]]", 'at = "1s"', "set = { X0 = true, D100 = 5 }"]
    assert str(place_of_key(lines, "name")) == "1:8"
    assert str(place_of_key(lines, "watch")) == "2:9"
    assert [str(place_of_key(lines, f"watch[{i}]")) for i in range(4)] == ["2:10", "2:15", "2:22", "2:30"]
    assert place_of_key(lines, "watch[9]") == Place(2, 9)  # no such item: the array
    assert str(place_of_key(lines, "robot.pacing")) == "5:12"
    assert str(place_of_key(lines, "robot.pacing", at_name=True)) == "5:3"
    assert str(place_of_key(lines, "inputs[0].set.D100")) == "8:27"
    assert str(place_of_key(lines, "robot")) == "4:1"
    assert place_of_key(lines, "nowhere.at.all") is None


def test_quoted_table_names_and_literal_keys_are_found():
    # the docs quote buffer memory with single quotes ('U0\G164' = 8); a table's name may
    # be quoted too. Both pointed at the table's header, or nowhere (0:0 in `uitamr check`).
    lines = ["[initial]", "D100 = 3", "'U0\\G164' = 8", "", '["robot"]', "turnaround_ms = 'x'",
             "", "[[ 'faults' ]]", "kind = 'x'"]
    assert place_of_key(lines, "initial.U0\\G164") == Place(3, 13)
    assert place_of_key(lines, "initial.U0\\G164", at_name=True) == Place(3, 1)
    assert place_of_key(lines, "robot.turnaround_ms") == Place(6, 17)
    assert line_of_key(lines, "robot") == 5
    assert line_of_key(lines, "faults[0].kind") == 9


def test_dotted_keys_are_found():
    # robot.turnaround_ms = "x" (a TOML dotted key) gave no place at all (0:0 in uitamr check)
    lines = ['name = "x"', 'robot.turnaround_ms = "x"', "a.b.c = 1"]
    assert place_of_key(lines, "robot.turnaround_ms") == Place(2, 23)
    assert place_of_key(lines, "a", at_name=True) == Place(3, 1)


def test_items_of_an_array_over_several_lines_are_found_on_their_line():
    """A watch list written one label a line (with comments, a nested array, a trailing
    comma): the n-th item's own line and column, not the array's first line."""
    text = ('watch = [\n'
            '    "fbEngine.o_wTxCount",   # counts, ["a", "b"] in a comment is no item\n'
            '\n'
            '    ["x", "y"], 3,\n'
            '    "fbCycle.o_wNoSuch",\n'
            ']\n')
    lines = text.splitlines()
    assert tomllib.loads(text)["watch"][3] == "fbCycle.o_wNoSuch"
    assert place_of_key(lines, "watch[0]") == Place(2, 5)
    assert place_of_key(lines, "watch[1]") == Place(4, 5)
    assert place_of_key(lines, "watch[2]") == Place(4, 17)
    assert place_of_key(lines, "watch[3]") == Place(5, 5)
    assert place_of_key(lines, "watch[4]") == Place(1, 9)  # no such item: the array
