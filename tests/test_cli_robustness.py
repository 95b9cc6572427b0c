"""Whatever a hurried integrator or a corrupted file hands a command, it answers with an
error that names what to fix and an exit status (2: unusable input), never a traceback."""
from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier.cli import main
from verifier.verify.scenario import ScenarioError, load_scenario

#: longer than any file name a Linux or Windows file system takes (255 bytes)
LONG = "a" * 300


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


@pytest.mark.parametrize("args", [
    ["check", LONG],
    ["check", LONG + ".toml"],
    ["verify", LONG],
    ["verify", "--scenario", LONG + ".toml"],
    ["verify", "--duration", "1s", "--json", f"{LONG}/x.json"],
    ["export", "--target", "gxworks2", "--out", "{tmp}", LONG],
])
def test_a_file_name_too_long_is_an_error_not_a_traceback(args, tmp_path):
    # os.stat raised OSError (ENAMETOOLONG) from Path.is_dir()/exists() before any check
    result = invoke(*[a.replace("{tmp}", str(tmp_path)) for a in args])
    assert result.exit_code == 2, result.output
    assert "File name too long" in result.output and LONG in result.output


def test_a_source_name_too_long_in_a_scenario_names_its_key_and_line(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(f'program = "Main"\nsources = ["{LONG}.st"]\n', encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert (caught.value.key, caught.value.line, caught.value.col) == ("sources[0]", 2, 12)
    assert "File name too long" in caught.value.message


def test_a_scenario_file_name_too_long_is_a_scenario_error(tmp_path):
    with pytest.raises(ScenarioError, match="cannot read: File name too long"):
        load_scenario(tmp_path / f"{LONG}.toml")


@pytest.mark.parametrize("args, words", [
    (["check", "{loop}.st"], "cannot read: Too many levels of symbolic links"),
    (["check", "{loop}.toml"], "cannot read: Too many levels of symbolic links"),
    (["verify", "--scenario", "{loop}.toml"], "a symbolic link to nothing"),
    (["verify", "{loop}.st"], "a symbolic link to nothing"),
    (["verify", "--duration", "1s", "--json", "{loop}.st"], "Too many levels of symbolic links"),
    (["replay", "--json", "{loop}.st", "{capture}"], "Too many levels of symbolic links"),
    (["export", "--target", "gxworks2", "--out", "{loop}.st", "{program}"], "cannot write"),
])
def test_a_symlink_loop_is_an_error_not_a_traceback(args, words, tmp_path):
    # Python 3.11's Path.resolve() raised RuntimeError("Symlink loop from ...")
    loop = tmp_path / "loop"
    for suffix in (".st", ".toml"):
        (tmp_path / f"a{suffix}").symlink_to(tmp_path / f"b{suffix}")
        (tmp_path / f"b{suffix}").symlink_to(tmp_path / f"a{suffix}")
        (tmp_path / f"loop{suffix}").symlink_to(tmp_path / f"a{suffix}")
    program = tmp_path / "P.st"
    program.write_text("PROGRAM P\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n", encoding="utf-8")
    capture = tmp_path / "c.txt"
    capture.write_text("0.000 tx 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    fill = {"{loop}": str(loop), "{program}": str(program), "{capture}": str(capture)}
    for key, value in fill.items():
        args = [a.replace(key, value) for a in args]
    result = invoke(*args)
    assert result.exit_code == 2, result.output
    assert words in result.output


def test_a_host_name_the_idna_codec_refuses_is_an_error_not_a_traceback():
    # socket.create_connection raised UnicodeError ("label empty or too long") for a..b
    result = invoke("monitor", "--tcp", "a..b:4001", "--duration", "1s")
    assert result.exit_code == 2
    assert "cannot connect to a..b:4001: not a host name" in result.output
