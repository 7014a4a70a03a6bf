"""Pictures for the HTML report, as inline SVG drawn by matplotlib
(the optional extra ``[plots]``; no pyplot, no display: figures are rendered straight
to SVG text). Without matplotlib every function returns None and the report says that
plots are off.

- :func:`trace_chart`: a motion trace (``CaseResult.traces``) — position and rate
  against time as sampled from the target, over the spec's model, with the tolerance
  band the check used (none in virtual time, where it is zero) and the trace's faults
  marked: the instant observed against the instant expected, a wrong reading against
  the positions admitted there.
- :func:`step_train_chart`: the pulses per axis of the emulator's stepper core.
"""

from __future__ import annotations

import io
import re
import threading
from collections.abc import Sequence
from functools import cache

import numpy as np

#: a line holds at most this many points (the report must stay small)
MAX_POINTS = 40
#: the step train shows at most this many pulses
MAX_PULSES = 120
#: a fault's colour: the FAIL verdict's of the page's bars (report.css)
FAIL_COLOUR = "#d9483b"
#: how opaque the tolerance band is drawn
BAND_ALPHA = 0.15
_AXIS_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")


@cache
def available() -> bool:
    """Whether matplotlib can be imported (the ``[plots]`` extra)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def _figure(width: float, height: float, margins: dict[str, float]):
    """A figure with fixed ``margins`` (fractions of the figure, as ``subplots_adjust``
    takes them): much faster than matplotlib's own layout, and the layout is known."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=(width, height), dpi=72)
    fig.subplots_adjust(**margins)
    return fig


def _svg(fig, key: str) -> str:
    """The figure as an SVG element for inline HTML: text as text (not glyph paths),
    no date (the same run gives the same bytes), ids salted by ``key`` so that several
    pictures on one page never share one."""
    from matplotlib import rc_context
    out = io.StringIO()
    with rc_context({"svg.fonttype": "none", "svg.hashsalt": key, "path.simplify": True}):
        fig.savefig(out, format="svg", metadata={"Date": None})
    text = out.getvalue()
    text = _METADATA.sub("", text[text.index("<svg"):])
    return _BETWEEN_TAGS.sub("><", _PATH.sub(_shorter, text))


_PATH = re.compile(r' d="([^"]*)"')
_METADATA = re.compile(r"<metadata>.*?</metadata>", re.S)
_BETWEEN_TAGS = re.compile(r">\s+<")
_DECIMALS = re.compile(r"(\d\.\d)\d+")


def _shorter(m: re.Match) -> str:
    """A path's coordinates to 0.1 pt (a tenth of a pixel at 72 dpi), on one line."""
    return ' d="' + _DECIMALS.sub(r"\1", m.group(1)).replace(" \n", " ").strip() + '"'


def _thin(points: Sequence, limit: int = MAX_POINTS) -> list:
    """At most ``limit`` points, evenly spread, the first and last kept."""
    if len(points) <= limit:
        return list(points)
    idx = np.unique(np.linspace(0, len(points) - 1, limit).round().astype(int))
    return [points[i] for i in idx]


def _columns(series: Sequence) -> tuple[np.ndarray, np.ndarray]:
    """(times, positions[point, axis]) of a trace's [(t_s, [pos...])]."""
    if not series:
        return np.zeros(0), np.zeros((0, 0))
    return (np.array([float(t) for t, _ in series]),
            np.array([[float(p) for p in pos] for _, pos in series]))


