"""docs/plc-library.md (and the pages that quote the library) stay true to it: its POU catalogue is what the
declarations say, and every error code the ST can produce is in its table."""
from __future__ import annotations

import re
from pathlib import Path

from verifier.export.catalogue import DOC, MARKER, catalogue

ROOT = Path(__file__).resolve().parents[1]


def test_catalogue_section_matches_the_declarations():
    text = DOC.read_text(encoding="utf-8")
    section = text.partition(MARKER)[2]
    generated = catalogue()
    assert generated.strip() in section, (
        "docs/plc-library.md is out of date: run `python -m verifier.export.catalogue --write`")


def test_a_summary_that_runs_over_two_header_lines_is_kept_whole():
    # "UITAMR_PortTcpFx5 : FX5U / FX5UC built-in Ethernet port for" goes on on the next line
    summaries = re.findall(r"^### .*\n\n(.*)\n", catalogue(), flags=re.MULTILINE)
    assert "FX5U / FX5UC built-in Ethernet port for UITAMR_Engine (socket communication, TCP client)." in summaries
    cut = [s for s in summaries if re.search(r"(,| for| and| of| the| a)\.$", s)]
    assert not cut, f"summaries cut in mid-sentence: {cut}"


def test_every_error_code_in_the_st_is_documented():
    codes = set()
    for path in (ROOT / "plc").rglob("*.st"):
        codes |= set(re.findall(r"ERR_[A-Z_]+ : WORD := (16#0[1-3][0-9A-F]{2})", path.read_text()))
    assert codes, "no error constants found"
    table = DOC.read_text(encoding="utf-8").partition("## Error codes")[2].partition("\n## ")[0]
    missing = sorted(c for c in codes if f"| {c} |" not in table)
    assert not missing, f"error codes not in docs/plc-library.md: {missing}"


def test_every_pou_file_is_named_after_its_pou():
    from verifier import st
    for path in (ROOT / "plc").rglob("*.st"):
        source = st.parse(path.read_text(), str(path))
        assert [p.name for p in source.pous] == [path.stem], path


def test_the_power_on_stop_goes_out_when_import_gxworks2_says():
    """docs/import-gxworks2.md §7: the stop goes out once the line was quiet for GUARD_TIME
    (the engine's ST), at 0.23 s in the bundled FX3U scenario, not in the second scan."""
    from dataclasses import replace

    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    doc = " ".join((ROOT / "docs" / "import-gxworks2.md").read_text(encoding="utf-8").split())
    claim = re.search(r"The engine sends the stop command once the line has been quiet for "
                      r"`GUARD_TIME` \((\d+) ms\) after RUN — at ([\d.]+) s with a 10 ms scan", doc)
    assert claim, "import-gxworks2.md §7 no longer says when the stop goes out"
    engine = (ROOT / "plc" / "core" / "UITAMR_Engine.st").read_text(encoding="utf-8")
    assert f"GUARD_TIME : TIME := T#{claim.group(1)}ms;" in engine
    scenario = load_scenario(ROOT / "plc" / "scenarios" / "fx3u-healthy.toml")
    result = run_scenario(replace(scenario, duration_us=1_000_000, expectations=()))
    first = result.trace[0]
    assert (first.direction, first.data.hex(" ").upper()) == ("tx", "01 06 01 A0 00 00 88 14")
    assert first.t_start_us == round(float(claim.group(2)) * 1e6)


