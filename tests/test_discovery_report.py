"""report.html (issue 14, item 7): plotly figures in one self-contained file that opens offline (plotly.js inline
once, no CDN), every shot-level point carrying its shot id, session and club for hover; the tables alone, naming
the extra to install, without plotly; and the page in a real headless Chromium: no console errors, every figure
drawn, a hover shows a shot id (skipped where chromium or Playwright is missing)."""

from __future__ import annotations

import re
import sys

import browser
import numpy as np
import pytest
from golfflight.discovery.conceal import conceal
from golfflight.discovery.diagnose import Diagnosis, diagnose
from golfflight.discovery.html import PLOTS_MISSING, render
from golfflight.discovery.model import reference
from golfflight.discovery.outputs import write_diagnosis
from golfflight.discovery.recordings import from_shot_set

plotly = pytest.importorskip("plotly", reason="report.html's figures need the extra 'report'")

from golfflight.discovery.figures import SHOT_FIELDS, report_figures  # after the skip: it imports plotly


@pytest.fixture(scope="module")
def diagnosis() -> Diagnosis:
    """A concealed wind over several sessions and clubs, 12 shots with trajectories, diagnosed against the reference
    world (quick: no learned correction)."""
    concealed = conceal({"wind": {"speed_mps": 4.0, "from_deg": 60.0}}, 120, seed=5, trajectories=True)
    tracks = dict(list(concealed.trajectories.items())[:12])
    recordings = from_shot_set(concealed.shots, tracks, source="concealed wind")
    return diagnose(recordings, reference(), seed=0, with_correction=False)


@pytest.fixture(scope="module")
def page_file(diagnosis, tmp_path_factory):
    return write_diagnosis(diagnosis, tmp_path_factory.mktemp("report"))[1]


def _shot_traces(diagnosis: Diagnosis) -> list:
    return [
        trace
        for figures in report_figures(diagnosis).values()
        for figure in figures
        for trace in figure.data
        if trace.customdata is not None and "shot %{customdata[0]}" in (trace.hovertemplate or "")
    ]


def test_the_page_embeds_plotly_once_and_fetches_nothing(page_file):
    html = page_file.read_text()
    bundle = plotly.offline.get_plotlyjs()
    assert html.count(bundle[:300]) == 1 and bundle[-300:] in html, "plotly.js inline, exactly once"
    assert not re.search(r"<script[^>]*\ssrc\s*=", html, re.IGNORECASE), "no script is fetched (no CDN)"
    assert not re.search(r"<link[^>]*href\s*=\s*['\"]https?:", html, re.IGNORECASE)
    assert html.count('class="plotly-graph-div"') >= 10
    assert "Expected error" in html and "Service settings" in html, "the tables are still there"


def test_every_shot_level_point_carries_its_shot_session_and_club(diagnosis, page_file):
    rec = diagnosis.recordings
    traces = _shot_traces(diagnosis)
    assert traces, "no shot-level trace"
    sessions_of = dict(zip(rec.shot_id, rec.session))
    club_of = dict(zip(rec.shot_id, rec.club))
    shown = set()
    for trace in traces:
        rows = np.asarray(trace.customdata)
        assert rows.shape[1] == len(SHOT_FIELDS)
        assert all(sessions_of[shot] == session and club_of[shot] == club for shot, session, club in rows)
        assert "session %{customdata[1]}" in trace.hovertemplate and "club %{customdata[2]}" in trace.hovertemplate
        shown |= set(rows[:, 0])
    assert shown == set(rec.shot_id), "every shot of the input can be found by hovering"
    html = page_file.read_text()
    assert all(f'"{shot}"' in html for shot in rec.shot_id) and all(f'"{s}"' in html for s in set(rec.session))


def test_without_plotly_the_page_keeps_its_tables_and_names_the_extra(diagnosis, monkeypatch):
    monkeypatch.setitem(sys.modules, "plotly", None)  # import plotly now raises ModuleNotFoundError
    html = render(diagnosis)
    assert "pip install &#x27;golfflight[report]&#x27;" in html and PLOTS_MISSING.startswith("The interactive")
    assert "plotly-graph-div" not in html and "<script" not in html
    assert "Expected error" in html and "Candidates" in html


@pytest.mark.skipif(browser.missing() is not None, reason=str(browser.missing()))
def test_the_report_in_chromium_draws_every_figure_and_hovers_a_shot_id(diagnosis, page_file):
    figures = page_file.read_text().count('class="plotly-graph-div"')
    with browser.headless_page() as page:
        errors: list[str] = []
        fetched: list[str] = []
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.on("console", lambda message: errors.append(message.text) if message.type == "error" else None)
        page.on("request", lambda request: fetched.append(request.url) if request.url.startswith("http") else None)
        page.goto(page_file.as_uri())
        page.wait_for_function(
            f"document.querySelectorAll('.plotly-graph-div .main-svg').length >= {figures}", timeout=20_000
        )
        drawn = page.eval_on_selector_all(
            ".plotly-graph-div", "divs => divs.map(d => d.querySelectorAll('.main-svg').length)"
        )
        assert len(drawn) == figures and all(n > 0 for n in drawn)

        point = page.locator("#figure-0 .scatterlayer .trace .points path.point").first
        point.scroll_into_view_if_needed()
        box = point.bounding_box()
        assert box is not None
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x - 20, y - 20)
        page.mouse.move(x, y, steps=5)
        page.wait_for_selector("#figure-0 .hoverlayer .hovertext", timeout=5_000)
        text = page.text_content("#figure-0 .hoverlayer .hovertext") or ""  # SVG text: the lines run together
        shown = [shot for shot in diagnosis.recordings.shot_id if f"shot {shot}" in text]
        assert len(shown) == 1 and "session" in text and "club" in text, text
        assert errors == [] and fetched == []
