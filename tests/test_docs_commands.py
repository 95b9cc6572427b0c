"""The `uitamr` commands the user-facing pages show are commands the tool takes, and every
option of a command is in the page about it.

Each command line in a code block of these pages (a shell line, a `$ ` session, a GitHub
Actions or GitLab step, a Jenkins `sh`, a VS Code task) and each concrete one in inline
code is parsed by the command itself, as the shell would hand it over: an option that was
renamed or dropped, a choice that is no longer one, a missing value fails here rather than
in an integrator's CI. Running them needs hardware or the integrator's files; the pages'
`uitamr frame` sessions are run by test_protocol_docs.py, the emulator's bench recipe by
test_emulator_bench_recipe below.
"""
from __future__ import annotations

import re
import shlex
from pathlib import Path

import click
import pytest

from doc_helpers import code_blocks
from verifier.cli import main

ROOT = Path(__file__).resolve().parents[1]
PAGES = ["README.md", "README.zh-TW.md", "docs/commissioning.md", "docs/emulator.md", "docs/wiring-rs485.md",
         "docs/wiring-rs232.md", "docs/ci.md", "docs/verifier.md", "docs/protocol.md", "docs/import-gxworks2.md",
         "docs/import-gxworks3.md", "docs/scenarios.md", "docs/tcp-converter.md", "plc/README.md"]
SHELL_ENDS = {">", ">>", "|", "&", "&&", ";"}


def _command(name: str) -> click.Command | None:
    return main.get_command(click.Context(main), name)


def _block_commands(block: str) -> list[str]:
    """The `uitamr ...` command lines of one code block, continuation lines joined."""
    lines = block.splitlines()
    found, index = [], 0
    while index < len(lines):
        line = lines[index]
        folded = re.match(r"(\s*)(?:- |run: )>\s*$", line)  # a YAML folded scalar
        if folded:
            parts = []
            index += 1
            while index < len(lines) and (not lines[index].strip()
                                          or len(lines[index]) - len(lines[index].lstrip()) > len(folded.group(1))):
                parts.append(lines[index].strip())
                index += 1
            text = " ".join(part for part in parts if part)
            if text.startswith("uitamr "):
                found.append(text)
            continue
        quoted = re.search(r"""(?:sh '|"command": ")(uitamr [^'"]*)""", line)
        plain = re.match(r"\s*(?:\$ |- |run: )?(uitamr .*)", line)
        if quoted or plain:
            text = (quoted or plain).group(1)
            while text.endswith("\\") and index + 1 < len(lines):
                index += 1
                text = text[:-1] + " " + lines[index].strip()
            found.append(text)
        index += 1
    return found


def _inline_commands(text: str) -> list[str]:
    """Inline `uitamr ...` code that is a whole command: no placeholders (SOURCES, PORT),
    no elisions, not a quoted message (`uitamr replay: site.txt:...`)."""
    found = []
    for span in re.findall(r"`(uitamr [^`]+)`", text):
        words = span.split()
        if (words[1].endswith(":") or "..." in span or "…" in span or re.search(r"[^\x00-\x7f]", span)
                or any(re.fullmatch(r"\[?[A-Z][A-Z_:.]+\]?(\.\.\.)?", word) for word in words[1:])):
            continue
        found.append(span)
    return found


def _words(line: str) -> list[str]:
    """A shell line's words, up to a comment, redirection, pipe or `&`."""
    lexer = shlex.shlex(line, posix=True, punctuation_chars="|&;<>")
    lexer.whitespace_split = True
    lexer.commenters = "#"
    words = []
    for token in lexer:
        if token in SHELL_ENDS:
            break
        words.append(token)
    return words


def _argv(command: str) -> list[str]:
    """The arguments after `uitamr`."""
    words = _words(command)
    assert words[0] == "uitamr", command
    return words[1:]


