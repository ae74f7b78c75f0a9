"""Issue 56, item 3: the bay's screen as a golfer reads it, in a real headless Chromium at 400 and 1280 px wide.

The session by club is read whole at both widths (at 400 px its rows stack, each number under its column's name: the
table was 813 px in a 363 px box, four columns shown, no cue); a connector's 40-character ClubData value stays in its
tile, cut, whole on hover; shots are numbered in their session (#1 for its first), not by the event ids that run on
across sessions; putts read as putts (no "heights 0 yd out", no carry, apex or landing of 0.0 ± 0.0). And over plain
HTTP: an empty session's CSV has the columns a session of shots has (it had 8)."""

from __future__ import annotations

import csv
import io

import pytest
from servers import keyed_service
from test_viewer import KEYED, KEY, gspro_over_tcp
from test_viewer_bay import PUTT_BALL, WITH_BROWSER, live_viewer

DRIVE_BALL = {"Speed": 150.0, "VLA": 12.0, "HLA": 1.0, "TotalSpin": 2900.0, "SpinAxis": 4.0}
LONG_TEXT = "Tour Edge Exotics C723 driver, 9.5 stiff"
"""A connector's text value of 40 characters, the most a ClubData text keeps (`contract.gspro.MAX_CLUB_TEXT`)."""


def drive(number: int) -> dict:
    """A drive a little different from the others (a session's spread is not 0)."""
    return {**DRIVE_BALL, "Speed": DRIVE_BALL["Speed"] + number, "HLA": number % 3 - 1.0}

SUMMARY = """() => {
  const box = document.querySelector('.summary-box'), b = box.getBoundingClientRect();
  const shown = (e) => getComputedStyle(e).display !== 'none' && e.getBoundingClientRect().width > 0;
  const heads = [...document.querySelectorAll('#summary th')];
  return {box: [b.left, b.right], overflow: box.scrollWidth - box.clientWidth,
    names: heads.map(h => h.textContent), heads: heads.filter(shown).map(h => h.textContent),
    rows: [...document.querySelectorAll('#summary tbody tr')].map(r => ({club: r.dataset.club, putts: r.dataset.putts,
      cells: [...r.cells].map(c => {
        const cb = c.getBoundingClientRect();
        return {text: c.textContent, label: getComputedStyle(c, '::before').content, box: [cb.left, cb.right],
                px: parseFloat(getComputedStyle(c).fontSize), cut: c.scrollWidth > c.clientWidth + 1};
      })}))};
}"""
"""The summary's box across and how far it scrolls sideways, its column names and the headers shown, and each row's
cells: text, the label drawn before it (a stacked row's column name), box across, font size and whether it is cut."""


def _session_rows(page, shots: int) -> None:
    page.wait_for_function(
        f"() => session.summary && session.summary.clubs.reduce((n, c) => n + c.shots, 0) === {shots}"
        " && document.querySelectorAll('#summary tbody tr').length === session.summary.clubs.length", timeout=10_000)


def _summary_is_read_whole(page, width: int) -> None:
    summary = page.evaluate(SUMMARY)
    left, right = summary["box"]
    assert summary["overflow"] <= 1, f"the summary scrolls sideways by {summary['overflow']} px"
    for row in summary["rows"]:
        for index, cell in enumerate(row["cells"]):
            x0, x1 = cell["box"]
            assert left - 0.5 <= x0 and x1 <= right + 0.5 and not cell["cut"] and cell["px"] >= 10, (row, cell)
            if width == 400 and index:  # stacked: each figure under its column's name, with the unit
                assert cell["label"] == f'"{summary["names"][index]}"', (row, cell)
    assert summary["names"][2] == "carry (yd)"
    assert summary["heads"] == ([] if width == 400 else summary["names"]) and len(summary["names"]) == 8
    putts = next(r for r in summary["rows"] if r["putts"] == "1")
    by_name = dict(zip(("club", "shots", "carry", "gap", "total", "apex", "lateral"), putts["cells"], strict=False))
    assert [by_name[k]["text"] for k in ("carry", "apex", "lateral")] == ["—"] * 3, putts
    assert by_name["total"]["text"] != "—" and by_name["club"]["text"].endswith("(putts)")
    assert not any(c["text"].startswith("0.0 ±") for c in putts["cells"]), putts


