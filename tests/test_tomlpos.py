"""verifier.tomlpos: the line of a key in a TOML file, shared by every TOML loader."""
from __future__ import annotations

import json
import re
import tomllib

import pytest
from hypothesis import given, settings, strategies as st

from verifier.place import Place
from verifier.textfile import text_lines
from verifier.tomlpos import decode_error_position, line_of_key, place_of_key

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
    ("inputs[0].set", 18),        # a sub-table of the last [[inputs]]: its own header (was 16, [[inputs]])
    ("inputs[0].set.X0", 19),
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
    assert line_of_key(lines, "faults[1].kind") == 3  # the second table's own line (was 2, the array's)
    assert line_of_key(lines, "robot.pacing") == 4
    assert line_of_key(lines, "nosuch.key") is None


def test_places_point_at_the_value_the_item_or_the_key():
    lines = ['name = "x"', 'watch = ["a", "b.c", [1, 2], { x = 1 }]', "", "[robot]", "  pacing = 'sometimes'",
             "[[inputs]]", 'at = "1s"', "set = { X0 = true, D100 = 5 }"]
    assert str(place_of_key(lines, "name")) == "1:8"
    assert str(place_of_key(lines, "watch")) == "2:9"
    assert [str(place_of_key(lines, f"watch[{i}]")) for i in range(4)] == ["2:10", "2:15", "2:22", "2:30"]
    assert place_of_key(lines, "watch[9]") == Place(None, 2, 9)  # no such item: the array
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
    assert place_of_key(lines, "initial.U0\\G164") == Place(None, 3, 13)
    assert place_of_key(lines, "initial.U0\\G164", at_name=True) == Place(None, 3, 1)
    assert place_of_key(lines, "robot.turnaround_ms") == Place(None, 6, 17)
    assert line_of_key(lines, "robot") == 5
    assert line_of_key(lines, "faults[0].kind") == 9


def test_dotted_keys_are_found():
    # robot.turnaround_ms = "x" (a TOML dotted key) gave no place at all (0:0 in uitamr check)
    lines = ['name = "x"', 'robot.turnaround_ms = "x"', "a.b.c = 1"]
    assert place_of_key(lines, "robot.turnaround_ms") == Place(None, 2, 23)
    assert place_of_key(lines, "a", at_name=True) == Place(None, 3, 1)


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
    assert place_of_key(lines, "watch[0]") == Place(None, 2, 5)
    assert place_of_key(lines, "watch[1]") == Place(None, 4, 5)
    assert place_of_key(lines, "watch[2]") == Place(None, 4, 17)
    assert place_of_key(lines, "watch[3]") == Place(None, 5, 5)
    assert place_of_key(lines, "watch[4]") == Place(None, 1, 9)  # no such item: the array


