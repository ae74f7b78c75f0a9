"""Issue 43, item 4, on the viewer: what a golfer reads on screen, measured in a real headless Chromium at 400 and
1280 px wide. Every shot lies inside every picture (the behind view frames a high wedge, 85 mph, 30°, 10,000 rpm,
whose apex the golfer's camera cut off, and gives its heights); the top and dispersion views have distance and
lateral scales in the page's units; a pin set on the page stands in every view and the last shot's rest is measured
to it; the shot table fits its box at 400 px, no column cut."""

from __future__ import annotations

import math

import pytest
from test_viewer import KEYED, gspro_over_tcp, pick_club
from test_viewer_bay import IRON_BALL, LONG_DRIVE, PUTT_BALL, WITH_BROWSER, live_viewer

YARD_M = 0.9144
HIGH_WEDGE = {"ball_speed_mph": 85.0, "launch_angle_deg": 30.0, "spin_rpm": 10000.0}
"""The issue's high wedge: apex 26 yd, 25° above the golfer's eye, out of the golfer's camera's picture."""
SLICED_DRIVE = {**LONG_DRIVE, "launch_direction_deg": -6.0, "side_spin_rpm": -1500.0}
"""185 mph, far left: "106.6 L" and "185.0" are the shot table's widest lateral and ball speed cells."""
APEX_MARGIN = 0.05
"""The highest point of a path on screen stays at least this part of the picture's height below its top."""

PICTURE = """(id) => {
  const svg = document.getElementById(id);
  const [, , width, height] = svg.getAttribute('viewBox').split(' ').map(Number);
  const s = svg.getBoundingClientRect();
  return {width, height, screen: [s.left, s.top, s.right, s.bottom],
    paths: [...svg.querySelectorAll('polyline')].map(p => {
      const b = p.getBoundingClientRect();
      return {shot: p.dataset.shot, screen: [b.left, b.top, b.right, b.bottom],
              points: p.getAttribute('points').trim().split(/\\s+/).map(xy => xy.split(',').map(Number))};
    })};
}"""
"""A view's size (its viewBox, which is its size on screen in CSS px), its box on screen, and each drawn path's
points and box on screen."""

LABELS = """(selector) => [...document.querySelectorAll(selector)].map(t => {
  const b = t.getBoundingClientRect();
  return {text: t.textContent, box: [b.left, b.top, b.right, b.bottom]};
})"""

CELLS = """() => {
  const scroll = document.querySelector('.shots .scroll').getBoundingClientRect();
  const shown = (selector) => [...document.querySelectorAll(selector)]
    .filter(c => getComputedStyle(c).display !== 'none');
  return {scroll: [scroll.left, scroll.right], heads: shown('#shots th').map(c => c.textContent),
    cells: shown('#shots th, #shots td').map(c => {
      const b = c.getBoundingClientRect();
      return {text: c.textContent, x: [b.left, b.right]};
    })};
}"""
"""The shot table's box across and every shown cell's, with the headers shown."""


def _done(page, shot: int) -> None:
    """Wait until shot `shot` is in the table and has flown in every view (its path drawn whole)."""
    page.wait_for_selector(f"#shots tbody tr[data-shot='{shot}']", timeout=10_000)
    for view in ("behind", "side", "top"):
        page.wait_for_selector(f"#{view} polyline.latest[data-done]", state="attached", timeout=10_000)


def _set_pin(page, text: str) -> None:
    """Type the pin's distance in the header's field, as a golfer does (the field commits on Enter)."""
    page.fill("#pin", text)
    page.press("#pin", "Enter")


def _every_path_inside(page) -> dict:
    """Every path of the behind, side and top views inside its picture, in its own units and on screen; the behind
    view's with APEX_MARGIN of sky above its highest point. The behind view's picture."""
    for view in ("behind", "side", "top"):
        picture = page.evaluate(PICTURE, view)
        width, height = picture["width"], picture["height"]
        top = APEX_MARGIN * height if view == "behind" else 0.0
        left, up, right, down = picture["screen"]
        assert picture["paths"], view
        for path in picture["paths"]:
            xs, ys = [x for x, _ in path["points"]], [y for _, y in path["points"]]
            assert 0 <= min(xs) and max(xs) <= width and top <= min(ys) and max(ys) <= height, (view, path["shot"])
            x0, y0, x1, y1 = path["screen"]
            assert left - 0.5 <= x0 and x1 <= right + 0.5 and up + top - 0.5 <= y0 and y1 <= down + 0.5, (view, path)
    dots = page.evaluate(LABELS, "#dispersion circle")
    left, up, right, down = page.evaluate(PICTURE, "dispersion")["screen"]
    for dot in dots:
        x0, y0, x1, y1 = dot["box"]
        assert left - 0.5 <= x0 and x1 <= right + 0.5 and up - 0.5 <= y0 and y1 <= down + 0.5, dot
    assert dots
    return page.evaluate(PICTURE, "behind")