def _numbers_in_the_session(page, http, port) -> None:
    """Two shots, a new session, then three: the table numbers them 3, 2, 1 (their event ids run on: 5, 4, 3)."""
    for number in (1, 2):
        gspro_over_tcp(port, number, drive(number))
    page.wait_for_selector("#shots tbody tr[data-shot='2']", timeout=10_000)
    assert http.post("/v1/sessions", headers=KEYED).status_code == 201
    for number in (3, 4, 5):
        gspro_over_tcp(port, number, drive(number))
    page.wait_for_selector("#shots tbody tr[data-shot='5']", timeout=10_000)
    table = page.eval_on_selector_all("#shots tbody tr", "rs => rs.map(r => [r.dataset.shot, r.cells[0].textContent])")
    assert table == [["5", "3"], ["4", "2"], ["3", "1"]], table
    assert page.inner_text("#last-source").startswith("#3 ·")


def _a_long_club_data_value_stays_in_its_tile(page, http) -> None:
    message = {"ShotNumber": 6, "APIversion": "1", "BallData": DRIVE_BALL,
               "ClubData": {"Speed": 101.0, "Model": LONG_TEXT},
               "ShotDataOptions": {"ContainsBallData": True, "ContainsClubData": True}}
    assert http.post("/v1/gspro", json=message, headers=KEYED).json()["Code"] == 200
    page.wait_for_selector("#shots tbody tr[data-shot='6']", timeout=10_000)
    tile = page.evaluate("""() => {
      const dd = document.getElementById('club-Model'), tile = dd.parentElement;
      const box = (e) => { const b = e.getBoundingClientRect(); return [b.left, b.right]; };
      return {value: dd.textContent, title: dd.title, dd: box(dd), tile: box(tile),
              section: box(document.querySelector('section.numbers')), cut: dd.scrollWidth > dd.clientWidth,
              overflow: getComputedStyle(dd).textOverflow};
    }""")
    assert len(LONG_TEXT) == 40 and tile["value"] == LONG_TEXT and LONG_TEXT in tile["title"]
    assert tile["tile"][0] - 0.5 <= tile["dd"][0] and tile["dd"][1] <= tile["tile"][1] + 0.5, tile
    assert tile["tile"][1] <= tile["section"][1] + 0.5, tile
    assert not tile["cut"] or tile["overflow"] == "ellipsis", tile


def _putts_read_as_putts(page, http, port) -> None:
    """Three putts after the drives: the behind view's heights stay at the last drive's apex (not "heights 0 yd
    out"), the last shot shows no carry, apex, landing or hang time, the table no carry, apex or landing."""
    assert http.patch("/v1/bay", json={"player": {"club": "PT"}}, headers=KEYED).status_code == 200
    for number in (7, 8, 9):
        gspro_over_tcp(port, number, {**PUTT_BALL, "Speed": PUTT_BALL["Speed"] * (0.8 + 0.1 * (number - 7)),
                                      "HLA": number - 8.0})
    page.wait_for_selector("#shots tbody tr[data-shot='9']", timeout=10_000)
    page.wait_for_selector("#behind polyline.latest[data-done]", state="attached", timeout=10_000)
    caption = page.text_content("#behind .height-caption")
    assert caption and not caption.startswith("heights 0 ") and caption.endswith("yd out"), caption
    tiles = {name: page.inner_text(f"#n-{name}") for name in ("carry", "apex", "landing-angle", "flight-time")}
    assert set(tiles.values()) == {"—"}, tiles
    assert page.inner_text("#n-total") != "—"
    putt = page.eval_on_selector("#shots tbody tr[data-shot='9']", "r => [...r.cells].map(c => c.textContent)")
    assert [putt[i] for i in (6, 8, 9, 10)] == ["—"] * 4 and putt[7] != "—", putt


@WITH_BROWSER
@pytest.mark.parametrize("width", [400, 1280])
def test_the_session_reads_whole_at_400_and_1280_px(width):
    with live_viewer(width, 900) as (page, http, port, errors):
        _numbers_in_the_session(page, http, port)
        _a_long_club_data_value_stays_in_its_tile(page, http)
        _putts_read_as_putts(page, http, port)
        _session_rows(page, 7)
        _summary_is_read_whole(page, width)
        assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")
        assert errors == []


def test_an_empty_sessions_csv_has_the_columns_of_one_with_shots():
    with keyed_service(KEY) as (http, port, _app):
        assert http.post("/v1/sessions", headers=KEYED).status_code == 201
        empty = http.get("/v1/session.csv", headers=KEYED).text
        gspro_over_tcp(port, 1, DRIVE_BALL)
        assert http.post("/v1/shots?viewer=true", json={"ball_speed_mph": 120.0, "launch_angle_deg": 16.0,
                                                         "spin_rpm": 6500.0}, headers=KEYED).status_code == 200
        full = http.get("/v1/session.csv", headers=KEYED).text
    header = next(csv.reader(io.StringIO(empty)))
    assert empty.count("\n") == 1 and len(header) == 38
    assert header == next(csv.reader(io.StringIO(full)))