@pytest.mark.parametrize("text, key, place, name", [
    # a sub-table by a dotted header: was its parent's header, or nothing
    ("[robot]\npacing = 'answer'\n\n[robot.point_durations_s]\n3 = 2.0\n4 = 'x'\n", "robot.point_durations_s.4",
     Place(None, 6, 5), Place(None, 6, 1)),
    ("[robot.point_durations_s]\n3 = 2.0\n", "robot.point_durations_s.3", Place(None, 2, 5), Place(None, 2, 1)),
    ("[robot.point_durations_s]\n3 = 2.0\n", "robot", Place(None, 1, 1), Place(None, 1, 1)),  # made on the way: that header
    ("[robot.point_durations_s]\n3 = 2.0\n[robot]\npacing = 1\n", "robot", Place(None, 3, 1), Place(None, 3, 1)),
    # a sub-table of the last table of an array of tables: was the [[...]] header
    ("[[inputs]]\nat = '1s'\n[[inputs]]\nat = '2s'\n[inputs.set]\nX0 = true\nD100 = 1\n", "inputs[1].set.D100",
     Place(None, 7, 8), Place(None, 7, 1)),
    ("[[inputs]]\nat = '1s'\n[[inputs]]\nat = '2s'\n[inputs.set]\nX0 = true\n", "inputs[1].set", Place(None, 5, 1),
     Place(None, 5, 1)),
    ("[[faults]]\nkind = 'x'\n[faults.sub]\ny = 1\n[[faults]]\nkind = 'z'\n[faults.sub]\ny = 2\n", "faults[1].sub.y",
     Place(None, 8, 5), Place(None, 8, 1)),
    ("[[a]]\n[[a.b]]\nc = 1\n[[a.b]]\nc = 2\n[[a]]\n[[a.b]]\nc = 3\n", "a[1].b[0].c", Place(None, 8, 5), Place(None, 8, 1)),
    # dotted keys in a table, quoted parts, spaces around the dots
    ("[robot]\npoint_durations_s . \"4\" = 'x'\n", "robot.point_durations_s.4", Place(None, 2, 27), Place(None, 2, 21)),
    # inline tables and arrays: the key inside, on its own line
    ("faults = [\n  { kind = 'a' },  # one\n  { kind = 'b', at_s = 1 },\n]\n", "faults[1].at_s", Place(None, 3, 24),
     Place(None, 3, 17)),
    ("set = { 'fbRobot.i_uPoint' = 3, X0 = true }\n", "set.fbRobot.i_uPoint", Place(None, 1, 30), Place(None, 1, 9)),
    # names in comments and strings are not keys or headers
    ("a = '''\n[robot]\nturnaround_ms = 1'''\n# [robot]\n[robot]  # [faults]\nturnaround_ms = 2\n",
     "robot.turnaround_ms", Place(None, 6, 17), Place(None, 6, 1)),
    ('s = "a \\" [robot] x = 1"\n[robot]\nx = 2\n', "robot.x", Place(None, 3, 5), Place(None, 3, 1)),
    # missing: the deepest table it would be in
    ("[[inputs]]\nat = '1s'\n[inputs.set]\nX0 = true\n", "inputs[0].set.D100", Place(None, 3, 1), Place(None, 3, 1)),
])
def test_keys_of_sub_tables_dotted_keys_and_inline_tables_are_at_their_own_place(text, key, place, name):
    lines = text.splitlines()
    tomllib.loads(text)  # valid TOML, as every loader has read it before
    assert place_of_key(lines, key) == place
    assert place_of_key(lines, key, at_name=True) == name


# --- any document: every value is found where it is written ----------------------------------

NAMES = st.text(st.characters(blacklist_characters=".[]", blacklist_categories=("Cs", "Cc")), min_size=1,
                max_size=6) | st.sampled_from(["a", "b", "kind", "3", "x-y", "set"])
SCALARS = st.integers(-10**6, 10**6) | st.booleans() | st.text(
    st.characters(blacklist_categories=("Cs",), blacklist_characters="\r\x7f"), max_size=8) | st.sampled_from(
    ["[robot]", "a = 1", "# no comment", "'''", '"""', '""', "\\", "x\ny", "}, {"])
TREES = st.recursive(
    SCALARS | st.lists(SCALARS, max_size=3),
    lambda inner: st.dictionaries(NAMES, inner, max_size=4) | st.lists(st.dictionaries(NAMES, inner, max_size=3),
                                                                        min_size=1, max_size=2),
    max_leaves=12)
STYLES = ("basic", "literal", "multi-line")


def _key(name: str) -> str:
    return name if re.fullmatch(r"[A-Za-z0-9_-]+", name) else json.dumps(name, ensure_ascii=False)


