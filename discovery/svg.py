"""Tiny static SVG charts (lines, histograms) for the docs' figures of the real sets
(`python -m golfflight.discovery.real --figures`): files a markdown page shows as images, made without a plotting
library. report.html's interactive figures are `discovery.figures`."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from html import escape

import numpy as np

WIDTH, HEIGHT = 420, 260
LEFT, RIGHT, TOP, BOTTOM = 58, 12, 26, 40
_CLIP_IDS = itertools.count()
COLORS = ("#888888", "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e")


def nice_ticks(low: float, high: float, count: int = 5) -> np.ndarray:
    """Round tick values covering [low, high]."""
    if not np.isfinite(low) or not np.isfinite(high) or high <= low:
        return np.array([low])
    raw = (high - low) / count
    magnitude = 10 ** np.floor(np.log10(raw))
    step = magnitude * min((1, 2, 2.5, 5, 10), key=lambda m: abs(m * magnitude - raw))
    return np.arange(np.ceil(low / step) * step, high + 1e-9 * step, step)


@dataclass
class Chart:
    """One chart: data ranges, axis labels and SVG elements drawn in data coordinates."""

    title: str
    xlabel: str
    ylabel: str
    xlim: tuple[float, float]
    ylim: tuple[float, float]
    parts: list[str] = field(default_factory=list)
    legend: list[tuple[str, str]] = field(default_factory=list)

    def x(self, v: np.ndarray) -> np.ndarray:
        lo, hi = self.xlim
        return LEFT + (np.asarray(v, dtype=float) - lo) / (hi - lo) * (WIDTH - LEFT - RIGHT)

    def y(self, v: np.ndarray) -> np.ndarray:
        lo, hi = self.ylim
        return HEIGHT - BOTTOM - (np.asarray(v, dtype=float) - lo) / (hi - lo) * (HEIGHT - TOP - BOTTOM)

    def line(
        self,
        x: np.ndarray,
        y: np.ndarray,
        color: str,
        label: str | None = None,
        dashed: bool = False,
        width: float = 1.6,
    ) -> None:
        keep = np.isfinite(x) & np.isfinite(y)
        if keep.sum() < 2:
            return
        path = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(self.x(x[keep]), self.y(y[keep])))
        dash = ' stroke-dasharray="5,3"' if dashed else ""
        self.parts.append(f'<polyline points="{path}" fill="none" stroke="{color}" stroke-width="{width}"{dash}/>')
        if label:
            self.legend.append((label, color))

    def rect(self, x0: float, x1: float, y0: float, y1: float, color: str, opacity: float = 0.45) -> None:
        ax, bx = sorted(self.x(np.array([x0, x1])))
        ay, by = sorted(self.y(np.array([y0, y1])))
        self.parts.append(
            f'<rect x="{ax:.1f}" y="{ay:.1f}" width="{bx - ax:.1f}" height="{by - ay:.1f}" '
            f'fill="{color}" fill-opacity="{opacity}"/>'
        )

    def render(self) -> str:
        out = [
            (
                f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" font-family="sans-serif" '
                f'font-size="10"><rect width="100%" height="100%" fill="white"/>'
            ),
            f'<text x="{WIDTH / 2}" y="15" text-anchor="middle" font-size="12">{escape(self.title)}</text>',
        ]
        x0, x1, y0, y1 = LEFT, WIDTH - RIGHT, TOP, HEIGHT - BOTTOM
        out.append(f'<rect x="{x0}" y="{y0}" width="{x1 - x0}" height="{y1 - y0}" fill="none" stroke="#333"/>')
        for t in nice_ticks(*self.xlim):
            px = float(self.x(t))
            out.append(
                f'<line x1="{px:.1f}" y1="{y1}" x2="{px:.1f}" y2="{y1 + 4}" stroke="#333"/>'
                f'<text x="{px:.1f}" y="{y1 + 14}" text-anchor="middle">{t + 0.0:g}</text>'
            )
        for t in nice_ticks(*self.ylim):
            py = float(self.y(t))
            out.append(
                f'<line x1="{x0 - 4}" y1="{py:.1f}" x2="{x0}" y2="{py:.1f}" stroke="#333"/>'
                f'<text x="{x0 - 6}" y="{py + 3:.1f}" text-anchor="end">{t + 0.0:g}</text>'
            )
        if self.ylim[0] < 0 < self.ylim[1]:
            py = float(self.y(0.0))
            out.append(f'<line x1="{x0}" y1="{py:.1f}" x2="{x1}" y2="{py:.1f}" stroke="#bbb"/>')
        out.append(f'<text x="{(x0 + x1) / 2}" y="{HEIGHT - 6}" text-anchor="middle">{escape(self.xlabel)}</text>')
        out.append(
            f'<text transform="translate(12,{(y0 + y1) / 2}) rotate(-90)" text-anchor="middle">'
            f"{escape(self.ylabel)}</text>"
        )
        clip = f"clip{next(_CLIP_IDS)}"
        out.append(
            f'<clipPath id="{clip}"><rect x="{x0}" y="{y0}" width="{x1 - x0}" height="{y1 - y0}"/></clipPath>'
            f'<g clip-path="url(#{clip})">{"".join(self.parts)}</g>'
        )
        for i, (label, color) in enumerate(dict.fromkeys(self.legend)):
            out.append(
                f'<rect x="{x0 + 6}" y="{y0 + 6 + 12 * i}" width="8" height="8" fill="{color}"/>'
                f'<text x="{x0 + 18}" y="{y0 + 14 + 12 * i}">{escape(label)}</text>'
            )
        out.append("</svg>")
        return "".join(out)


def _limits(*arrays: np.ndarray, pad: float = 0.05) -> tuple[float, float]:
    values = np.concatenate([np.ravel(a)[np.isfinite(np.ravel(a))] for a in arrays] or [np.zeros(1)])
    if values.size == 0:
        return 0.0, 1.0
    lo, hi = np.quantile(values, [0.005, 0.995])
    if hi <= lo:
        lo, hi = lo - 1, hi + 1
    span = hi - lo
    return float(lo - pad * span), float(hi + pad * span)


def histogram(title: str, xlabel: str, series: list[tuple[np.ndarray, str]], bins: int = 30) -> str:
    """Overlaid density histograms of each (values, label)."""
    lo, hi = _limits(*[s[0] for s in series], pad=0.0)
    edges = np.linspace(lo, hi, bins + 1)
    counts = [np.histogram(np.clip(v[np.isfinite(v)], lo, hi), edges, density=True)[0] for v, _ in series]
    chart = Chart(title, xlabel, "density", (lo, hi), (0.0, max(float(np.max(c)) for c in counts) * 1.1 or 1.0))
    for (_, label), c, color in zip(series, counts, COLORS):
        for a, b, h in zip(edges[:-1], edges[1:], c):
            chart.rect(a, b, 0.0, h, color, 0.35)
        chart.legend.append((label, color))
    return chart.render()


def lines(title: str, xlabel: str, ylabel: str, series: list[tuple[np.ndarray, np.ndarray, str, int, bool]]) -> str:
    """Curves (x, y, label, colour index, dashed)."""
    chart = Chart(
        title, xlabel, ylabel, _limits(*[s[0] for s in series], pad=0.02), _limits(*[s[1] for s in series], pad=0.05)
    )
    for x, y, label, color, dashed in series:
        chart.line(x, y, COLORS[color % len(COLORS)], label, dashed)
    return chart.render()