def _quoted_commands() -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """(page, command) of the code blocks' command lines, and of inline code."""
    blocks, inline = [], []
    for page in PAGES:
        text = (ROOT / page).read_text(encoding="utf-8")
        for block in code_blocks(text):
            blocks += [(page, command) for command in _block_commands(block)]
        inline += [(page, command) for command in _inline_commands(text)]
    return blocks, inline


QUOTED, INLINE = _quoted_commands()


def test_the_pages_quote_commands():
    """The extraction finds what it must: a failure here is the parser's, not the pages'."""
    pages = {page for page, _ in QUOTED + INLINE}
    assert {"docs/ci.md", "docs/emulator.md", "docs/commissioning.md", "docs/verifier.md", "docs/protocol.md",
            "docs/wiring-rs485.md"} <= pages
    commands = [command for _, command in QUOTED]
    assert any(c.startswith("uitamr verify plc/*.st --program MAIN --platform fx3u --scenario verify/healthy.toml "
                            "--scenario verify/no-reply.toml --jobs 2") for c in commands)  # the folded YAML step
    assert any("--response-signal" in c for c in commands)
    assert "uitamr check --platform fx3u plc verify/*.toml" in commands  # the VS Code task
    assert len(QUOTED) >= 30 and len(INLINE) >= 30


@pytest.mark.parametrize("page, command", QUOTED, ids=[f"{p}: {c}" for p, c in QUOTED])
def test_a_command_line_of_a_page_is_one_the_tool_takes(page, command):
    """A whole command line: its options, their values and its arguments, as click reads them."""
    argv = _argv(command)
    sub = _command(argv[0])
    assert sub is not None, f"{page}: `{command}`: uitamr has no command {argv[0]!r}"
    try:
        sub.make_context(f"uitamr {argv[0]}", argv[1:])
    except click.UsageError as err:
        pytest.fail(f"{page}: `{command}`: {err.format_message()}")


@pytest.mark.parametrize("page, command", INLINE, ids=[f"{p}: {c}" for p, c in INLINE])
def test_a_command_named_in_the_text_has_the_options_it_is_named_with(page, command):
    """Inline code names a command, often not a whole one (`uitamr replay`, `uitamr emulate
    --tcp`): its command and options must exist, and a choice given must be one."""
    argv = _argv(command)
    sub = _command(argv[0])
    assert sub is not None, f"{page}: `{command}`: uitamr has no command {argv[0]!r}"
    options = {opt: param for param in sub.params if isinstance(param, click.Option) for opt in param.opts}
    for index, word in enumerate(argv[1:], start=1):
        if not word.startswith("--"):
            continue
        assert word in options, f"{page}: `{command}`: uitamr {argv[0]} has no option {word}"
        param = options[word]
        if isinstance(param.type, click.Choice) and index + 1 < len(argv):
            assert argv[index + 1] in param.type.choices, f"{page}: `{command}`: {argv[index + 1]!r} is not a choice"


# The page that documents each command's options. `monitor` and `replay` refer to the
# protocol options as "`--address`, `--field-order`, ... as `uitamr frame`".
OPTION_PAGES = {
    "verify": ["docs/verifier.md"],
    "check": ["docs/ci.md", "docs/st-dialect.md"],
    "frame": ["docs/protocol.md"],
    "monitor": ["docs/commissioning.md"],
    "replay": ["docs/commissioning.md"],
    "emulate": ["docs/emulator.md"],
    "export": ["docs/import-gxworks2.md", "docs/import-gxworks3.md", "README.md"],
}
PROTOCOL_OPTIONS = {"--address", "--field-order", "--codes-10-13", "--status-order", "--manual-stop-counts-as-stop"}


