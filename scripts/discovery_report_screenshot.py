"""docs/figures/discovery_report.png and discovery_report_400.png: the top of report.html from `golfflight diagnose`
on synthetic recordings, as a reader first sees it in headless Chromium, on a desktop (1280 px wide) and on a phone
(400 px wide).

The recordings: the drivers of 800 concealed shots (seed 3) flown through the reference world in air 0.912 times
as dense as assumed (a warm venue a few hundred metres up), with only the apex recorded, like a tour feed that
records no air and no carry. The diagnosis names thin air and lists the rivals apex alone cannot tell from it, with
carry as what to record next. Seeded throughout, so the page (all but its run time) is the same on every run.

    python3 scripts/discovery_report_screenshot.py [--out-dir docs/figures] [--report-dir DIR]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from golfflight.discovery.conceal import conceal
from golfflight.discovery.diagnose import Diagnosis, diagnose
from golfflight.discovery.model import reference
from golfflight.discovery.outputs import write_diagnosis
from golfflight.discovery.recordings import from_shot_set
from golfflight.shots.records import ShotSet

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from browser import headless_page, missing

AIR_RATIO = 0.912
"""The concealed air density, true/assumed (East Lake's in issue 32: 0.912 × ICAO)."""
UNRECORDED = {"carry_y_m": None, "carry_x_m": None, "flight_time_s": None, "landing_angle_deg": None}
"""The outcomes the synthetic feed leaves out: only the apex is recorded."""
VIEWS = (("discovery_report.png", 1280, 1500), ("discovery_report_400.png", 400, 1400))
"""Each picture: its file name, the browser window's width and the picture's height (the title, the headline and the
verdict, on the desktop also the first table)."""


def synthetic_diagnosis(quiet: bool = True) -> Diagnosis:
    """The diagnosis of the drivers of concealed thin-air shots with only the apex recorded."""
    concealed = conceal({"air_density": {"ratio": AIR_RATIO}}, 800, seed=3)
    records = [r.model_copy(update=UNRECORDED) for r in concealed.shots.records if r.club == "Driver"]
    source = f"Synthetic drivers, air {AIR_RATIO} × assumed, apex only"
    recordings = from_shot_set(ShotSet(records), source=source)
    return diagnose(recordings, reference(), seed=0, with_correction=False, progress=not quiet)


def screenshot(page_file: Path, out: Path, width: int, height: int) -> None:
    """The first width × height pixels of the page in a headless Chromium window that wide, once every figure is
    drawn."""
    with headless_page(width, 1000) as page:
        page.goto(page_file.as_uri())
        page.wait_for_function(
            "[...document.querySelectorAll('.plotly-graph-div')].every(d => d.querySelector('.main-svg'))",
            timeout=30_000,
        )
        out.parent.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(out), full_page=True, clip={"x": 0, "y": 0, "width": width, "height": height})
    quantize(out)


def quantize(png: Path, colors: int = 128) -> None:
    """The picture in `colors` colours, undithered: a page of text and rules looks the same at a third of the size."""
    from PIL import Image  # Pillow comes with matplotlib (the extra `train`, in `dev`)

    with Image.open(png) as image:
        small = image.convert("RGB").quantize(colors, Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    small.save(png, optimize=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=Path("docs/figures"), help="where the pictures go")
    parser.add_argument(
        "--report-dir", type=Path, help="keep report.html, report.json here (default: a temporary folder)"
    )
    args = parser.parse_args()
    if missing():
        raise SystemExit(f"cannot take the screenshot: {missing()}")
    diagnosis = synthetic_diagnosis()
    with tempfile.TemporaryDirectory() as scratch:
        folder = args.report_dir or Path(scratch)
        page_file = write_diagnosis(diagnosis, folder)[1]
        for name, width, height in VIEWS:
            screenshot(page_file, args.out_dir / name, width, height)
            print(f"wrote {args.out_dir / name}")
    print(f"from {diagnosis.report.n_shots} shots: {' '.join(diagnosis.report.headline)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
