"""The verifier's documents say what the code does: every scenario key is documented, the
examples of the PLC-settings section load, and citations of protocol.md point at the
section that holds what they cite."""
from __future__ import annotations

import re
from pathlib import Path

from doc_helpers import code_blocks
from file_helpers import write_files
from verifier.verify.scenario import (C24_KEYS, CONVERTER_KEYS, EXPECT_KEYS, INPUT_KEYS, KINDS, PROTOCOL_KEYS,
                                      RESPONSE_KEYS, RULES_KEYS, TOP_KEYS, parse_scenario)

DOCS = Path(__file__).resolve().parents[1] / "docs"
SCENARIOS_MD = (DOCS / "scenarios.md").read_text(encoding="utf-8")
VERIFIER_MD = (DOCS / "verifier.md").read_text(encoding="utf-8")
PROTOCOL_MD = (DOCS / "protocol.md").read_text(encoding="utf-8")


def test_every_scenario_key_is_documented():
    for key in TOP_KEYS:
        assert f"`{key}`" in SCENARIOS_MD or f"[{key}]" in SCENARIOS_MD or f"[[{key}]]" in SCENARIOS_MD, key
    for key in C24_KEYS:
        assert re.search(rf"^{key} = ", SCENARIOS_MD, re.MULTILINE), key


def _scenario_section(title: str) -> str:
    return SCENARIOS_MD.split(f"\n## {title}", 1)[1].split("\n## ", 1)[0]


def _table(section: str) -> dict[str, str]:
    """A key table's rows: each key of the first column (`ip`, `port` are two) and the row's
    last cell (the default, where the table has that column)."""
    rows = {}
    for line in section.splitlines():
        if line.startswith("| `"):
            cells = [cell.strip() for cell in line.strip("|").split(" | ")]
            for key in re.findall(r"`([\w.]+)", cells[0]):
                rows[key] = cells[-1]
    return rows


def test_the_key_tables_are_the_keys_the_reader_takes():
    """Every key the scenario reader takes is in its section's table (or, for a table of
    its own, has a section), and every key a table shows is one the reader takes: the
    tables of [[inputs]], [[expect]], [rules], [response_handling] and [converter] were
    not held to the reader, only the top-level keys and [[c24]]'s."""
    top = _table(_scenario_section("Top-level keys"))
    sections = {key for key in TOP_KEYS if re.search(rf"^## .*`\[{{1,2}}{key}\]{{1,2}}`", SCENARIOS_MD, re.M)}
    assert set(top) <= set(TOP_KEYS) and set(top) | sections == set(TOP_KEYS), (set(TOP_KEYS) - set(top) - sections)
    assert set(_table(_scenario_section("`[[inputs]]`"))) == set(INPUT_KEYS)
    expect = _scenario_section("`[[expect]]`")
    assert set(_table(expect)) == set(KINDS)
    assert all(f"`{key}`" in expect for key in set(EXPECT_KEYS) - set(KINDS))
    assert set(_table(_scenario_section("`[rules]` and `[response_handling]`"))) == (
        {f"rules.{key}" for key in RULES_KEYS} | {f"response_handling.{key}" for key in RESPONSE_KEYS})
    assert set(_table(_scenario_section("The TCP route: `[converter]`"))) == set(CONVERTER_KEYS)
    protocol = _scenario_section("`[protocol]`")
    assert set(re.findall(r"`(\w+)` \(", protocol)) == set(PROTOCOL_KEYS)


def _as_toml(cell: str) -> str:
    """A default as the table writes it (`"60s"`, `0`, `[]`, `fx3u`), as a TOML value."""
    value = re.match(r"`([^`]*)`", cell).group(1)
    return value if re.match(r'^("|\[|\d|true$|false$)', value) else f'"{value}"'


def _same(a, b) -> bool:
    ignored = {"key_lines"}
    return {k: v for k, v in vars(a).items() if k not in ignored} == {k: v for k, v in vars(b).items() if k not in ignored}


