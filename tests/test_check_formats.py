"""`uitamr check --format json|github|sarif` and scenario files given to `uitamr check`."""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from st_helpers import CORPUS, ROOT
from verifier.cli import main
from verifier.commands.check_formats import RULES
import procs

BAD = CORPUS / "invalid" / "int_from_word.st"
WARN = CORPUS / "invalid" / "unused_warning.st"
BROKEN = CORPUS / "broken" / "if_else_not_closed.st"


def run(*args, cwd: Path | None = None):
    return procs.run([sys.executable, "-m", "verifier.cli", "check", *map(str, args)],
                     capture_output=True, text=True, timeout=120, cwd=cwd)


def test_text_stays_the_editor_format():
    done = run(BROKEN)
    assert done.returncode == 1
    assert done.stdout.splitlines()[0] == (
        f"{BROKEN}:12:1: error: IF opened at 7:1 is not closed: expected END_IF before END_FUNCTION_BLOCK")


def test_github_annotations_name_file_line_column_and_rule():
    done = run("--format", "github", BROKEN.relative_to(ROOT), BAD.relative_to(ROOT), WARN.relative_to(ROOT),
               cwd=ROOT)
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert lines[0] == ("::error file=tests/corpus/broken/if_else_not_closed.st,line=12,col=1,"
                        "title=uitamr check UITAMR-ST-SYNTAX::IF opened at 7:1 is not closed: "
                        "expected END_IF before END_FUNCTION_BLOCK")
    assert any(line.startswith("::error file=tests/corpus/invalid/int_from_word.st,line=5,col=7,")
               and "UITAMR-ST-CHECK" in line for line in lines)
    assert any(line.startswith("::warning file=tests/corpus/invalid/unused_warning.st,line=4,col=5,")
               for line in lines)
    assert lines[-1].endswith("error(s), 1 warning(s)")


def test_github_annotations_escape_what_would_break_the_command(tmp_path):
    odd = tmp_path / "a,b:100%.st"
    odd.write_text("PROGRAM P\nVAR iX : INT; END_VAR\niX := 'x\nEND_PROGRAM\n", encoding="utf-8")
    done = run("--format", "github", odd.name, cwd=tmp_path)
    first = done.stdout.splitlines()[0]
    assert first.startswith("::error file=a%2Cb%3A100%25.st,line=3,col=7,")


def test_absolute_paths_below_the_working_directory_become_relative():
    done = run(BROKEN, "--format", "github", cwd=ROOT)
    assert "file=tests/corpus/broken/if_else_not_closed.st," in done.stdout


def test_a_file_in_a_symlinked_vendor_folder_is_annotated_by_the_path_in_the_repository(tmp_path):
    # vendor/lib links to a folder outside the repository: the annotation must name the
    # file as the repository holds it (vendor/lib/...), as the reports do, not by where the
    # link leads nor by the absolute path
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "bad.st").write_bytes(BROKEN.read_bytes())
    repo = tmp_path / "repo"
    (repo / "vendor").mkdir(parents=True)
    (repo / "vendor" / "lib").symlink_to(outside, target_is_directory=True)
    done = run("--format", "github", repo / "vendor" / "lib" / "bad.st", cwd=repo)
    assert done.stdout.startswith("::error file=vendor/lib/bad.st,line=12,col=1,"), done.stdout


def _sarif(*args, cwd=ROOT) -> dict:
    done = run("--format", "sarif", *args, cwd=cwd)
    return json.loads(done.stdout)