def _rate(t: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rate (steps/s) between consecutive points, at their midpoints."""
    if len(t) < 2:
        return np.zeros(0), np.zeros((0, pos.shape[1] if pos.ndim == 2 else 0))
    dt = np.diff(t)
    dt[dt == 0] = np.nan
    return (t[:-1] + t[1:]) / 2, np.diff(pos, axis=0) / dt[:, None]


def _band(t: np.ndarray, model_t: np.ndarray, model: np.ndarray, seconds: float,
          steps: float) -> tuple[np.ndarray, np.ndarray]:
    """What the tolerance admits around the model: at each instant, anything the model
    passes within ±seconds, widened by ±steps."""
    shifted = np.stack([np.interp(t + d, model_t, model) for d in (-seconds, 0.0, seconds)])
    return shifted.min(axis=0) - steps, shifted.max(axis=0) + steps


def band_text(seconds: float, steps: float) -> str:
    """The tolerance band for a caption; none where it is zero (virtual time: exact)."""
    if not seconds and not steps:
        return ""
    return f"band: ±{seconds * 1e3:.3f} ms, ±{steps:g} step(s)"


def trace_chart(trace: dict, key: str, rate: bool = True) -> str | None:
    """Position (and ``rate``) against time: the target's samples over the model, the
    tolerance band around it (where it has a width) and the trace's faults marked."""
    if not available():
        return None
    st, sp = _columns(_thin(trace.get("samples") or []))
    mt, mp = _columns(trace.get("model") or [])
    tol = trace.get("tolerance") or {}
    seconds, steps = float(tol.get("seconds", 0.0)), float(tol.get("steps", 0.0))
    faults = trace.get("faults") or []
    names = trace.get("axes") or ["X", "Y", "Z", "A"]
    width = max(sp.shape[1] if sp.size else 0, mp.shape[1] if mp.size else 0)
    moving = sorted({i for i in range(width)
                     if (sp.size and np.ptp(sp[:, i]) > 0) or (mp.size and np.ptp(mp[:, i]) > 0)}
                    | {f["axis"] for f in faults if f.get("kind") == "position"
                       and f["axis"] < width})
    with _CANVAS_LOCK:
        fig, pos_ax, rate_ax = _blank(*_canvas(rate))
        for i in moving or range(min(width, 1)):
            colour, name = _AXIS_COLOURS[i % 4], names[i] if i < len(names) else f"axis {i}"
            if mp.size:
                grid = np.linspace(mt[0], mt[-1], MAX_POINTS)
                model_i = np.interp(grid, mt, mp[:, i])
                if seconds or steps:
                    lo, hi = _band(grid, mt, mp[:, i], seconds, steps)
                    pos_ax.fill_between(grid, lo, hi, color=colour, alpha=BAND_ALPHA, linewidth=0)
                pos_ax.plot(grid, model_i, "--", color=colour, linewidth=1, label=f"{name} model")
                if rate_ax is not None:
                    rt, rv = _rate(grid, model_i[:, None])
                    rate_ax.plot(rt, rv[:, 0], "--", color=colour, linewidth=1)
            if sp.size:
                # samples are readings (PF) at instants: points, not a line between them
                pos_ax.plot(st, sp[:, i], "o", color=colour, markersize=3.5, label=f"{name} read")
                if rate_ax is not None:
                    rt, rv = _rate(st, sp[:, i:i + 1])
                    rate_ax.plot(rt, rv[:, 0], "o", color=colour, markersize=3.5)
        _mark_faults(faults, pos_ax, rate_ax)
        title = trace.get("name", "motion")
        params = trace.get("params") or {}
        if params:
            title += "  (" + ", ".join(f"{k} {v}" for k, v in params.items()) + ")"
        pos_ax.set_title(title, fontsize=9, y=1.0)
        pos_ax.set_ylabel("position (steps)")
        if rate_ax is not None:
            rate_ax.set_ylabel("rate (steps/s)")
        band = band_text(seconds, steps)
        (rate_ax or pos_ax).set_xlabel("time (s)" + (f"; {band}" if band else ""))
        if pos_ax.get_legend_handles_labels()[0]:
            pos_ax.legend(fontsize=7, ncols=2)
        for ax in (pos_ax, rate_ax or pos_ax):
            ax.tick_params(labelsize=8)
        return _svg(fig, key)


#: one trace chart is drawn at a time on the canvas of its shape
_CANVAS_LOCK = threading.Lock()


@cache
def _canvas(rate: bool) -> tuple:
    """The figure and axes a trace chart of this shape is drawn on, made once: laying out
    a figure and its ticks costs more than drawing the chart."""
    height = 4.4 if rate else 2.6
    fig = _figure(7.5, height, {"left": 0.12, "right": 0.98, "top": 1 - 0.3 / height,
                                "bottom": 0.5 / height, "hspace": 0.12})
    pos_ax, rate_ax = fig.subplots(2, 1, sharex=True) if rate else (fig.add_subplot(), None)
    return fig, pos_ax, rate_ax


def _blank(fig, pos_ax, rate_ax) -> tuple:
    """The canvas without the last chart: its lines, areas, marks, legend and texts gone,
    the limits to be set by what is drawn next."""
    for ax in (pos_ax, rate_ax):
        if ax is None:
            continue
        for artist in [*ax.lines, *ax.collections, *ax.patches, *ax.texts]:
            artist.remove()
        if ax.get_legend() is not None:
            ax.get_legend().remove()
        ax.set_title("")
        ax.set_xlabel("")
        ax.set_ylabel("")
        ax.relim()
        ax.set_xlim(0, 1)                   # a new axes' limits, until something is drawn
        ax.set_ylim(0, 1)
        ax.set_autoscale_on(True)
    return fig, pos_ax, rate_ax


#: how a fault is drawn: what the unit did in the verdict's red, what the spec wants black
_OBSERVED, _EXPECTED = FAIL_COLOUR, "#000000"


def _mark_faults(faults: list[dict], pos_ax, rate_ax) -> None:
    """The faults on the picture: a wrong instant as a red line where it happened and a
    black one (or span) where it should have; a wrong reading ringed in red, the
    positions the spec admits there in black (a tick, or a bar where the band is wide)."""
    readings = _thin([f for f in faults if f.get("kind") == "position"])
    for n, f in enumerate(readings):
        lo, hi = f["expected"]
        t, got = f["t"], f["observed"]
        near = lo if got < lo else hi
        pos_ax.plot([t, t], [got, near], ":", color=_OBSERVED, linewidth=1)
        if hi > lo:
            pos_ax.vlines(t, lo, hi, color=_EXPECTED, linewidth=2.5,
                          label="expected there" if n == 0 else None)
        else:
            pos_ax.plot([t], [lo], "_", color=_EXPECTED, markersize=10, markeredgewidth=2.5,
                        label="expected there" if n == 0 else None)
        pos_ax.plot([t], [got], "o", color=_OBSERVED, markersize=9, markerfacecolor="none",
                    markeredgewidth=1.6, label="read wrong" if n == 0 else None)
    for f in (f for f in faults if f.get("kind") == "instant"):
        lo, hi = f["expected"]
        for ax in (pos_ax, rate_ax):
            if ax is None:
                continue
            first = ax is pos_ax
            ax.axvline(f["observed"], color=_OBSERVED, linewidth=1.6,
                       label=f"{f['what']} {f['observed'] * 1e3:.1f} ms" if first else None)
            expected = f"{f.get('expected_what', 'expected')} {lo * 1e3:.1f} ms" + (
                f"..{hi * 1e3:.1f} ms" if hi != lo else "") + " (expected)"
            if hi > lo:
                ax.axvspan(lo, hi, color=_EXPECTED, alpha=0.2,
                           label=expected if first else None)
            else:
                ax.axvline(lo, color=_EXPECTED, linewidth=1.6, linestyle=":",
                           label=expected if first else None)


def step_train_chart(pulses: Sequence[tuple[float, int]], axes: Sequence[str], key: str,
                     total: int | None = None) -> str | None:
    """Pulses per axis as ticks against time: ``pulses`` are (t_s, mask) with bit i =
    axis i stepped and bit 4+i = it stepped backwards (the stepper core's own mask)."""
    if not available():
        return None
    shown = list(pulses[:MAX_PULSES])
    height = 0.9 + 0.35 * len(axes)
    fig = _figure(7.5, height, {"left": 0.06, "right": 0.98, "top": 1 - 0.3 / height,
                                "bottom": 0.5 / height})
    ax = fig.add_subplot()
    for i in range(len(axes)):
        for negative, alpha in ((False, 1.0), (True, 0.45)):
            times = [t for t, m in shown if m >> i & 1 and bool(m >> (4 + i) & 1) == negative]
            if times:
                ax.eventplot(times, lineoffsets=len(axes) - 1 - i, linelengths=0.7,
                             linewidths=0.7, colors=_AXIS_COLOURS[i % 4], alpha=alpha)
    ax.set_yticks(range(len(axes)), list(axes)[::-1])
    count = total if total is not None else len(pulses)
    ax.set_title(f"step train: the first {len(shown)} of {count} pulses "
                 "(pale: backwards)", fontsize=9)
    ax.set_xlabel("time (s)")
    ax.tick_params(labelsize=8)
    return _svg(fig, key)