def test_the_platforms_the_pages_list_are_the_ones_verify_takes():
    """scenarios.md's `platform` row gives each platform with its dialect and default port,
    the example's comment and verifier.md's --platform row name every one: fx3g was
    accepted by check and export, refused by verify, and these lists said nothing of it."""
    from verifier.verify.scenario import PLATFORMS

    row = next(line for line in SCENARIOS_MD.splitlines() if line.startswith("| `platform` |"))
    editors = {"gxworks2": "GX Works2", "gxworks3": "GX Works3"}
    listed = re.findall(r"`(\w+)` \((GX Works\d)[^,]*, (?:port )?`([\w:]+)`", row)
    assert listed == [(name, editors[target], port) for name, (target, port) in PLATFORMS.items()], listed
    assert "# " + " | ".join(PLATFORMS) + "\n" in SCENARIOS_MD  # the complete example's comment
    option = next(line for line in VERIFIER_MD.splitlines() if line.startswith("| `--platform "))
    assert option.startswith("| `--platform " + "\\|".join(PLATFORMS) + "` |"), option


def test_the_documented_defaults_are_the_readers():
    """Each default a key table gives, written out in a scenario, changes nothing: the
    scenario reads as the one that leaves the key out."""
    top = _table(_scenario_section("Top-level keys"))
    for key in ("platform", "duration", "scan", "scan_jitter", "seed", "watch"):
        assert _same(parse_scenario(f"{key} = {_as_toml(top[key])}\n"), parse_scenario("")), (key, top[key])
    rules = _table(_scenario_section("`[rules]` and `[response_handling]`"))
    for key in ("rules.min_period", "rules.reply_timeout", "response_handling.within"):
        table, name = key.split(".")
        assert _same(parse_scenario(f"[{table}]\n{name} = {_as_toml(rules[key])}\n"), parse_scenario("")), key
    converter = _table(_scenario_section("The TCP route: `[converter]`"))
    empty = parse_scenario('platform = "fx5u"\n[converter]\n').converter
    for cells in {row: None for row in converter.values()}:
        keys = [key for key, row in converter.items() if row == cells]
        values = re.findall(r"`[^`]*`", cells)
        assert len(values) == len(keys), (keys, cells)
        text = "".join(f"{key} = {_as_toml(value)}\n" for key, value in zip(keys, values))
        assert parse_scenario(f'platform = "fx5u"\n[converter]\n{text}').converter == empty, text
    example = code_blocks(_scenario_section("The TCP route: `[converter]`"), "toml")[0]
    assert parse_scenario('platform = "fx5u"\n' + example).converter != empty  # it loads, and sets something


def test_the_plc_settings_example_is_a_valid_scenario():
    section = SCENARIOS_MD.split("## PLC settings", 1)[1]
    block = section.split("```toml\n", 1)[1].split("```", 1)[0]
    scenario = parse_scenario('platform = "q"\n' + block)
    assert dict(scenario.initial) == {"D100": 3, "U0\\G164": 8}
    (c24,) = scenario.c24
    assert (c24.unit, c24.channel, c24.no_reception_us, c24.byte_units, c24.receive_count, c24.end_code,
            c24.no_reception_format) == (0, 1, 5000, True, 8, 0xFFFF, 1)


def _section(number: int) -> str:
    return re.split(r"^## ", PROTOCOL_MD, flags=re.MULTILINE)[number]


def test_protocol_citations_point_at_the_section_that_holds_them():
    """The reply time-out is in protocol.md §1 (line and pacing), not §6 (CRC)."""
    for text in (SCENARIOS_MD, VERIFIER_MD):
        for number in re.findall(r"protocol\.md §(\d+)", text) + re.findall(r"protocol\.md#(\d+)-", text):
            assert _section(int(number)).startswith(f"{number}."), number
    row = next(line for line in SCENARIOS_MD.splitlines() if line.startswith("| `rules.reply_timeout`"))
    number = int(re.search(r"protocol\.md §(\d+)", row).group(1))
    assert "reply timeout" in _section(number)


def test_sent_by_is_the_statement_that_starts_the_transmission():
    """FX3U: the origin is the `M8402 := TRUE` statement (the send request), not the RS2 call."""
    assert "`M8402 := TRUE`" in VERIFIER_MD
    assert "the RS2 / G_OUTPUT /\nADPRW call" not in VERIFIER_MD


def test_the_checked_tree_api_of_st_dialect_section_10_is_reachable_as_written():
    """st-dialect.md §10 names the import that works: `verifier.st.check` on the package is
    the function check(), so `verifier.st.check.check_project` is no path to it."""
    text = (DOCS / "st-dialect.md").read_text(encoding="utf-8")
    section = text.split("## 10. ", 1)[1]
    statement = re.search(r"`(from verifier\.st\.check import check_project)`", section).group(1)
    names: dict = {}
    exec(statement, names)
    from verifier import st
    source = st.parse("FUNCTION F : INT\nVAR_INPUT a : INT; END_VAR\nF := a + 1;\nEND_FUNCTION\n", "f.st")
    diagnostics, table = names["check_project"]([source], "gxworks2")
    assert diagnostics == [] and "A" in table.pous["F"].labels
    assert "verifier.st.check.check_project" not in text