def test_the_rs2_ports_say_in_which_scan_rs2_is_first_driven(tmp_path):
    """The FX3 and FX5 port FBs' headers say when RS2 is first driven relative to the
    settings they write (receive time-out, 16-bit mode, communication format): in the scan
    that writes them, after the writes - what the FB does, seen scan by scan."""
    import verifier

    for cpu, target, port, settings in (
            ("fx5u", "gxworks3", "fx5/UITAMR_PortFx5.st", {"SD8621": 5, "SD8622": 0}),
            ("fx3u", "gxworks2", "fx3/UITAMR_PortFx3.st", {"D8400": 0x1C81})):
        name = Path(port).stem
        main = tmp_path / f"Main{cpu}.st"
        main.write_text(f"PROGRAM Main{cpu}\nVAR\n    fbPort : {name};\n    uPort : ARRAY[0..39] OF WORD;\n"
                        "END_VAR\nfbPort(i_bEN := TRUE, i_wChannel := 1, io_uPort := uPort);\nEND_PROGRAM\n",
                        encoding="utf-8")
        project = verifier.load(str(ROOT / "plc" / "core"), str(ROOT / "plc" / port), str(main),
                                target=target, cpu=cpu)
        project.run_programs([f"Main{cpu}"], until_us=1)  # the first scan
        fb = project.program(f"Main{cpu}").fbPort
        assert fb.bConfigured and fb.bDriveCh1, name  # RS2 runs in this scan ...
        for device, value in settings.items():  # ... after the writes
            assert project.devices[device] == value, (name, device)
        header = " ".join((ROOT / "plc" / port).read_text(encoding="utf-8").split("*)", 1)[0].split())
        assert "RS2 is driven from that same scan on, after these writes" in header, name
        assert "from the next scan" not in (ROOT / "plc" / port).read_text(encoding="utf-8"), name


def test_how_the_pieces_fit_names_every_port_fb():
    """plc-library.md's overview shows where each port FB plugs in: an FX5U integrator on
    the TCP route finds UITAMR_PortTcpFx5 there, not only the serial ports."""
    text = DOC.read_text(encoding="utf-8")
    section = text.split("## How the pieces fit", 1)[1].split("### ", 1)[0]
    ports = sorted(p.stem for p in (ROOT / "plc").glob("*/UITAMR_Port*.st") if p.parent.name != "core")
    assert ports and [p for p in ports if p not in section] == []


def test_the_wiring_checklist_catches_a_port_that_reads_its_own_frame():
    """On two-wire RS-485 the FC06 request is byte for byte the robot's echo reply: a C24
    that receives its own transmission (an UNCONFIRMED QJ71C24N behaviour the simulator
    does not model) would see every command acknowledged with no robot. The checklist had
    no step that would catch it; now a bench step with the robot unplugged does, and says
    what is unconfirmed."""
    wiring = (ROOT / "docs" / "wiring-rs485.md").read_text()
    step = wiring.split("6. Once, with the pair unplugged at the robot", 1)[1]
    assert "16#0101" in step and "**UNCONFIRMED**" in step and "echo" in step


def test_the_library_page_leads_to_the_wiring_of_every_port():
    """Issue 6 asked docs/plc-library.md for the wiring of the FX3U-485-BD, the FX5U built-in
    port and the QJ71C24N-R4; it moved to wiring-rs485.md (and wiring-rs232.md), which the
    library page must still lead to, and which must still hold a section for each."""
    text = DOC.read_text(encoding="utf-8")
    for page, boards in {"wiring-rs485.md": ("FX3U-485-BD", "FX5U", "QJ71C24N-R4"),
                         "wiring-rs232.md": ("FX3U",)}.items():
        assert f"]({page})" in text.split("\n## ", 1)[0], f"plc-library.md's introduction does not link {page}"
        headings = [h for h in (ROOT / "docs" / page).read_text(encoding="utf-8").splitlines() if h.startswith("#")]
        assert all(any(board in h for h in headings) for board in boards), (page, headings)


def _constants(pou: str) -> dict[str, str]:
    """The named constants of a library POU as written (`T#500ms`, `16#0310`)."""
    text = (ROOT / "plc" / "core" / f"{pou}.st").read_text(encoding="utf-8")
    return dict(re.findall(r"^\s*(\w+) : \w+ := ([^;]+);", text, flags=re.M))


def _ms(value: str) -> int:
    number, unit = re.fullmatch(r"T#(\d+)(ms|s)", value).groups()
    return int(number) * (1000 if unit == "s" else 1)