def _the_high_wedge_framed_with_its_heights(page, http) -> dict:
    """The high wedge whole in the behind view, its highest point a margin below the top (the golfer's camera cut
    it off: the camera widens just enough), with level lines of height at its apex, labelled, its apex marked
    above the 20 yd level (an apex of 26 yd)."""
    reply = http.post("/v1/shots?viewer=true", json=HIGH_WEDGE, headers=KEYED).json()
    assert 25.0 < reply["apex_yd"] < 28.0
    _done(page, 1)
    picture = _every_path_inside(page)
    (path,) = picture["paths"]
    highest = min(y for _, y in path["points"])
    behind = page.evaluate("window.golfflightViewer.behind")
    camera = behind["camera"]
    assert 55 < camera["fov_deg"] <= 90 and camera["back_m"] == 3 and camera["height_m"] == 1.6
    levels = {label["text"]: label["line_y"] for label in behind["heights"]}
    assert list(levels) == ["10 yd", "20 yd"] and levels["20 yd"] < levels["10 yd"]
    apex_y = float(page.get_attribute("#behind line.apex-mark", "y1"))
    assert highest <= apex_y < levels["20 yd"], "the apex reads 26 yd: above the 20 yd level"
    caption = page.text_content("#behind text.height-caption")
    assert caption == f"heights {math.floor(_apex_distance_yd(page) + 0.5)} yd out", caption
    print(f"high wedge: the path's top {highest:.0f} px below the top of {picture['height']} px, "
          f"camera {camera['fov_deg']:.1f}° tilted {camera['pitch_deg']:.1f}°, heights {list(levels)}, {caption}")
    return reply


def _apex_distance_yd(page) -> float:
    """How far out the newest shot's apex is, yards, from its event's trajectory as the page holds it."""
    return page.evaluate("""() => {
      const points = state.shots[state.shots.length - 1].event.flight.trajectory;
      return points.reduce((a, p) => (p.z_m > a.z_m ? p : a)).y_m / 0.9144;
    }""")


def _scales(page, view: str, unit: str) -> tuple[list[str], list[str]]:
    """A view's distance labels (downrange) and lateral labels, each whole inside its picture and with its unit;
    the lateral ones either side of the target line."""
    left, top, right, bottom = page.evaluate(PICTURE, view)["screen"]
    along = page.evaluate(LABELS, f"#{view} text.along")
    lateral = page.evaluate(LABELS, f"#{view} text.lateral")
    for label in along + lateral:
        x0, y0, x1, y1 = label["box"]
        assert left - 0.5 <= x0 and x1 <= right + 0.5 and top - 0.5 <= y0 and y1 <= bottom + 0.5, (view, label)
    along_texts, lateral_texts = [a["text"] for a in along], [a["text"] for a in lateral]
    assert len(along_texts) >= 3 and all(text.endswith(f" {unit}") for text in along_texts), along_texts
    assert any(text.endswith(f" {unit} L") for text in lateral_texts), lateral_texts
    assert any(text.endswith(f" {unit} R") for text in lateral_texts), lateral_texts
    assert len(page.locator(f"#{view} line.lateral").all()) >= 2
    return along_texts, lateral_texts


def _pin_in_every_view(page, pin_m: float, label: str, on_grid: bool = True) -> None:
    """The pin's flag in every view, its label in the top and dispersion views; where the pin is at a round
    distance (`on_grid`), on the behind view's distance line of that distance and the top and dispersion views' grid
    lines of it."""
    mark = f"{pin_m:.2f}"
    hole = {view: page.locator(f"#{view} g.pin ellipse.pin-hole") for view in ("behind", "side", "top", "dispersion")}
    for view, ellipse in hole.items():
        assert ellipse.count() == 1 and page.get_attribute(f"#{view} g.pin", "data-m") == mark, view
    for view in ("top", "dispersion"):
        assert page.locator(f"#{view} text.pin-label").all_text_contents() == [label], view
    if not on_grid:
        return
    behind_line = page.locator(f"#behind line.marker-line[data-m='{mark}']")
    assert coordinate(hole["behind"], "cy") == pytest.approx(coordinate(behind_line, "y1"), abs=0.6)
    top_line = page.locator(f"#top line.grid[data-m='{mark}']")
    assert coordinate(hole["top"], "cx") == pytest.approx(coordinate(top_line, "x1"), abs=0.6)
    dispersion_line = page.locator(f"#dispersion line.grid[data-m='{mark}']")
    assert coordinate(hole["dispersion"], "cy") == pytest.approx(coordinate(dispersion_line, "y1"), abs=0.6)


def coordinate(locator, name: str) -> float:
    """An SVG element's coordinate attribute (cx, y1, ...), in its picture's pixels."""
    return float(locator.get_attribute(name))