def _scalar(value, style: str) -> str:
    """A scalar as TOML writes it; a string in one of the styles, where that style can hold it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    controls = {ch for ch in value if ord(ch) < 32 and ch != "\t"}
    if style == "literal" and not controls and "'" not in value:
        return f"'{value}'"
    if style == "literal" and controls <= {"\n"} and "'''" not in value and not value.startswith("\n") \
            and not value.endswith("'"):
        return f"'''{value}'''"
    if style == "multi-line":
        return '"""' + json.dumps(value, ensure_ascii=False)[1:-1] + '"""'
    return json.dumps(value, ensure_ascii=False)


def _inline(value, data) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)} = {_inline(v, data)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        gap = "\n  " if data.draw(st.booleans()) else " "  # an array over several lines, with comments
        comment = " # [x] = 1" if gap != " " else ""
        return "[" + "".join(f"{gap}{_inline(v, data)},{comment}" for v in value) + gap + "]"
    return _scalar(value, data.draw(st.sampled_from(STYLES)))


def _is_tables(value) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(item, dict) for item in value)


def _render(table: dict, header: list[str], data, out: list[str]) -> None:
    """`table` as TOML: its plain keys, then each sub-table as a header (an array of them as
    [[...]]), inline, or as dotted keys (`sub . key = 1`)."""
    later = []
    for name, value in table.items():
        style = data.draw(st.sampled_from(["header", "inline", "dotted"]))
        if isinstance(value, dict) and style == "dotted" and value and not any(
                isinstance(v, (dict, list)) for v in value.values()):
            out += [f"{_key(name)} . {_key(k)} = {_inline(v, data)}" for k, v in value.items()]
        elif (isinstance(value, dict) or _is_tables(value)) and style != "inline":
            later.append((name, value))
        else:
            out.append(f"{_key(name)} = {_inline(value, data)}")
    for name, value in later:
        path = header + [_key(name)]
        for item in (value if isinstance(value, list) else [value]):
            out.append(f"[[{'.'.join(path)}]]" if isinstance(value, list) else f"[ {' . '.join(path)} ]")
            _render(item, path, data, out)


def _leaves(value, key: str):
    if isinstance(value, dict):
        for name, item in value.items():
            yield from _leaves(item, f"{key}.{name}" if key else name)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _leaves(item, f"{key}[{i}]")
    else:
        yield key, value


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.dictionaries(NAMES, TREES, min_size=1, max_size=4), st.data())
def test_every_value_of_any_document_is_found_where_it_is_written(document, data):
    """Random documents, their tables written as headers, sub-tables of arrays of tables,
    inline tables, dotted keys; arrays over several lines with comments; strings of each
    kind holding brackets, quotes, '#' and '=': every value is placed where it starts."""
    out: list[str] = []
    _render(document, [], data, out)
    text = "\n".join(out) + "\n"
    assert tomllib.loads(text) == document, text  # the document is written right
    lines = text_lines(text)
    for key, value in _leaves(document, ""):
        place = place_of_key(lines, key)
        assert place is not None, (key, text)
        written = "\n".join(lines[place.line - 1:])[place.col - 1:]
        assert any(written.startswith(_scalar(value, style)) for style in STYLES), (key, place, text)


def test_finding_a_key_looks_up_its_own_parts_not_every_key_of_the_document(monkeypatch):
    """A scenario's loader places every key it knows (each input and each label an input
    sets), so finding one must not read every place of the document: a scenario of 600
    inputs took 6.5 s to load (0.17 s before the rewrite), 3,000 inputs 37 s."""
    import verifier.tomlpos as tomlpos

    def document(count: int) -> str:
        return "\n".join(f"[[inputs]]\nat = \"{i}ms\"\nset = {{ X0 = true, \"fb.i_uPoint\" = {i} }}"
                         for i in range(count))

    class Counting(dict):
        read = 0

        def __iter__(self):
            for path in super().__iter__():
                Counting.read += 1
                yield path

        def __contains__(self, path):
            Counting.read += 1
            return super().__contains__(path)

    walk, reads = tomlpos._places, []
    for count in (10, 1000):
        text = document(count)
        places = Counting(walk(text))
        monkeypatch.setattr(tomlpos, "_places", lambda _text, places=places: places)
        Counting.read = 0
        lines = text_lines(text)
        assert place_of_key(lines, f"inputs[{count - 1}].set.fb.i_uPoint") == Place(None, 3 * count, 36)
        assert place_of_key(lines, f"inputs[{count - 1}].set.X0", at_name=True) == Place(None, 3 * count, 9)
        reads.append(Counting.read)
    assert reads[1] == reads[0] < 40, reads


def test_an_array_nested_deeper_than_the_walk_can_follow_is_no_crash():
    """tomllib reads an array nested 400 deep; the walk that places keys takes more frames
    per level and ran out of them: `uitamr check` and `verify` of such a file ended in a
    RecursionError traceback instead of the file's own error. Its places are best effort:
    those found before it are kept."""
    from verifier.verify.scenario import ScenarioError, parse_scenario

    text = "name = 5\nwatch = " + "[" * 400 + "]" * 400 + "\n"
    assert tomllib.loads(text)["name"] == 5
    assert place_of_key(text_lines(text), "name") == Place(None, 1, 8)
    with pytest.raises(ScenarioError) as error:
        parse_scenario(text)
    assert error.value.place.line == 1 and "name" in str(error.value)


def check_scenario(path, text):
    """`uitamr check` of a scenario file written at path with text."""
    from click.testing import CliRunner

    from verifier.cli import main

    path.write_text(text, encoding="utf-8")
    return CliRunner().invoke(main, ["check", str(path)], catch_exceptions=False)


@pytest.mark.parametrize("text, place, words", [
    ('name = "x"\nprogram = "P', (2, 13), "Unterminated string at the end of the file"),
    ('name = "x"\nprogram', (2, 8), "Expected '=' after a key in a key/value pair at the end of the file"),
    ('name = "x"\nprogram = """P\n\n', (4, 1), "Unterminated string at the end of the file"),
])
def test_a_file_that_ends_inside_a_value_is_placed_at_its_end(text, place, words, tmp_path):
    # tomllib (Python < 3.14) says "(at end of document)" with no line: `uitamr check`
    # printed file:0:0 and `uitamr verify` the file name alone
    with pytest.raises(tomllib.TOMLDecodeError) as caught:
        tomllib.loads(text)
    message, found = decode_error_position(caught.value, text)
    assert (found.line, found.col) == place and message == words
    path = tmp_path / "cut.toml"
    result = check_scenario(path, text)
    assert result.output.startswith(f"{path}:{place[0]}:{place[1]}: error: not valid TOML: {words}\n")