def _error_blocks() -> list[list[str]]:
    section = SCENARIOS_MD.split("## Errors in a scenario file", 1)[1]
    return [[line for line in block.splitlines() if line.strip()] for block in section.split("```")[1::2]]


EXAMPLE_SOURCES = ('sources = ["{plc}/core/*.st", "{plc}/fx3/*.st", "{plc}/examples/common/*.st", '
                   '"{plc}/examples/fx3/UITAMR_ExampleFx3.st"]\n')


def test_the_documented_scenario_file_errors_are_what_verify_prints(tmp_path, monkeypatch):
    """scenarios.md, "Errors in a scenario file": the three file errors, position and all,
    come out of `uitamr verify` as printed there, with exit status 2."""
    from click.testing import CliRunner

    from verifier.cli import main

    plc = (DOCS.parent / "plc").as_posix()
    files = {
        "x.toml": EXAMPLE_SOURCES.format(plc=plc) + '[[expect]]\nsent = "stop"\nwithin = "5"\n',
        "y.toml": EXAMPLE_SOURCES.format(plc=plc) + '[[faults]]\nkind = "no-replies"\nat_s = 1.0\n',
        "z.toml": 'name = "z"\nsources x\n',
    }
    monkeypatch.chdir(tmp_path)
    for name, text in files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    documented = _error_blocks()[0]
    assert len(documented) == len(files)
    for line, name in zip(documented, files):
        result = CliRunner().invoke(main, ["verify", "--scenario", name])
        assert result.exit_code == 2, result.output
        assert result.output.strip() == line


def test_the_documented_label_errors_are_what_verify_prints(tmp_path):
    """The label errors of scenarios.md name what `uitamr verify` names (file positions
    differ with the file; the messages after them must not)."""
    from verifier.verify.runner import run_scenario
    from verifier.verify.result import UnusableInput
    from verifier.verify.scenario import parse_scenario

    plc = DOCS.parent / "plc"
    program = tmp_path / "MAIN.st"
    program.write_text("PROGRAM MAIN\nVAR\n    fbEngine : UITAMR_Engine;\n    wBuf : ARRAY[0..39] OF WORD;\n"
                       "END_VAR\nwBuf[0] := 16#1;\nEND_PROGRAM\n", encoding="utf-8")
    head = f'sources = ["{program.as_posix()}", "{(plc / "core").as_posix()}"]\nprogram = "MAIN"\nduration = "1s"\n'
    bodies = [
        '[[expect]]\nthat = "fbEngine.o_bNope"\n',
        'watch = ["fbEngine.o_wTxCount", "wBuf[40]"]\n',
        '[[inputs]]\nat = "0s"\nset = { X0 = 5 }\n',
        '[[inputs]]\nat = "0s"\nset = { X0 = true }\n[[inputs]]\nat = "0s"\nset = { D100 = 99999 }\n',
        '[[expect]]\nnever = "fbEngine.o_bErr"\n[[expect]]\nnever = "fbEngine.o_bErr"\n'
        '[[expect]]\nthat = "fbEngine.o_wTask"\n',
    ]
    documented = _error_blocks()[1]
    assert len(documented) == len(bodies)
    for line, body in zip(documented, bodies):
        expected = re.sub(r"^error: s\.toml:\d+:\d+: ", "", line)
        scenario = parse_scenario(head + body, tmp_path / "s.toml")
        try:
            run_scenario(scenario)
        except UnusableInput as err:
            assert str(err).endswith(expected), (str(err), expected)
        else:
            raise AssertionError(f"no error for {body!r}")


def _example_as_main(tmp_path, folder: str, example: str, port_folder: str) -> Path:
    plc = DOCS.parent / "plc"
    sources = tmp_path / example
    sources.mkdir()
    for path in [*(plc / "core").glob("*.st"), *(plc / port_folder).glob("*.st"),
                 *(plc / "examples" / "common").glob("*.st")]:
        (sources / path.name).write_text(path.read_text(encoding="utf-8"), encoding="utf-8")
    text = (plc / "examples" / folder / f"{example}.st").read_text(encoding="utf-8")
    (sources / "MAIN.st").write_text(text.replace(example, "MAIN"), encoding="utf-8")
    return sources