def test_the_tcp_and_rs232_pages_quote_the_librarys_constants():
    """tcp-converter.md's connection handling and timing chart, and wiring-rs232.md's
    'everything else is the same', quote times and error codes that are constants of
    UITAMR_TcpLink and UITAMR_Engine: held here to the ST, so a changed constant changes
    the page."""
    link, engine = _constants("UITAMR_TcpLink"), _constants("UITAMR_Engine")
    tcp = " ".join((ROOT / "docs" / "tcp-converter.md").read_text(encoding="utf-8").split())
    back_off = [_ms(link[f"BACKOFF_{n}"]) for n in range(1, 6)]
    said = re.search(r"the next open follows after ([\d.]+) s, ([\d.]+) s, ([\d.]+) s, ([\d.]+) s and then every "
                     r"([\d.]+) s", tcp)
    assert said and [round(float(s) * 1000) for s in said.groups()] == back_off
    assert f"BACKOFF {back_off[0] / 1000} s→OPENING" in tcp  # the chart
    assert f"`RX_GAP_TIME` ({_ms(link['RX_GAP_TIME'])} ms)" in tcp
    assert tcp.count(f"`REPLY_TIMEOUT`, {_ms(engine['REPLY_TIMEOUT'])} ms") == 1
    assert tcp.count(f"`REPLY_TIMEOUT` ({_ms(engine['REPLY_TIMEOUT'])} ms)") == 2
    for name, said_as in [("ERR_OPEN", "a refused or unanswered open is {}"), ("ERR_LOST", "closing the connection is {}"),
                          ("ERR_NOT_CONNECTED", "is not sent: {}")]:
        assert said_as.format(link[name]) in tcp, name
    rs232 = " ".join((ROOT / "docs" / "wiring-rs232.md").read_text(encoding="utf-8").split())
    assert (f"the {_ms(engine['PACE_TIME'])} ms pace, the {_ms(engine['REPLY_TIMEOUT'])} ms reply time-out"
            in rs232)