@pytest.mark.parametrize("name", sorted(OPTION_PAGES))
def test_every_option_of_a_command_is_in_its_page(name):
    command = _command(name)
    text = "\n".join((ROOT / page).read_text(encoding="utf-8") for page in OPTION_PAGES[name])
    options = {opt for param in command.params if isinstance(param, click.Option)
               for opt in param.opts if opt.startswith("--")} - {"--help"}
    if name in ("monitor", "replay"):
        assert "| `--address`, `--field-order`, ... | as `uitamr frame` |" in text
        options -= PROTOCOL_OPTIONS
    missing = sorted(opt for opt in options if not re.search(rf"(?<![\w-]){re.escape(opt)}(?![\w-])", text))
    assert not missing, f"uitamr {name} has options that {', '.join(OPTION_PAGES[name])} do not name: {missing}"


@pytest.mark.serial
def test_emulator_bench_recipe(tmp_path):
    """emulator.md, "Testing without hardware", run as the page gives it (its /tmp links
    moved into the test's folder): socat's pty pair, the emulator on one end, the three
    mbpoll commands on the other; the stop and the point command are written, the
    status read shows coil 17 = 1 (running), and `kill %2` (SIGTERM) ends the emulator with
    its summary line and status 0, as the page says. (socat killed first: status 1,
    test_emulate_ports.py's test_an_adapter_unplugged_mid_run_...)"""
    import os
    import subprocess
    import sys
    import time

    text = (ROOT / "docs" / "emulator.md").read_text(encoding="utf-8")
    block = text.split("## Testing without hardware", 1)[1].split("```sh\n", 1)[1].split("```", 1)[0]
    lines = [line.replace("/tmp/robot", str(tmp_path / "robot")).replace("/tmp/plc", str(tmp_path / "plc"))
             for line in block.splitlines() if line.strip()]
    socat_line, emulate_line, *mbpoll_lines = lines
    assert socat_line.startswith("socat -d -d pty,raw,echo=0,") and emulate_line.startswith("uitamr emulate --serial")
    assert len(mbpoll_lines) == 3 and all(line.startswith("mbpoll ") for line in mbpoll_lines)
    socat = subprocess.Popen(_words(socat_line), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    emulator = None
    try:
        deadline = time.monotonic() + 15
        while not ((tmp_path / "robot").exists() and (tmp_path / "plc").exists()):
            assert socat.poll() is None and time.monotonic() < deadline, "socat made no pty pair"
            time.sleep(0.02)
        emulator = subprocess.Popen([sys.executable, "-m", "verifier.cli", *_argv(emulate_line)],
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                    env={**os.environ, "PYTHONUNBUFFERED": "1"})
        assert "listening on serial" in emulator.stdout.readline()
        outputs = []
        for line in mbpoll_lines:
            done = subprocess.run(_words(line), capture_output=True, text=True, timeout=30)
            assert done.returncode == 0, (line, done.stdout, done.stderr)
            outputs.append(done.stdout)
        assert "Written 1 references." in outputs[0] and "Written 1 references." in outputs[1]
        coils = dict(re.findall(r"^\[(\d+)\]:\s+(\d)", outputs[2], flags=re.M))
        assert len(coils) == 22 and coils["17"] == "1", outputs[2]  # running: point 3 was started
        # "`kill %2` stops the emulator (it prints its summary line and exits with status 0)"
        emulator.terminate()
        out = emulator.communicate(timeout=15)[0]
        assert emulator.returncode == 0, out
        assert out.splitlines()[-1].startswith("uitamr emulate: stopped after "), out
        assert "3 frames in, 3 replies out, 0 unanswered" in out.splitlines()[-1], out
    finally:
        for process in (emulator, socat):
            if process is not None and process.poll() is None:
                process.terminate()
                process.wait(timeout=15)


def _python_blocks(page: str) -> list[str]:
    return code_blocks((ROOT / "docs" / page).read_text(encoding="utf-8"), "python")


def test_the_python_examples_of_verifier_md_run(monkeypatch):
    """verifier.md, "Using it from Python": the example runs (its own assert is the check),
    and a trace from elsewhere is judged with the classes and fields the page names."""
    from types import SimpleNamespace

    monkeypatch.chdir(ROOT)
    (block,) = _python_blocks("verifier.md")
    exec(compile(block, "verifier.md", "exec"), {})
    text = " ".join((ROOT / "docs" / "verifier.md").read_text(encoding="utf-8").split())
    said = re.search(r"build `([\w.]+)\.RunEvidence\(settings, frames, end_us\)`.* from objects with "
                     r"`t_start_us`, `t_end_us`, `direction` \(`\"tx\"` or `\"rx\"`\), `data` \(bytes\), `origin`\.",
                     text)
    assert said, "verifier.md no longer says how to build the evidence"
    import importlib

    from verifier.protocol import Settings
    from verifier.verify.rules import check_all

    evidence_class = importlib.import_module(said.group(1)).RunEvidence
    run_point = bytes.fromhex("01 06 01 01 00 00 D9 F6")
    frames = [SimpleNamespace(t_start_us=0, t_end_us=8_333, direction="tx", data=run_point, origin=None),
              SimpleNamespace(t_start_us=13_000, t_end_us=21_333, direction="rx", data=run_point, origin=None)]
    found = check_all(evidence_class(Settings(), frames, 1_000_000))
    assert [rule for rule, violations in found.items() if violations] == ["UITAMR-POWERON-STOP"]


def test_the_python_example_of_protocol_md_gives_what_its_comments_say():
    (block,) = [b for b in _python_blocks("protocol.md") if "from verifier.protocol import" in b]
    imports, lines = block.split("\n\n", 1)
    names: dict = {}
    exec(imports, names)
    results = []
    for line in lines.splitlines():
        code, _, comment = line.partition("#")
        if "=" in code.split("(")[0]:
            exec(code, names)
        else:
            results.append((eval(code, names), comment.strip()))
    assert [comment for _, comment in results] == [
        r"b'\x01\x06\x01\xa0\x00\x00\x88\x14'", "StatusRequest(1, Query.TASK)", "'stop (01/A0)'",
        "ControlRequest(1, MOVE_FRONT_NEG, 25)"]
    encoded, status, described, move = (value for value, _ in results)
    assert repr(encoded) == results[0][1] and repr(described) == results[2][1]
    assert (status.address, status.query.name) == (1, "TASK")
    assert (move.address, move.code.name, move.command) == (1, "MOVE_FRONT_NEG", 25)


def test_the_fault_defaults_emulator_md_gives_are_the_codes():
    """emulator.md's fault table gave the exception's default code but not the garbage
    bytes `--garbage-on N` sends (A5 5A FF, as its `-- scripted fault:` line shows)."""
    from verifier.amr.faults import Fault

    rows = {row.split("|")[1].strip(): row for row in (ROOT / "docs" / "emulator.md").read_text(encoding="utf-8")
            .splitlines() if row.startswith("| `")}
    garbage = Fault("garbage", on_request=1)
    assert f"`data` bytes (default `{garbage.data.hex(' ').upper()}`)" in rows["`garbage`"]
    assert f'`"{garbage.position}"`, the default' in rows["`garbage`"]
    assert f"`code` (default {Fault('exception', on_request=1).code:02d})" in rows["`exception`"]


def test_the_reply_lateness_emulator_md_gives_is_how_often_the_emulator_looks():
    """emulator.md gave `--turnaround-ms` as the time to the reply; on the wall clock the
    reply goes out when the serving loop next looks, up to ports.POLL_S later."""
    from verifier.emulate.ports import POLL_S

    text = " ".join((ROOT / "docs" / "emulator.md").read_text(encoding="utf-8").split())
    assert (f"a reply goes out up to {POLL_S * 1000:g} ms after it falls due, as the emulator looks at its port "
            f"and clock every {POLL_S * 1000:g} ms") in text


def test_the_fault_file_error_emulator_md_quotes_is_what_its_bench_toml_gives(tmp_path):
    """emulator.md quotes a fault file mistake right before it prints `bench.toml`: that
    file with its first fault's kind misspelt 'x' gives the quoted place and message (the
    quote once named line 6 and faults[1], a file the page does not show)."""
    from verifier.emulate.faultfile import FaultFileError, load_fault_file

    text = (ROOT / "docs" / "emulator.md").read_text(encoding="utf-8")
    quoted = re.search(r"\(`bench\.toml:(\d+:\d+: [^;`]+);", text).group(1)
    bench = code_blocks(text.split("## Fault files", 1)[1], "toml")[0]
    assert bench.count('kind = "anti_collision"') == 1
    (tmp_path / "bench.toml").write_text(bench, encoding="utf-8")
    assert len(load_fault_file(tmp_path / "bench.toml").faults) == 4  # as printed, it loads
    (tmp_path / "bench.toml").write_text(bench.replace('kind = "anti_collision"', 'kind = "x"'), encoding="utf-8")
    with pytest.raises(FaultFileError) as raised:
        load_fault_file(tmp_path / "bench.toml")
    assert f"bench.toml:{quoted};" in str(raised.value)


def test_the_port_messages_the_pages_quote_are_the_commands_own(tmp_path):
    """emulator.md and commissioning.md quote what `uitamr emulate` and `uitamr monitor` say of
    a port that cannot be opened and of one that went away; each quote is the command's own
    words, run on a real port where one can be had (a quote ending in "..." is their start)."""
    import socket
    import subprocess
    import sys

    import serial

    from verifier.serialports import why_it_failed

    def page(name: str) -> str:
        return " ".join((ROOT / "docs" / name).read_text(encoding="utf-8").split())

    def said(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "verifier.cli", *args], capture_output=True, text=True,
                              timeout=30)

    emulator, commissioning = page("emulator.md"), page("commissioning.md")
    missing = said("emulate", "--serial", str(tmp_path / "ttyUSB9"))  # the page's /dev/ttyUSB9, surely absent
    quote = re.search(r"`cannot open serial port /dev/ttyUSB9: ([^`]*) \.\.\.`", emulator).group(1)
    assert missing.returncode == 2 and f"cannot open serial port {tmp_path / 'ttyUSB9'}: {quote}" in missing.stderr
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        in_use = said("emulate", "--tcp", f"127.0.0.1:{port}")
    quote = re.search(r"`(cannot listen on 127\.0\.0\.1:4001: [^`]*)`", emulator).group(1)
    assert in_use.returncode == 2 and quote.replace("4001", str(port)) in in_use.stderr, in_use.stderr
    with socket.create_server(("127.0.0.1", 0)) as probe:  # closed again: nothing listens on it
        free = probe.getsockname()[1]
    refused = said("monitor", "--tcp", f"127.0.0.1:{free}")
    quote = re.search(r"`(cannot connect to 192\.168\.0\.60:4001: [^`]*)`", commissioning).group(1)
    assert refused.returncode == 2
    assert quote.replace("192.168.0.60:4001", f"127.0.0.1:{free}") in refused.stderr, refused.stderr
    # an unplugged adapter, in pyserial 3.5's words (run on a real pty by test_emulate_ports.py
    # and test_monitor.py)
    gone = why_it_failed(serial.SerialException("device reports readiness to read but returned no data (device "
                                                "disconnected or multiple access on port?)"))
    assert f"`serial port /dev/ttyUSB0 failed: {gone}`" in emulator
    quote = re.search(r"`the capture ended early: /dev/ttyUSB0: ([^`]*) \.\.\.`", commissioning).group(1)
    assert gone.startswith(quote)