def test_matrix_picks_the_bundled_scenarios_of_the_programs_route_as_verifier_md_says(tmp_path):
    """verifier.md: --matrix with SOURCES runs the scenarios of the program's platform *and
    route*: a serial FX5U program never meets a [converter] scenario, a TCP one only those."""
    from click.testing import CliRunner

    from verifier.cli import main

    assert "**and of its route**" in VERIFIER_MD
    helps = " ".join(CliRunner().invoke(main, ["verify", "--help"]).output.split())
    assert "those of the program's platform and route" in helps
    bundled = DOCS.parent / "plc" / "scenarios"
    tcp_names = {p.stem for p in bundled.glob("fx5u-tcp-*.toml")}
    serial_names = {p.stem for p in bundled.glob("fx5u-*.toml")} - tcp_names
    for example, expected in (("UITAMR_ExampleFx5", serial_names), ("UITAMR_ExampleTcpFx5", tcp_names)):
        sources = _example_as_main(tmp_path, "fx5", example, "fx5")
        result = CliRunner().invoke(main, ["verify", str(sources), "--program", "MAIN", "--matrix",
                                           "--duration", "6s"])
        ran = set(re.findall(r"plc/scenarios/(fx5u-[\w-]+)\.toml\)", result.output))
        stands_for = len(re.findall(r"also stands for", result.output))
        assert ran and ran <= expected and len(ran) + stands_for == len(expected), (example, result.output)


def test_the_missing_function_input_messages_of_st_dialect_are_the_checkers():
    """st-dialect.md §8 quotes what `Add3(1, 2)` and `Add3(a := 1, b := 2)` get."""
    from verifier import st

    text = " ".join((DOCS / "st-dialect.md").read_text(encoding="utf-8").split())
    source = st.parse("FUNCTION Add3 : INT\nVAR_INPUT a : INT; b : INT; c : INT; END_VAR\nAdd3 := a + b + c;\n"
                      "END_FUNCTION\nPROGRAM P\nVAR\n    iX : INT;\nEND_VAR\niX := Add3(1, 2);\n"
                      "iX := Add3(a := 1, b := 2);\nEND_PROGRAM\n", "a.st")
    messages = [d.message for d in st.check([source]) if d.severity == "error"]
    assert len(messages) == 2
    for message in messages:
        assert f"`{message.replace('...', '')}" in text.replace("...", ""), message


def test_sent_by_names_the_statement_of_every_fx5u_and_tcp_route(tmp_path):
    """verifier.md's "sent by" paragraph names the statement each route's port FB starts a
    frame with: the send request on FX5U RS2, the ADPRW call, and on the TCP route the send
    instruction (SP_SOCSND, ZP_BUFSND) - read here from the first frame of a real run."""
    import json
    from click.testing import CliRunner
    from verifier.commands.verify import command

    text = " ".join(VERIFIER_MD.split("The ST location is the statement that started", 1)[1]
                    .split("### `--json FILE`", 1)[0].split())
    for name in ("fx5u-healthy", "fx5u-adprw-healthy", "fx5u-tcp-healthy", "q-tcp-healthy"):
        trace = tmp_path / f"{name}.jsonl"
        scenario = Path(__file__).resolve().parents[1] / "plc" / "scenarios" / f"{name}.toml"
        done = CliRunner().invoke(command, ["--scenario", str(scenario), "--duration", "1s", "--trace", str(trace)])
        assert done.exit_code in (0, 1), done.output
        origin = json.loads(trace.read_text().splitlines()[0])["origin"]
        file, line, col = origin.rsplit(":", 2)
        statement = (Path(__file__).resolve().parents[1] / file).read_text().splitlines()[int(line) - 1]
        word = re.match(r"[A-Za-z0-9_]+", statement[int(col) - 1:]).group(0)
        assert f"`{word}`" in text, (name, statement)


