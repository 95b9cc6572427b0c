"""`uitamr verify --html` does not hold the run's frames: the run is judged as it goes and
writes each frame's trace line to a file beside the page (as `--trace` does,
tests/test_verify_trace_spool.py), and the page reads from that file, pass by pass, the
frames it draws (verifier/verify/report_html.py). The page is the same, byte for byte, as
the one drawn from a run that held every frame and was judged as a whole: on every bundled
scenario, with the page's caps lowered so that it leaves frames out (the frames around
each violation first), on pages of several runs, and on random scenarios; and what a long
run holds does not grow with it."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from test_idle_skip import robot_scenarios
from test_verify_pipeline import FX3_EXAMPLE, VARIANTS, broken_scenario, library_copy
from verifier.commands import verify as verify_command
from verifier.commands.verify import command
from verifier.verify import report_html
from verifier.verify import runner as runner_module
from verifier.verify import stream as stream_module
from verifier.verify.result import KEEP_ALL, Keep
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))


def _runs(scenario, folder: Path, monkeypatch, every_us: int = 0, compact_at: int = 2):
    """The run holding its frames (judged as a whole) and the run spooling them (judged as it goes)."""
    monkeypatch.setattr(stream_module, "COMPACT_AT", compact_at)
    monkeypatch.setattr(runner_module, "STREAM_EVERY_US", every_us)  # 0: every virtual second
    held = run_scenario(scenario, keep=KEEP_ALL)
    spooled = run_scenario(scenario, keep=Keep(frames=True, details=True, frames_to_file=str(folder)))
    assert spooled.trace == [] and spooled.trace_file is not None and held.trace_file is None
    for result in (held, spooled):
        result.wall_s = 0.0
    return held, spooled


def _caps(monkeypatch, frames: int, context: int = 4, page: int = 20_000, each: int = 500) -> None:
    monkeypatch.setattr(report_html, "FRAMES_AT_MOST", frames)
    monkeypatch.setattr(report_html, "CONTEXT_FRAMES", context)
    monkeypatch.setattr(report_html, "PAGE_FRAMES_AT_MOST", page)
    monkeypatch.setattr(report_html, "FRAMES_EACH_AT_LEAST", each)


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bundled_scenarios_give_the_same_page(path, tmp_path, monkeypatch):
    held, spooled = _runs(load_scenario(path), tmp_path, monkeypatch)
    page = report_html.render([held])
    assert report_html.render([spooled]) == page and page.count('class="frame ') == len(held.trace) > 10
    # the page's caps lowered: the frames around each violation's first, then the first ones
    _caps(monkeypatch, frames=40, context=2)
    short = report_html.render([held])
    assert report_html.render([spooled]) == short
    if len(held.trace) > 40:
        assert short.count('class="frame ') == 40 and f"40 of the {len(held.trace)} frames" in short
    # two runs sharing a page that holds fewer frames than they have
    _caps(monkeypatch, frames=40, page=50, each=15)
    assert report_html.render([spooled, held]) == report_html.render([held, held])


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_broken_libraries_give_the_same_page(tmp_path, monkeypatch, variant):
    """The frames each broken rule blames, and those around them, are drawn from the spool
    as from the frames held: with every frame drawn, and with 40 of them."""
    held, spooled = _runs(*broken_scenario(tmp_path, variant), monkeypatch)
    assert held.violation_count > 0
    assert report_html.render([spooled]) == report_html.render([held])
    _caps(monkeypatch, frames=40, context=2)
    assert report_html.render([spooled]) == report_html.render([held])


def test_a_long_faulty_run_gives_the_same_page(tmp_path, monkeypatch):
    """Twelve minutes of a library that sends while a reply is due, the robot late twice
    (at the start, and after ten minutes): over 4,000 frames, the page's own caps; the
    frames around the late violations are drawn after the run's first ones."""
    copy = library_copy(tmp_path, VARIANTS["sending-while-a-reply-is-due"][0])
    late = '[[faults]]\nkind = "late_reply"\non_request = {}\ndelay_ms = 400\n'
    text = FX3_EXAMPLE.format(duration="720s", robot="", faults=late.format(3) + late.format(2000), point_within="10s")
    folder = tmp_path / "out"
    folder.mkdir()
    held, spooled = _runs(parse_scenario(text, copy / "scenario.toml"), folder, monkeypatch,
                          runner_module.STREAM_EVERY_US, stream_module.COMPACT_AT)
    assert len(held.trace) > report_html.FRAMES_AT_MOST
    assert {v.t_us // 100_000_000 for v in held.all_violations()} == {0, 6}  # early and late
    page = report_html.render([held])
    assert report_html.render([spooled]) == page
    assert page.count('class="frame ') == report_html.FRAMES_AT_MOST and "frame(s) not shown" in page
    late_blamed = re.findall(r'class="frame \w+ blamed" data-t0="6\d\d\d\d\d', page)
    assert late_blamed  # the late violations' frames are drawn
    assert report_html.render([spooled, spooled]) == report_html.render([held, held])


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=robot_scenarios(), every_s=st.sampled_from([0, 1, 3]), compact_at=st.sampled_from([1, 2, 1024]),
       frames=st.sampled_from([5, 30, 4000]), context=st.sampled_from([0, 1, 4]))