def _plc_arguments(command: str) -> list[str]:
    """The bundled files a command names (not a pattern: `plc/*.st` in ci.md is the
    integrator's own plc/ folder)."""
    return [word for word in _argv(command) if word.startswith("plc/") and not re.search(r"[*?\[]", word)]


def test_the_bundled_files_the_commands_name_are_there():
    """`uitamr check ... plc/examples/fx5/UITAMR_ExampleTcpFx5.st`, `--scenario
    plc/scenarios/q-tcp-dropped.toml`: each bundled file or folder a page's command names
    exists (a renamed scenario or example would leave the page's command failing)."""
    named = {word for _, command in QUOTED + INLINE for word in _plc_arguments(command)}
    assert {"plc/scenarios/q-tcp-dropped.toml", "plc/examples/fx5/UITAMR_ExampleTcpFx5.st"} <= named
    missing = sorted(word for word in named if not (ROOT / word).exists())
    assert not missing, missing


CHECKS = sorted({(page, command) for page, command in QUOTED
                 if _argv(command)[0] == "check" and _plc_arguments(command)
                 and all(word.startswith(("-", "plc/")) or word in ("fx3u", "fx3g", "fx5u", "q")
                         for word in _argv(command)[1:])})


@pytest.mark.parametrize("page, command", CHECKS, ids=[f"{p}: {c}" for p, c in CHECKS])
def test_a_check_of_the_bundled_library_a_page_shows_is_clean(page, command, monkeypatch):
    """The pages' `uitamr check --platform fx3u plc/core plc/fx3 ...` lines before a
    download: run from the repository as shown, they find nothing."""
    from click.testing import CliRunner

    monkeypatch.chdir(ROOT)
    done = CliRunner().invoke(main, _argv(command))
    assert done.exit_code == 0 and done.output.rstrip().endswith(": 0 error(s), 0 warning(s)"), (page, done.output)