def test_the_troubleshooting_rows_that_name_an_fx3_serial_device_name_the_fx5s_too():
    """An FX5U integrator reading the bench-test and commissioning tables finds the device of
    its own CPU next to the FX3's (the equivalents `uitamr check --platform fx5u` names)."""
    from verifier.sim.cpu import FX3_MODBUS, FX3_SERIAL

    rows = [line for doc in ("emulator.md", "commissioning.md")
            for line in (DOCS / doc).read_text(encoding="utf-8").splitlines() if line.startswith("|")]
    checked = 0
    for row in rows:
        for device in re.findall(r"\b[MD]8[0-9]{3}\b", row):
            if device not in FX3_SERIAL:
                continue
            fx5 = FX3_SERIAL[device][1]["fx5"]
            wanted = re.match(r"S[MD]\d+", fx5)
            assert (wanted.group(0) if wanted else "module parameters") in row, (device, row)
            checked += 1
            if device in FX3_MODBUS and "time-out" in row:
                # D8409 is the FX3U-485ADP-MB's slave response time-out too: on the FX5 ADPRW
                # route that is a module parameter, not SD8621
                assert "slave response time-out" in row and "module parameter" in row, (device, row)
    assert checked >= 4


def _block_after(text: str, marker: str) -> list[str]:
    """The lines of the first code block after `marker`."""
    return text.split(marker, 1)[1].split("```\n", 1)[1].split("```", 1)[0].rstrip("\n").splitlines()


def test_the_console_example_is_what_verify_prints_for_a_library_paced_at_200ms(tmp_path, monkeypatch):
    """verifier.md, "Console": the FAIL block of a copy of the library with PACE_TIME set to
    200 ms, line for line (the rule table after it is the console's own)."""
    import shutil
    from click.testing import CliRunner

    from verifier.cli import main

    shutil.copytree(DOCS.parent / "plc", tmp_path / "lib")
    engine = tmp_path / "lib" / "core" / "UITAMR_Engine.st"
    text = engine.read_text(encoding="utf-8")
    assert "PACE_TIME : TIME := T#300ms;" in text
    engine.write_text(text.replace("PACE_TIME : TIME := T#300ms;", "PACE_TIME : TIME := T#200ms;"), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["verify", "--scenario", "lib/scenarios/fx3u-healthy.toml"])
    assert result.exit_code == 1, result.output
    documented = _block_after(VERIFIER_MD, "### Console")
    assert result.output.splitlines()[:len(documented)] == documented


def test_the_matrix_note_example_is_what_verify_prints_for_an_adprw_program(tmp_path, monkeypatch):
    """verifier.md, "Your program under the bundled fault sets": the result of the ADPRW
    example run as MAIN with --matrix --channel adp:1, notes and all."""
    from click.testing import CliRunner

    from verifier.cli import main

    sources = _example_as_main(tmp_path, "fx3", "UITAMR_ExampleAdpFx3", "fx3")
    monkeypatch.chdir(DOCS.parent)
    result = CliRunner().invoke(main, ["verify", str(sources), "--program", "MAIN", "--matrix",
                                       "--channel", "adp:1"])
    assert result.exit_code in (0, 1), result.output
    documented = _block_after(VERIFIER_MD, "Each result says what was left out:")
    lines = result.output.splitlines()
    start = lines.index(documented[0]) if documented[0] in lines else -1
    assert start >= 0, "\n".join(line for line in lines if "adprw-no-reply" in line)
    assert lines[start:start + len(documented)] == documented


def test_the_device_messages_scenarios_md_quotes_are_what_check_prints(tmp_path):
    """scenarios.md: a device an FX3U scenario's CPU lacks is an error, an FX3 special number
    in an FX5U scenario the ST warning, both as `uitamr check` prints them."""
    from click.testing import CliRunner

    from verifier.cli import main

    write_files(tmp_path, {
        "MAIN.st": "PROGRAM MAIN\nVAR\n    iX : INT;\nEND_VAR\niX := iX + 1;\nEND_PROGRAM\n",
        "fx3.toml": 'platform = "fx3u"\nsources = ["MAIN.st"]\n[initial]\nSM400 = true\n',
        "fx5.toml": 'platform = "fx5u"\nsources = ["MAIN.st"]\n[initial]\nM8402 = true\n',
    })
    text = " ".join(SCENARIOS_MD.split())
    for name, severity in (("fx3.toml", "error"), ("fx5.toml", "warning")):
        result = CliRunner().invoke(main, ["check", str(tmp_path / name)])
        message = re.search(rf": {severity}: (initial\..*)", result.output).group(1)
        assert f"`{message}`" in text, message