def test_sarif_has_what_code_scanning_requires():
    log = _sarif(BROKEN.relative_to(ROOT), BAD.relative_to(ROOT), WARN.relative_to(ROOT))
    assert log["version"] == "2.1.0" and log["$schema"].endswith("sarif-2.1.0.json")
    (run_,) = log["runs"]
    driver = run_["tool"]["driver"]
    assert driver["name"] == "uitamr check" and re.match(r"\d+\.\d+", driver["version"])
    rule_ids = [r["id"] for r in driver["rules"]]
    assert set(rule_ids) == set(RULES) and all(r["shortDescription"]["text"] for r in driver["rules"])
    results = run_["results"]
    assert len(results) == 4
    for result in results:
        assert result["level"] in ("error", "warning")
        assert result["message"]["text"]
        assert rule_ids[result["ruleIndex"]] == result["ruleId"]
        (location,) = result["locations"]
        physical = location["physicalLocation"]
        assert physical["artifactLocation"]["uriBaseId"] == "%SRCROOT%"
        assert not Path(physical["artifactLocation"]["uri"]).is_absolute()
        assert (ROOT / physical["artifactLocation"]["uri"]).is_file()
        region = physical["region"]
        assert region["startLine"] >= 1 and region["startColumn"] >= 1
    first = results[0]
    assert first["ruleId"] == "UITAMR-ST-SYNTAX"
    assert first["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == \
        "tests/corpus/broken/if_else_not_closed.st"
    assert first["locations"][0]["physicalLocation"]["region"] == {"startLine": 12, "startColumn": 1}
    assert run_["originalUriBaseIds"]["%SRCROOT%"]["uri"].startswith("file://")


def test_sarif_of_a_clean_run_has_no_results():
    log = _sarif((CORPUS / "valid" / "statements.st").relative_to(ROOT))
    assert log["runs"][0]["results"] == []


def test_json_names_the_rule_of_each_diagnostic():
    done = run("--format", "json", BROKEN, WARN)
    report = json.loads(done.stdout)
    assert [d["rule"] for d in report["diagnostics"]] == ["UITAMR-ST-SYNTAX", "UITAMR-ST-WARNING"]
    assert report["errors"] == 1 and report["warnings"] == 1


@pytest.mark.parametrize("fmt", ["text", "json", "github", "sarif"])
def test_a_scenario_file_is_checked_with_line_and_column(tmp_path, fmt):
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "Main"\nduration = "60s"\nscan = "10xs"\n', encoding="utf-8")
    done = run("--format", fmt, scenario.name, cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "Traceback" not in done.stdout + done.stderr
    if fmt == "text":
        assert done.stdout.startswith("s.toml:3:8: error: scan: '10xs' is not a duration")
        assert done.stdout.splitlines()[1:3] == ['    scan = "10xs"', "           ^"]
    elif fmt == "github":
        assert done.stdout.startswith("::error file=s.toml,line=3,col=8,title=uitamr check UITAMR-SCENARIO::scan: ")
    elif fmt == "json":
        (d,) = json.loads(done.stdout)["diagnostics"]
        assert (d["file"], d["line"], d["col"], d["rule"]) == ("s.toml", 3, 8, "UITAMR-SCENARIO")
    else:
        (result,) = _sarif(scenario.name, cwd=tmp_path)["runs"][0]["results"]
        assert result["locations"][0]["physicalLocation"]["region"] == {"startLine": 3, "startColumn": 8}


def test_the_bundled_scenarios_check_clean():
    done = run(*sorted((ROOT / "plc" / "scenarios").glob("*.toml")))
    assert done.returncode == 0, done.stdout


def test_sarif_uris_are_percent_encoded_and_resolve_to_the_files(tmp_path):
    # SARIF 2.1.0 §3.10.2: artifactLocation.uri is a URI reference (RFC 3986), so a space,
    # a '%' or a non-ASCII letter in a file name is percent-encoded; a file outside the
    # working directory gets an absolute file: URI and no uriBaseId (§3.4.4)
    from urllib.parse import unquote, urljoin, urlparse
    repo, outside = tmp_path / "repo", tmp_path / "else where"
    repo.mkdir()
    outside.mkdir()
    inside = repo / "Main Program 100% ü.st"
    other = outside / "b.st"
    for path in (inside, other):
        path.write_bytes(BROKEN.read_bytes())
    run_ = _sarif(inside.name, other, cwd=repo)["runs"][0]
    base = run_["originalUriBaseIds"]["%SRCROOT%"]["uri"]
    places = []
    for result in run_["results"]:
        artifact = result["locations"][0]["physicalLocation"]["artifactLocation"]
        uri = artifact["uri"]
        assert re.fullmatch(r"[A-Za-z0-9\-._~!$&'()*+,;=:@/%]+", uri), uri
        assert not re.search(r"%(?![0-9A-F]{2})", uri), uri
        if "uriBaseId" in artifact:
            assert artifact["uriBaseId"] == "%SRCROOT%" and not urlparse(uri).scheme
            uri = urljoin(base, uri)
        places.append(Path(unquote(urlparse(uri).path)))
    assert places == [inside.resolve(), other.resolve()]


def test_a_file_reached_by_climbing_out_of_the_working_directory_gets_an_absolute_uri(tmp_path):
    # `uitamr check ../lib/b.st` from the repository: the file is outside the working
    # directory as surely as /abs/lib/b.st is, and gets the same absolute file: URI (a
    # "../lib/b.st" reference under %SRCROOT% names nothing in the repository that code
    # scanning can show); a path that only steps through a folder and back is folded
    repo, lib = tmp_path / "repo", tmp_path / "lib"
    (repo / "sub").mkdir(parents=True)
    lib.mkdir()
    for path in (repo / "a.st", lib / "b.st"):
        path.write_bytes(BROKEN.read_bytes())
    results = _sarif("sub/../a.st", "../lib/b.st", cwd=repo)["runs"][0]["results"]
    artifacts = [result["locations"][0]["physicalLocation"]["artifactLocation"] for result in results]
    assert artifacts == [{"uri": "a.st", "uriBaseId": "%SRCROOT%"}, {"uri": (lib / "b.st").as_uri()}]
    done = run("--format", "github", "sub/../../lib/b.st", cwd=repo)
    assert done.stdout.startswith(f"::error file={(lib / 'b.st').as_posix()},line=12,col=1,"), done.stdout


def test_a_channel_the_scenarios_cpu_lacks_is_a_check_error_at_its_line(tmp_path):
    # `uitamr check` reads scenario files "as uitamr verify reads them": [[c24]] and
    # [converter] on the wrong CPU were errors at their line, but channel = "q:1" in an
    # FX3U scenario passed the check and failed only when verify loaded the program
    scenario = tmp_path / "s.toml"
    scenario.write_text('platform = "fx3u"\nchannel = "q:1"\n', encoding="utf-8")
    done = run("s.toml", cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert done.stdout.startswith("s.toml:2:11: error: channel: channel q:1 does not exist on the fx3u CPU; "
                                  "the fx3u CPU has fx3:1, fx3:2, adp:1")
    for platform, channel in (("fx5u", "adp:1"), ("q", "q:2"), ("fx3u", "fx3:2")):
        scenario.write_text(f'platform = "{platform}"\nchannel = "{channel}"\n', encoding="utf-8")
        assert run("s.toml", cwd=tmp_path).returncode == 0
    scenario.write_text('platform = "q"\nchannel = "adp:1"\n', encoding="utf-8")
    assert "channel adp:1 does not exist on the q CPU; the q CPU has q:1, q:2" in run("s.toml", cwd=tmp_path).stdout