def test_random_scenarios_give_the_same_page(text, every_s, compact_at, frames, context, tmp_path_factory,
                                             monkeypatch):
    folder = tmp_path_factory.mktemp("spool")
    scenario = parse_scenario(text, ROOT / "plc" / "scenarios" / "random.toml")
    held, spooled = _runs(scenario, folder, monkeypatch, every_s * 1_000_000, compact_at)
    _caps(monkeypatch, frames=frames, context=context, page=2 * frames, each=max(1, frames // 3))
    assert report_html.render([spooled]) == report_html.render([held])
    assert report_html.render([held, spooled, held]) == report_html.render([held, held, held])


def test_a_long_run_holds_no_frame_and_the_page_only_those_it_draws(tmp_path, monkeypatch):
    """Ten minutes of fx3u-healthy as `--html` runs it: the result holds no frame, the
    stream lets go of what it judged (at most one step of COMPACT_AT exchanges at the end),
    and drawing the page holds at most the FRAMES_AT_MOST frames it draws."""
    monkeypatch.setattr(report_html, "FRAMES_AT_MOST", 1000)
    held_at_finish = []
    finish = stream_module.Stream.finish

    def spy(self, *args, **kwargs):
        held_at_finish.append(len(self.pairing.traffic.exchanges))
        return finish(self, *args, **kwargs)

    monkeypatch.setattr(stream_module.Stream, "finish", spy)
    text = (ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8")
    scenario = parse_scenario(text.replace('duration = "60s"', 'duration = "600s"'),
                              ROOT / "plc" / "scenarios" / "long.toml")
    result = run_scenario(scenario, keep=Keep(frames=True, details=True, frames_to_file=str(tmp_path)))
    assert result.trace == [] and result.tx_count + result.rx_count > 3800
    assert held_at_finish and held_at_finish[-1] < stream_module.COMPACT_AT + 100
    read = []
    records = report_html.records

    def counted(*args, **kwargs):
        for record in records(*args, **kwargs):
            read.append(record)
            yield record

    monkeypatch.setattr(report_html, "records", counted)
    view = report_html.scenario_view(0, result, report_html.FRAMES_AT_MOST)
    assert len(read) == len(view["frames"]) == 1000
    assert view["frames_left_out"] == result.tx_count + result.rx_count - 1000
    assert (view["tx"], view["rx"]) == (result.tx_count, result.rx_count)


def _invoke(*args):
    return CliRunner().invoke(command, [str(a) for a in args], catch_exceptions=False)


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_the_command_runs_html_without_holding_frames_and_leaves_no_spool_file(tmp_path, monkeypatch, jobs):
    """What the reports are written from: no run holds its frames; and the hidden folder
    beside the page is gone. The page draws every frame of these short runs."""
    written = []
    write_reports = verify_command.write_reports

    def spy(results, *args, **kwargs):
        written.extend(results)
        return write_reports(results, *args, **kwargs)

    monkeypatch.setattr(verify_command, "write_reports", spy)
    scenarios = [ROOT / "plc" / "scenarios" / f"{name}.toml" for name in ("fx3u-healthy", "q-bad-crc")]
    args = [arg for path in scenarios for arg in ("--scenario", path)]
    result = _invoke(*args, "--jobs", jobs, "--html", tmp_path / "r.html", "--duration", "5s")
    assert result.exit_code == 1, result.output  # q-bad-crc fails: the report is still written
    assert len(written) == 2 and all(r.trace == [] and r.tx_count > 0 for r in written)
    # nor the watched labels' changes, which only --json lists (the page draws the events)
    assert all(r.watched == {} for r in written) and any(r.events for r in written)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html"]
    page = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert page.count('class="frame ') == sum(r.tx_count + r.rx_count for r in written)


def test_the_page_is_the_same_with_every_scan(tmp_path):
    """--every-scan (the reference path) still holds every frame and judges the run as a
    whole: its page and the default one's are the same file."""
    scenario = ROOT / "plc" / "scenarios" / "fx3u-bad-crc.toml"
    assert _invoke("--scenario", scenario, "--html", tmp_path / "a.html").exit_code == 0
    assert _invoke("--scenario", scenario, "--html", tmp_path / "b.html", "--every-scan").exit_code == 0
    assert (tmp_path / "a.html").read_bytes() == (tmp_path / "b.html").read_bytes()