def test_the_json_example_shows_the_schema_the_reports_carry():
    from verifier.verify.report_json import SCHEMA_VERSION

    page = (DOCS / "verifier.md").read_text(encoding="utf-8")
    example = page.split("### `--json FILE`", 1)[1].split("```", 2)[1]
    assert f'"schema": {SCHEMA_VERSION},' in example
    assert f"**{SCHEMA_VERSION}**: " in page  # and what that number means


def test_the_share_of_idle_scans_jumped_over_is_the_bundled_scenarios(idle_runs):
    """verifier.md, "Idle scans are jumped over": the range of the share of scans each
    bundled scenario jumps over, and the FX3U example's "three scans in four". The range
    said 60-89 % after a bundled scenario (fx3u-address-out-of-range) had come to jump over
    92.5 %."""
    import math

    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    text = " ".join(VERIFIER_MD.split())
    low, high = map(int, re.search(r"between (\d+) % and (\d+) % of the scans are jumped over", text).groups())
    assert "In the FX3U example, about three scans in four are jumped over." in text
    shares = {}
    for path in sorted((DOCS.parent / "plc" / "scenarios").glob("*.toml")):
        idle_runs.clear()
        run_scenario(load_scenario(path))
        (idle,) = idle_runs
        shares[path.stem] = 100 * idle.skipped_scans / idle.rt.scan_count
    assert (math.floor(min(shares.values())), math.ceil(max(shares.values()))) == (low, high), shares
    assert 70 <= shares["fx3u-healthy"] < 80  # about three in four


def test_the_trace_of_an_hour_of_fx3u_healthy_is_the_size_verifier_md_says(tmp_path, monkeypatch):
    """verifier.md, "Long runs": the disk a trace takes an hour (it said 5.5 MiB; the trace
    of an hour of fx3u-healthy, run from the repository's root, is 5.36 MiB)."""
    from click.testing import CliRunner

    from verifier.cli import main

    said = {float(size) for size in re.findall(r"(\d+\.\d) MiB an hour of fx3u-healthy", VERIFIER_MD)
            + re.findall(r"the trace of an hour of fx3u-healthy is (\d+\.\d) MiB", VERIFIER_MD)}
    assert len(said) == 1, said
    monkeypatch.chdir(DOCS.parent)  # the frames' origins are relative to the working folder
    trace = tmp_path / "hour.jsonl"
    done = CliRunner().invoke(main, ["verify", "--scenario", "plc/scenarios/fx3u-healthy.toml", "--duration", "1h",
                                     "--trace", str(trace)])
    assert done.exit_code == 0, done.output
    assert round(trace.stat().st_size / 2**20, 1) == said.pop()


def test_ci_md_says_which_scenario_mistakes_only_verify_finds(tmp_path):
    """ci.md: `uitamr check` does not load the program, so a scenario naming a PROGRAM the
    sources do not define passes it; `uitamr verify` names it (exit 2) with the words the
    page quotes. The page named only labels, and an integrator took the passing check for
    a checked program name."""
    from click.testing import CliRunner

    from verifier.cli import main
    from verifier.verify.result import UnusableInput
    from verifier.verify.runner import run_scenario

    text = (DOCS / "ci.md").read_text(encoding="utf-8")
    quoted = re.search(r"`(no PROGRAM 'MIAN' in the sources)`", text)
    assert quoted, "ci.md does not say that verify, not check, finds a wrong program name"
    program = tmp_path / "MAIN.st"
    program.write_text("PROGRAM MAIN\nVAR\n    n : INT;\nEND_VAR\nn := n + 1;\nEND_PROGRAM\n", encoding="utf-8")
    scenario_text = f'sources = ["{program.as_posix()}"]\nprogram = "MIAN"\nduration = "1s"\n'
    (tmp_path / "s.toml").write_text(scenario_text, encoding="utf-8")
    checked = CliRunner().invoke(main, ["check", str(program), str(tmp_path / "s.toml")])
    assert checked.exit_code == 0, checked.output
    try:
        run_scenario(parse_scenario(scenario_text, tmp_path / "s.toml"))
    except UnusableInput as err:
        assert quoted.group(1) in str(err), str(err)
    else:
        raise AssertionError("verify ran a scenario whose PROGRAM does not exist")