def _to_pin(reply: dict, pin_m: float) -> float:
    """The rest's distance to the pin, metres."""
    return math.hypot(reply["rest"]["x_m"], reply["rest"]["y_m"] - pin_m)


@WITH_BROWSER
@pytest.mark.parametrize("width", [400, 1280])
def test_every_shot_inside_every_picture_with_scales_and_a_pin(width):
    with live_viewer(width, 900) as (page, http, port, errors):
        page.wait_for_function("() => document.querySelector('#bay-summary').textContent !== '—'", timeout=10_000)
        assert not page.is_visible("#n-to-pin")  # no pin until one is set
        _set_pin(page, "100")
        assert page.evaluate("localStorage.getItem('golfflight-pin-m')") == str(100 * YARD_M)
        pin_m = 100 * YARD_M
        wedge = _the_high_wedge_framed_with_its_heights(page, http)
        assert page.inner_text("#n-to-pin") == f"{_to_pin(wedge, pin_m) / YARD_M:.1f}yd"
        _pin_in_every_view(page, pin_m, "pin 100 yd")
        for view in ("top", "dispersion"):
            along, lateral = _scales(page, view, "yd")
            print(f"{width} px, {view}: {along} {lateral}")

        assert http.post("/v1/shots?viewer=true", json=SLICED_DRIVE, headers=KEYED).status_code == 200
        gspro_over_tcp(port, 1, IRON_BALL)  # the last shot: its rest measured to the pin
        _done(page, 3)
        _every_path_inside(page)  # the wedge as well as a 300 yd drive far left
        iron = page.evaluate("state.shots[state.shots.length - 1].event.flight")
        assert page.inner_text("#n-to-pin") == f"{_to_pin(iron, pin_m) / YARD_M:.1f}yd"

        page.click(".units button[data-units=metric]")  # the bay's units: every scale and the pin follow
        page.wait_for_function("() => document.querySelector('#pin-unit').textContent === 'm'", timeout=10_000)
        assert page.input_value("#pin") == "91.4" and page.inner_text("#n-to-pin").endswith("m")
        _pin_in_every_view(page, pin_m, "pin 91 m", on_grid=False)
        for view in ("top", "dispersion"):
            _scales(page, view, "m")
        assert all(label["text"].endswith(" m") for label in page.evaluate("window.golfflightViewer.behind.heights"))

        page.reload()  # the pin is this browser's: kept
        _done(page, 3)
        assert page.input_value("#pin") == "91.4" and page.locator("#top g.pin").count() == 1
        _set_pin(page, "")  # an empty field takes the pin away
        assert page.locator("svg g.pin").count() == 0 and not page.is_visible("#n-to-pin")
        assert errors == []


@WITH_BROWSER
@pytest.mark.parametrize("width", [400, 1280])
def test_the_shot_table_fits_its_box_with_every_column_shown_whole(width):
    """The widest cells a session has (a putt's mark beside its club, a 185 mph drive 106.6 yd left, three-figure
    carries) in yards and in metres: the table no wider than its box, every column shown inside it."""
    with live_viewer(width, 900) as (page, http, port, errors):
        pick_club(page, "PT")
        gspro_over_tcp(port, 1, PUTT_BALL)
        pick_club(page, "LW")
        gspro_over_tcp(port, 2, {**IRON_BALL, "HLA": -8.0, "SpinAxis": -30.0})
        assert http.post("/v1/shots?viewer=true", json=SLICED_DRIVE, headers=KEYED).status_code == 200
        page.wait_for_selector("#shots tbody tr[data-shot='3']", timeout=10_000)
        for units in ("imperial", "metric"):
            if units == "metric":
                page.click(".units button[data-units=metric]")
                page.wait_for_function("() => document.querySelector('#shots thead').textContent.includes('(m)')",
                                       timeout=10_000)
            scroll = page.locator(".shots .scroll")
            sizes = scroll.evaluate("e => [e.scrollWidth, e.clientWidth]")
            assert sizes[0] <= sizes[1], (units, sizes)
            table = page.evaluate(CELLS)
            left, right = table["scroll"]
            for cell in table["cells"]:
                assert left - 0.5 <= cell["x"][0] and cell["x"][1] <= right + 0.5, (units, cell)
            unit = "yd" if units == "imperial" else "m"
            speed = "mph" if units == "imperial" else "m/s"
            narrow = ["#", "club", f"ball speed ({speed})", f"carry ({unit})", f"total ({unit})", f"lateral ({unit})"]
            assert table["heads"] == narrow if width == 400 else len(table["heads"]) == 11, table["heads"]
            assert "106.6 L" in page.inner_text("#shots tbody") or units == "metric"
            print(f"{width} px, {units}: table {sizes[0]} of {sizes[1]} px, columns {table['heads']}")
        assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth") and errors == []