def test_the_pages_check_the_bundled_library_for_every_platform():
    assert {page for page, _ in CHECKS} >= {"docs/import-gxworks2.md", "docs/import-gxworks3.md", "plc/README.md"}
    assert {_argv(command)[_argv(command).index("--platform") + 1] for _, command in CHECKS} >= {"fx3u", "fx5u", "q"}


def _anchors(page: Path) -> set[str]:
    """The #anchors GitHub makes of a page's headings: lower case, punctuation dropped,
    spaces to hyphens."""
    headings = re.findall(r"^#+\s+(.*?)\s*$", page.read_text(encoding="utf-8"), flags=re.M)
    return {re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-") for heading in headings}


def test_the_links_of_the_pages_resolve():
    """Every relative link of the READMEs and docs/ (the walked pages link each other, the
    plc/ folders and sections: `st-dialect.md#9-uitamr-check`) names a file or folder that
    is there and, for a section, a heading the page has."""
    pages = [ROOT / "README.md", ROOT / "README.zh-TW.md", ROOT / "plc" / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    broken, checked = [], 0
    for page in pages:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text(encoding="utf-8")):
            if re.match(r"(https?:|mailto:|\d)", target):  # a web page, or `Bit String[16-bit](0..39)`
                continue
            path, _, anchor = target.partition("#")
            linked = (page.parent / path).resolve() if path else page
            checked += 1
            if not linked.exists() or (anchor and linked.suffix == ".md" and anchor not in _anchors(linked)):
                broken.append(f"{page.relative_to(ROOT)}: {target}")
    assert checked > 100 and not broken, broken


IMPORT_PAGES = ("docs/import-gxworks2.md", "docs/import-gxworks3.md", "plc/README.md")
EXPORTS = [(page, command) for page, command in QUOTED if page in IMPORT_PAGES and _argv(command)[0] == "export"]
# "your program" of the pages' `vendor/uitamr ... src/` lines, one per CPU they name
USER_MAIN = """PROGRAM Main
VAR
    fbPort : {port};
    fbEngine : UITAMR_Engine;
    fbRun : UITAMR_RunPoint;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
fbPort(i_bEN := TRUE, {port_args}, io_uPort := uPort);
fbEngine(i_bEN := NOT SM402, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);
fbRun(i_bEN := TRUE, i_bExecute := {start}, i_wPoint := 1, io_uMbx := uMbx);
END_PROGRAM
"""
USER_PORTS = {"q": ("UITAMR_PortQC24", "i_uUnit := 16#0, i_wChannel := 1, i_bReadReq := X3, i_bRecvErr := X4", "X20"),
              "fx5u": ("UITAMR_PortFx5", "i_wChannel := 1", "X0")}


def test_the_export_lines_of_the_import_pages_run_and_write_what_they_say(tmp_path, monkeypatch):
    """The `uitamr export` lines of import-gxworks2.md, import-gxworks3.md and plc/README.md,
    run as given from an integrator's folder (the toolkit as a `vendor/uitamr` submodule, a
    program `Main` in `src/`): each exits 0 without a warning, and writes what the line's
    comment or the page says - the FX3 and Q ports for GX Works2, only the Q's part with
    `--platform q`, the three FX5 ports for GX Works3, the same files with `--platform
    fx5u`, and with `--program Main` only Main and the library POUs it uses."""
    from click.testing import CliRunner

    assert len(EXPORTS) == 7, EXPORTS
    monkeypatch.chdir(tmp_path)
    (tmp_path / "vendor").mkdir()
    (tmp_path / "vendor" / "uitamr").symlink_to(ROOT, target_is_directory=True)
    (tmp_path / "src").mkdir()
    fx3_only = {p.stem for part in ("fx3", "examples/fx3") for p in (ROOT / "plc" / part).glob("*.st")}
    previous: dict[str, bytes] = {}
    for page, command in EXPORTS:
        argv, comment = _argv(command), command.partition("#")[2].strip()
        platform = argv[argv.index("--platform") + 1] if "--platform" in argv else None
        if "src/" in argv:
            port, port_args, start = USER_PORTS[platform]
            (tmp_path / "src" / "Main.st").write_text(USER_MAIN.format(port=port, port_args=port_args, start=start),
                                                      encoding="utf-8")
        out = tmp_path / argv[argv.index("--out") + 1]
        if out.exists():
            for old in out.iterdir():
                old.unlink()
        done = CliRunner().invoke(main, argv)
        assert done.exit_code == 0 and "warning" not in done.output, (page, command, done.output)
        files = {p.name: p.read_bytes() for p in sorted(out.iterdir())}
        written = {name.split(".")[0] for name in files} - {"IMPORT_ORDER"}
        ports = {name for name in written if name.startswith("UITAMR_Port") and name not in ("UITAMR_PortLink",
                                                                                               "UITAMR_PortPacking")}
        if "--program" in argv:
            assert "Main" in written and not {n for n in written if "Example" in n or "Panel" in n}, (command, written)
            assert ports == {USER_PORTS[platform][0]}, (command, written)
        elif comment == "library + FX3 and Q ports + examples" or comment == "paste-ready labels and bodies":
            assert ports == {"UITAMR_PortFx3", "UITAMR_PortAdpFx3", "UITAMR_PortQC24", "UITAMR_PortE71"}, written
            assert {"UITAMR_ExampleFx3", "UITAMR_ExampleQ", "UITAMR_ExampleTcpQ", "UITAMR_PanelFx3"} <= written
        elif comment == "only the Q's part, checked against the Q CPU":
            assert ports == {"UITAMR_PortQC24", "UITAMR_PortE71"} and not written & fx3_only, written
        elif comment == "library + FX5 RS2, ADPRW and Ethernet ports + examples":
            assert ports == {"UITAMR_PortFx5", "UITAMR_PortAdpFx5", "UITAMR_PortTcpFx5"}, written
            assert {"UITAMR_ExampleFx5", "UITAMR_ExampleAdpFx5", "UITAMR_ExampleTcpFx5"} <= written
            previous = files
        elif comment == "the same, checked against the FX5U CPU first":
            assert files == previous
        else:
            pytest.fail(f"{page}: `{command}`: a comment this test does not know what to hold to")