def test_a_replay_trace_carries_a_tolerance_only_for_host_times_and_ends_with_the_end_record(tmp_path):
    """verifier.md, `--trace FILE`: a line's trace (monitor, replay) ends each run with an
    end record; a frame says its tolerance only when its times were judged with one, so a
    replay of `uitamr verify`'s exact trace writes none (the page said every frame has one)."""
    import json

    from click.testing import CliRunner

    from verifier.cli import main

    text = " ".join((DOCS / "verifier.md").read_text(encoding="utf-8").split())
    assert "none in a replay of an exactly timed trace" in text
    scenario = Path(__file__).resolve().parents[1] / "plc" / "scenarios" / "fx3u-healthy.toml"
    CliRunner().invoke(main, ["verify", "--scenario", str(scenario), "--duration", "2s",
                              "--trace", str(tmp_path / "v.jsonl")])
    replayed = CliRunner().invoke(main, ["replay", str(tmp_path / "v.jsonl"), "--trace", str(tmp_path / "r.jsonl")])
    assert replayed.exit_code == 0, replayed.output
    *frames, end = (json.loads(line) for line in (tmp_path / "r.jsonl").read_text(encoding="utf-8").splitlines())
    assert frames and all("dir" in f and "tolerance" not in f for f in frames)
    # the run's end is verify's (2 s of virtual time, not the last frame's), and the rules'
    # settings and the program's outputs verify recorded go on with it
    verified = (tmp_path / "v.jsonl").read_text(encoding="utf-8").splitlines()
    assert end == dict(json.loads(verified[-1]), scenario=end["scenario"]) and end["end"] == 2.0 > frames[-1]["t_end"]


def test_verifier_md_says_what_the_junit_of_a_run_that_cannot_start_holds():
    """The exit-code table said 'No report is written' for exit 2 after --junit came to
    list the mistakes; the --junit section is held to what report_junit writes, a mistake
    with a place and one without (`--program MIAN`: name `input`, no `file`)."""
    from verifier.place import Place
    from verifier.verify.report_junit import unusable_element
    from verifier.verify.result import Mistake

    section = " ".join(VERIFIER_MD.split("### `--junit FILE`", 1)[1].split("\n### ", 1)[0].split())
    (row,) = [line for line in VERIFIER_MD.splitlines() if line.startswith("| 2 | unusable input")]
    assert "`--junit`" in row and "(#--junit-file)" in row
    root = unusable_element([Mistake("s.toml:4:1: duraton: unknown key\nmore", Place("s.toml", 4, 1)),
                             Mistake("--program: no PROGRAM 'MIAN' in the sources")])
    placed, unplaced = root.findall("./testsuite/testcase")
    assert f"classname `{placed.get('classname')}`" in section
    assert f'<error type="{placed.find("error").get("type")}">' in section
    assert (placed.get("name"), placed.get("file"), placed.get("line")) == ("s.toml:4:1", "s.toml", "4")
    assert "name = its place `file:line:col`, `file` = the file it names and `line` its line" in section
    assert placed.find("error").get("message") == "s.toml:4:1: duraton: unknown key"  # the first line
    assert unplaced.get("name") == "input" and unplaced.get("file") is None
    assert "name `input` and no `file`" in section and "`--program MIAN`" in section
    replay = unusable_element([Mistake("c.txt:1:16: 'zz' is not a byte in hex", Place("c.txt", 1, 16))], "uitamr replay")
    assert f"classname `{replay.find('./testsuite/testcase').get('classname')}`" in section


def test_ci_md_github_job_publishes_every_junit_file_its_steps_write():
    """ci.md's GitHub job published `report_paths: verify.xml` while its --matrix step wrote
    verify-matrix.xml: the fault sets' results never reached the check run; and the matrix
    step, after a failed verify step, was skipped. Every --junit file of the GitHub section
    is matched by the report step's report_paths, and every step that writes one runs
    after a failure too."""
    from fnmatch import fnmatch

    text = (DOCS / "ci.md").read_text(encoding="utf-8")
    github = text.split("## GitHub Actions", 1)[1].split("\n## ", 1)[0]
    (paths,) = re.findall(r'^\s+report_paths: "?([^"\s]+)"?', github, re.M)
    written = re.findall(r"--junit (\S+)", github)
    assert {"verify.xml", "verify-matrix.xml"} <= set(written), written
    assert all(fnmatch(name, paths) for name in written), (paths, written)
    steps = [step for step in re.split(r"\n\s*- (?:name|uses|run):", github)
             if "--junit" in step or "report_paths" in step]
    for step in steps[1:]:  # each after the first verify step, which may fail
        assert re.search(r"if: (always\(\)|success\(\) \|\| failure\(\))", step), step