@pytest.mark.parametrize("text, key, place", [
    ('name = "x"\n"" = 1\n', "", (2, 1)),
    ('name = "x"\n[robot]\nturnaround_ms = 5\n"" = 1\n', "robot.", (4, 1)),
    ('[[faults]]\nkind = "no_reply"\n"" = 2\n', "faults[0].", (3, 1)),
    ('robot = { pacing = "late", "" = 1 }\n', "robot.", (1, 28)),
])
def test_an_empty_key_is_found_where_it_is_written(text, key, place):
    # TOML allows the quoted key "": a scenario's unknown key "" at the top had no place
    # (`uitamr check` printed file:0:0), one in a table was placed at the table's header
    found = place_of_key(text_lines(text), key, at_name=True)
    assert (found.line, found.col) == place


def test_a_scenario_with_an_empty_key_names_its_line(tmp_path):
    path = tmp_path / "empty-key.toml"
    result = check_scenario(path, 'name = "x"\n"" = 1\n')
    assert result.output.startswith(f"{path}:2:1: error: unknown key; expected one of name,")


@pytest.mark.parametrize("text, place", [
    ("name = 'x'\nwatch = " + "[" * 1000 + "]" * 1000 + "\n", (2, 9)),
    ("name = 'x'\n[robot]\nx = " + "{a=" * 1000 + "1" + "}" * 1000 + "\n", (3, 5)),
])
def test_values_nested_too_deep_for_tomllib_are_an_error_at_their_key(text, place, tmp_path):
    # tomllib raised RecursionError (not a TOMLDecodeError) some 400 levels deep: check,
    # verify --scenario and emulate --faults ended in a traceback
    from verifier.emulate.faultfile import FaultFileError, load_fault_file
    from verifier.verify.scenario import ScenarioError, parse_scenario

    with pytest.raises(ScenarioError) as error:
        parse_scenario(text)
    assert (error.value.place.line, error.value.place.col) == place
    assert error.value.message == ("not valid TOML: arrays or inline tables nested hundreds deep: too deep to "
                                   "read, and no setting takes them")
    path = tmp_path / "deep.toml"
    result = check_scenario(path, text)
    assert result.output.startswith(f"{path}:{place[0]}:{place[1]}: error: not valid TOML: arrays")
    with pytest.raises(FaultFileError, match=rf"^{path}:{place[0]}:{place[1]}: not valid TOML: arrays or inline tables"):
        load_fault_file(path)


def test_a_value_nested_hundreds_deep_is_shown_without_a_recursion_error():
    """A scenario's deeply nested `watch` item, told now beside the file's other mistakes,
    reached `shown` and ended in a RecursionError instead of the file's errors."""
    from verifier.tomlpos import shown

    deep: list = []
    for _ in range(400):
        deep = [deep]
    assert shown(deep).startswith("[[[[") and shown(deep).endswith("...")
    assert shown([1, [True, "a"]]) == "[1, [true, 'a']]"