def test_the_timing_chart_says_what_a_10ms_scan_puts_on_the_line():
    """plc-library.md's timing charts give the constants (300 ms pace, attempts 700 ms
    apart, 16#0101 at 1,900 ms); the simulation of the bundled examples at their 10 ms scan
    shows 310 ms, 720 ms and 1,940 ms (a timer is seen done in the scan after its time, the
    port sends in the scan after the engine asked), and 630 ms on the ADPRW route. The page
    now says so with the figures held here to `uitamr verify` runs, and fx3u-no-reply's
    description, which said 700 ms, to the same figure."""
    from dataclasses import replace

    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    text = " ".join(DOC.read_text(encoding="utf-8").split())
    said = re.search(r"requests start (\d+) ms apart; a silent robot gets its attempts (\d+) ms apart .*?"
                     r"the command ends ([\d,]+) ms after the first attempt went out .*? in `fx3u-no-reply`, "
                     r"and the same on every RS2, C24 and TCP route \(([^)]*)\)\. On an ADPRW route .*? "
                     r"(\d+) ms apart, and the command ends \(16#0108\) ([\d,]+) ms after the first "
                     r"\(`fx3u-adprw-no-reply`\)", text)
    assert said, "plc-library.md no longer says what a 10 ms scan puts on the line"
    pace, attempts, ends, others, adp_attempts, adp_ends = said.groups()
    routes = {"fx3u-no-reply": (int(attempts), int(ends.replace(",", "")))}
    routes |= {name: routes["fx3u-no-reply"] for name in re.findall(r"`([\w-]+)`", others)}
    routes["fx3u-adprw-no-reply"] = (int(adp_attempts), int(adp_ends.replace(",", "")))
    assert len(routes) == 6
    for name, (apart, ended) in routes.items():
        scenario = load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")
        assert scenario.scan_us == 10_000, name
        result = run_scenario(replace(scenario, duration_us=7_000_000, expectations=()))
        sent = [r.t_start_us for r in result.trace if r.direction == "tx"]
        gaps = [(b - a) // 1000 for a, b in zip(sent, sent[1:])]
        assert set(gaps) == {int(pace), apart}, (name, sorted(set(gaps)))
        first_unanswered = sent[gaps.index(apart)]
        # to the scan: on the TCP route the trace has each frame on the robot's line, after
        # the converter's delay (2 ms in the *-tcp-no-reply scenarios)
        assert round((result.signal_held[0][0] - first_unanswered) / 1000, -1) == ended, name
    description = load_scenario(ROOT / "plc" / "scenarios" / "fx3u-no-reply.toml").description
    assert f"{attempts} ms apart" in description


def test_0304_is_named_as_the_port_headers_name_it_and_looks_like_a_silent_robot():
    """16#0304 is "invalid channel" in the serial ports' headers and "invalid connection
    number" in the TCP ports'; plc-library.md's table and commissioning.md named only the
    channel, so an FX5U/E71 integrator with connection 9 read of a channel they never set.
    Both pages now name both, and what commissioning.md says the engine shows (16#0101,
    detail 1, nothing sent) is what an FX5U engine behind either port shows."""
    import verifier

    meanings = set()
    for path in (ROOT / "plc").rglob("UITAMR_Port*.st"):
        header = " ".join(path.read_text(encoding="utf-8").split("*)", 1)[0].split())
        meanings |= set(re.findall(r"16#0304 (invalid [a-z]+(?: number)?)", header))
    assert meanings == {"invalid channel", "invalid connection number"}
    row = re.search(r"^\| 16#0304 \|(.*)$", DOC.read_text(encoding="utf-8"), flags=re.M).group(1)
    commissioning = " ".join((ROOT / "docs" / "commissioning.md").read_text(encoding="utf-8").split())
    said = re.search(r"the port FB's `o_uErrId` 16#0304: ([^.]*)\.", commissioning).group(1)
    for meaning in meanings:
        assert meaning in row and meaning.split(" ", 1)[1] in said, meaning
    for port, argument in (("UITAMR_PortFx5", "i_wChannel := 3"),
                           ("UITAMR_PortTcpFx5", "i_wConnection := 9, i_udIpAddress := 16#C0A80332, "
                                                 "i_uTcpPort := 4001, i_uLocalPort := 5000")):
        harness = (f"PROGRAM T_Bad\nVAR\n    fbPort : {port};\n    fbEngine : UITAMR_Engine;\n"
                   "    uMbx : ARRAY[0..15] OF WORD;\n    uPort : ARRAY[0..39] OF WORD;\nEND_VAR\n"
                   f"fbPort(i_bEN := TRUE, {argument}, io_uPort := uPort);\n"
                   "fbEngine(i_bEN := NOT SM402, i_wAddress := 1, i_bMonitor := FALSE, io_uMbx := uMbx, "
                   "io_uPort := uPort);\nEND_PROGRAM\n")
        project = verifier.load(ROOT / "plc" / "core", ROOT / "plc" / "fx5", sources={"T_Bad.st": harness},
                                target="gxworks3", cpu="fx5u")
        project.run_programs(["T_Bad"], until_us=3_000_000)
        bad = project.program("T_Bad")
        assert (bad.fbPort.o_uErrId, bad.fbEngine.o_uErrId, bad.fbEngine.o_uErrDetail) == (0x0304, 0x0101, 1), port


def test_the_tcp_examples_name_the_details_the_engine_gets_from_the_tcp_link():
    """The TCP examples' headers said commands end with 16#0108 "detail 16#0310..16#0314",
    but UITAMR_TcpLink hands the engine only 16#0311, 16#0312 and 16#0314 (a refused open
    and a failed receive never fail an attempt; 16#0310 and 16#0313 are the port's own
    o_uErrId). The headers and plc-library.md's 16#0108 row now name the codes the ST
    hands over, and the bundled refused-converter runs show the engine's detail among them."""
    from dataclasses import replace

    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    link = (ROOT / "plc" / "core" / "UITAMR_TcpLink.st").read_text(encoding="utf-8")
    constants = _constants("UITAMR_TcpLink")
    handed = {int(constants[name][3:], 16) for name in re.findall(r"uHeldErr := (ERR_\w+);", link)} - {0}
    assert handed == {0x0311, 0x0312, 0x0314}

    def codes(text: str) -> set[int]:
        return {int(c, 16) for c in re.findall(r"16#(03[0-9A-F]{2})", text)}

    for example in ("fx5/UITAMR_ExampleTcpFx5.st", "q/UITAMR_ExampleTcpQ.st"):
        header = " ".join((ROOT / "plc" / "examples" / example).read_text(encoding="utf-8").split("*)", 1)[0].split())
        said = re.search(r"ends with 16#0108 \(D102\), the engine's detail being (.*?); the port's own code", header)
        assert said and codes(said.group(1)) == handed, example
    row = re.search(r"^\| 16#0108 \|[^|]*\|([^|]*)\|", DOC.read_text(encoding="utf-8"), flags=re.M).group(1)
    in_row = {int(c, 16) for c in re.findall(r"(?:16#|/)(03[0-9A-F]{2})", row)}  # "16#0311/0312/0314"
    assert {c for c in in_row if 0x0310 <= c <= 0x031F} == handed
    for name in ("fx5u-tcp-refused", "q-tcp-refused"):
        scenario = load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")
        result = run_scenario(replace(scenario, duration_us=8_000_000, expectations=(),
                                      watch=("fbEngine.o_uErrId", "fbEngine.o_uErrDetail")))
        ids = result.watched["fbEngine.o_uErrId"]

        def id_at(t_us: int) -> int:  # the error id in force when the detail was sampled
            return [value for t, value in ids if t <= t_us][-1]

        details = {value for t, value in result.watched["fbEngine.o_uErrDetail"] if id_at(t) == 0x0108}
        assert details and details <= handed, (name, details)


def test_a_command_fb_lists_0301_only_if_it_has_a_parameter_to_refuse():
    """Every command FB's header listed "16#0301 parameter out of range", UITAMR_Stop's and
    UITAMR_Pause's too, which have no parameter and call UITAMR_Command with
    i_bParamErr := FALSE: an integrator looked for a parameter that is not there. Now a
    wrapper's header names 16#0301 exactly when it can report it."""
    wrappers = [p for p in (ROOT / "plc" / "core").glob("UITAMR_*.st")
                if "fbCmd : UITAMR_Command;" in p.read_text(encoding="utf-8")]
    assert len(wrappers) == 10
    for path in wrappers:
        text = path.read_text(encoding="utf-8")
        header, body = text.split("*)", 1)
        checks = "i_bParamErr := FALSE" not in body
        assert ("16#0301" in header.split("Outputs:", 1)[1].replace("never 16#0301", "")) == checks, path.name


def test_the_error_table_says_where_a_wrappers_detail_is():
    """The error table's detail column is headed `o_uErrDetail`, which no wrapper
    (UITAMR_RunPoint ...) has: their detail is in their UITAMR_Command instance fbCmd. The
    page now says so, and it names the instance the wrappers really hold."""
    wrappers = []
    for path in (ROOT / "plc" / "core").glob("UITAMR_*.st"):
        text = path.read_text(encoding="utf-8")
        if "fbCmd : UITAMR_Command;" in text:
            wrappers.append(path.stem)
            assert "o_uErrDetail" not in text.split("*)", 1)[1], path.stem
    assert len(wrappers) == 10
    table = " ".join(DOC.read_text(encoding="utf-8").partition("## Error codes")[2].partition("| code |")[0].split())
    assert "their internal instance `fbCmd`" in table and "`fbRun.fbCmd.o_uErrDetail`" in table


def test_the_fx3_example_says_how_to_set_bUseRs232_as_wiring_rs232_does():
    """UITAMR_ExampleFx3's label comment said "(set before RUN)", while wiring-rs232.md says
    to assign it above the fbPort call (the port reads it in its first scan only; GX Works2
    has no initial value for the label). The example now says what the page says."""
    example = (ROOT / "plc" / "examples" / "fx3" / "UITAMR_ExampleFx3.st").read_text(encoding="utf-8")
    page = " ".join((ROOT / "docs" / "wiring-rs232.md").read_text(encoding="utf-8").split())
    assert "with an assignment above the `fbPort` call (`bUseRs232 := TRUE;`" in page
    assert "set before RUN" not in example
    comment = re.search(r"bUseRs232 : BOOL; +\(\* (.*) \*\)", example).group(1)
    assert "assignment above the fbPort call" in comment
    assert "bUseRs232 := TRUE; (or an input already ON at RUN) above the fbPort call" in " ".join(
        example.split("*)", 1)[0].split())


def test_the_engine_header_gives_every_detail_the_error_table_gives():
    """The error table gives a detail for 16#0101 (1 = the port never finished sending),
    16#0105 (length or byte count), 16#0108 (the port's code) and 16#0301 (the kind or the
    code); UITAMR_Engine's header, which an integrator reads in GX Works, named none of those
    for o_uErrDetail. It now names each, as the table does."""
    engine = (ROOT / "plc" / "core" / "UITAMR_Engine.st").read_text(encoding="utf-8")
    header = " ".join(engine.split("*)", 1)[0].split())
    detail = header.split("o_uErrDetail", 1)[1].split("o_bReady", 1)[0]
    table = DOC.read_text(encoding="utf-8").partition("## Error codes")[2]
    assert "| 16#0101 | no reply after 3 attempts | 1 = the port never finished sending |" in table
    for said in ("1 = the port never finished sending", "length or byte count", "port code (16#0108)",
                 "kind or code (16#0301)", "exception code", "robot code", "the address out of range"):
        assert said in detail, said


def test_plc_readme_names_the_rs485_boards_the_fx3_port_drives():
    """plc/README.md's first row read "FX3U / FX3G + FX3U-485-BD": an FX3G takes the
    FX3G-485-BD, and UITAMR_PortFx3's header names that board and the FX3U-485ADP as RS2
    channels too. The row now names every RS-485 board or adapter the port's header does."""
    header = " ".join((ROOT / "plc" / "fx3" / "UITAMR_PortFx3.st").read_text(encoding="utf-8").split("*)", 1)[0].split())
    boards = set(re.findall(r"\bFX3[UG]-485(?:-BD|ADP)\b(?!-)", header))
    assert boards == {"FX3U-485-BD", "FX3G-485-BD", "FX3U-485ADP"}
    readme = (ROOT / "plc" / "README.md").read_text(encoding="utf-8")
    row = next(line for line in readme.splitlines() if line.startswith("| FX3U / FX3G "))
    assert "UITAMR_PortFx3.st" in row and "i_bRs232" not in row
    assert {board for board in boards if board not in row} == set()


def test_what_says_the_panel_has_every_command_fb_names_the_one_it_has_not():
    """UITAMR_PanelFx3 was "every command FB on push buttons" (its header, the catalogue,
    plc-library.md's layout and fault coverage, its scenario's name), but it has no
    UITAMR_RunPoint: an engineer looked there for the point run. Every such claim now names
    the command FB the panel lacks, taken here from the declarations."""
    import tomllib

    from verifier import st

    wrappers = {p.stem for p in (ROOT / "plc" / "core").glob("UITAMR_*.st")
                if "fbCmd : UITAMR_Command;" in p.read_text(encoding="utf-8")}
    panel_path = ROOT / "plc" / "examples" / "fx3" / "UITAMR_PanelFx3.st"
    (panel,) = st.parse(panel_path.read_text(encoding="utf-8"), str(panel_path)).pous
    used = {getattr(label.type, "name", "") for block in panel.var_blocks for label in block.variables}
    lacking = sorted(wrappers - used)
    assert len(wrappers) == 10 and lacking == ["UITAMR_RunPoint"]
    scenario = tomllib.loads((ROOT / "plc" / "scenarios" / "fx3u-panel-all-commands.toml").read_text(encoding="utf-8"))
    text = DOC.read_text(encoding="utf-8")
    claims = [panel_path.read_text(encoding="utf-8").splitlines()[1], scenario["name"],
              *[line for line in text.splitlines() if "every command FB" in line]]
    assert len(claims) >= 5  # header, scenario, layout row, coverage row, catalogue
    for claim in claims:
        assert all(name.removeprefix("UITAMR_") in claim for name in lacking), claim


def test_the_unit_of_the_fx3_receive_time_out_is_given_as_an_assumption_wherever_it_is_given():
    """plc-library.md marks D8409's 10 ms unit an ASSUMPTION (no manual page gives it);
    UITAMR_PortFx3's constant said "D8409: 5 x 10 ms = 50 ms" as a fact, and that comment
    is what the GX Works label table shows. Every line of plc/ that gives the unit now
    says it is an assumption."""
    stated = []
    for path in sorted((ROOT / "plc").rglob("*")):
        if path.suffix not in (".st", ".il", ".toml"):
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            if re.search(r"D8[34]29|D8409", line) and re.search(r"10 ms|x 10\b", line):
                stated.append((f"{path.relative_to(ROOT)}:{number}", "ASSUMPTION" in line))
    assert any(place.startswith("plc/fx3/UITAMR_PortFx3.st") for place, _ in stated)
    assert [place for place, marked in stated if not marked] == []


def test_the_choice_table_gives_the_constants_defaults_as_the_st_declares_them():
    """plc-library.md, "The manual's [choice]s, one constant each": every constant it names
    is declared in the POU it names, with the default it gives (TRUE/FALSE, the times and
    counts in order, the first command's code/command) - a changed default changes the page."""
    section = DOC.read_text(encoding="utf-8").partition("## The manual's [choice]s")[2].partition("\n## ")[0]
    rows = re.findall(r"^\| [^|]+ \| (`[^|]+) \| `(UITAMR_\w+)` \| ([^|]+) \|$", section, flags=re.M)
    assert len(rows) == 7, rows
    for names_cell, pou, default in rows:
        names = re.findall(r"`(\w+)`", names_cell)
        constants = _constants(pou)
        values = [constants[name] for name in names]
        said = re.findall(r"\d+ ms|\b\d+\b|TRUE|FALSE", default.split("(")[0])
        if names == ["CMD_STOP"]:  # "`CMD_STOP` (01/A0)": the code is the engine's CODE_ROBOT
            code, command = re.search(r"\((\w\w)/(\w\w)\)", names_cell).groups()
            assert (constants["CODE_ROBOT"], constants["CMD_STOP"]) == (str(int(code, 16)), f"16#{command}")
            continue
        written = [f"{_ms(v)} ms" if v.startswith("T#") else v for v in values]
        assert said == written, (names, default, values)


def test_import_gxworks2_registers_every_program_it_exports():
    """import-gxworks2.md §4 said to register "`UITAMR_ExampleFx3` or `UITAMR_ExampleQ`":
    an integrator with the ADPRW adapter, the panel or the QJ71E71-100 found no word about
    the program they had created. The step now names every PROGRAM the GX Works2 export
    writes, as the declarations say."""
    from verifier import st

    programs = set()
    for folder in ("fx3", "q"):
        for path in (ROOT / "plc" / "examples" / folder).glob("*.st"):
            programs |= {p.name for p in st.parse(path.read_text(encoding="utf-8"), str(path)).pous
                         if p.kind == "PROGRAM"}
    text = " ".join((ROOT / "docs" / "import-gxworks2.md").read_text(encoding="utf-8").split())
    step = text.split("## 4. Programs and tasks", 1)[1].split("## 5.", 1)[0]
    assert len(programs) == 6 and set(re.findall(r"`(UITAMR_\w+)`", step)) == programs


def test_the_label_prefixes_are_the_type_letters_the_library_page_lists():
    """plc-library.md listed the type letters of the i_/o_/io_ labels as "b Bit, w
    Word[Signed], u Word[Unsigned], e FLOAT, t Time", while the TCP ports take
    `i_udIpAddress` (a DWORD) and `i_sUnit` (a STRING): an integrator naming their own
    labels by the page had no letter for either. The list now has them, and every
    interface label of plc/ carries the letters of its type as the GX Works2 table names it."""
    from verifier import st
    from verifier.export.types import TABLES

    text = " ".join(DOC.read_text(encoding="utf-8").split())
    listed = re.search(r"\(`i_`/`o_`/`io_` \+ type letters: (.*?)\) and GX Works' naming rules", text).group(1)
    letters = dict(item.split(" ", 1) for item in listed.split(", "))
    used = set()
    for path in (ROOT / "plc").rglob("*.st"):
        for pou in st.parse(path.read_text(encoding="utf-8"), str(path)).pous:
            for block in pou.var_blocks:
                if block.keyword not in ("VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT"):
                    continue
                for label in block.variables:
                    prefix = re.match(r"(?:i|o|io)_([a-z]+)[A-Z]", label.name).group(1)
                    used.add(prefix)
                    declared = getattr(label.type, "element", label.type)
                    name = "STRING" if type(declared).__name__ == "StringType" else declared.name
                    editor = TABLES["gxworks2"][name]
                    assert prefix in letters and editor.startswith(letters[prefix]), (pou.name, label.name, editor)
    assert {"ud", "s"} <= used


def test_the_fx5_port_names_for_channel_2_the_board_the_rs2_model_has_there():
    """UITAMR_PortFx5's header put "FX5-485-BD / FX5-485ADP" on serial channel 2, while
    instructions.md §8 gives the simulator's channel 2 as the FX5-485-BD and the FX5
    special relay list it cites has channels up to ch4 (the adapters'): an integrator with
    an FX5-485ADP set i_wChannel := 2 for a port on ch3/ch4. The header now names only the
    board for channel 2 and says the adapter is not driven, as instructions.md does."""
    header = " ".join((ROOT / "plc" / "fx5" / "UITAMR_PortFx5.st").read_text(encoding="utf-8").split("*)", 1)[0].split())
    channel_2 = re.search(r"serial channel 1 \(the FX5U built-in RS-485 port\) or 2 \(([^)]*)\)", header).group(1)
    model = (ROOT / "docs" / "instructions.md").read_text(encoding="utf-8")
    heading = re.search(r"^## 8\. RS2 — FX5 \(built-in RS-485 / ([^)]*)\), channel `fx5:1` / `fx5:2`$", model,
                        flags=re.M).group(1)
    assert channel_2 == f"an {heading}"
    assert "An FX5-485ADP is not channel 2 but 3 or 4, which this FB does not drive" in header
    section = " ".join(model.split("## 8. ", 1)[1].split("\n## ", 1)[0].split())
    assert "an FX5-485ADP needs a port FB with the ch3/ch4 devices" in section


def test_an_example_with_a_pause_gives_the_reason_to_call_it_every_scan_the_library_gives():
    """review s35: the FX5U/Q examples (pausewire35) told the integrator a pause not called
    when its result comes 'blocks the stop' - true before 11060eb, merged alongside: the
    stop now takes the priority slot over and the pause loses its result (16#0316), as
    UITAMR_Pause's header says. An example copied for its comments must not teach the old
    reason."""
    examples = sorted((ROOT / "plc" / "examples").rglob("*.st"))
    headers = {p.name: " ".join(p.read_text(encoding="utf-8").split("*)")[0].split()) for p in examples
               if ": UITAMR_Pause;" in p.read_text(encoding="utf-8")}
    assert len(headers) == 7              # UITAMR_CellFx3, PanelFx3 and the five FX5U/Q examples
    for name, header in headers.items():
        assert "blocks the stop" not in header, name
        if "not called when its result comes" in header:
            assert "16#0316" in header, name
