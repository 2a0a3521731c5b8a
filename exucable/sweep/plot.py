"""``sweep.png``: the chosen output against the first varied key, one line per combination of the
other keys (grid) or one line (zip), the rope reference beside it as dashed lines."""

from __future__ import annotations

import json
import math
import numbers

from matplotlib import rcParams

from ..io import new_figure, save_figure
from .spec import OUTPUTS

__all__ = ["plot_sweep"]

_LABELS = {
    "pull_force_N": "pulling force [N]",
    "trailing_tension_N": "trailing-end tension [N]",
    "max_tension_N": "largest tension [N]",
    "max_sidewall_pressure_N_per_m": "largest sidewall pressure [N/m]",
    "wall_time_s": "wall time per case [s]",
}


def _number(v) -> float | None:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return None
    v = float(v)
    return v if math.isfinite(v) else None


def _is_numeric(values) -> bool:
    return all(_number(v) is not None for v in values)


def plot_sweep(path, rows: list[dict], keys, output: str = "pull_force_N", mode: str = "grid",
               title: str = "") -> None:
    """Draw ``output`` against ``keys[0]`` from the table rows and save it atomically as PNG.

    Failed and pending cases are left out of the lines and marked with an ``x`` on the x axis.
    A non-numeric first key is drawn on evenly spaced categories.
    """
    x_key, others = keys[0], list(keys[1:])
    rope_key = OUTPUTS.get(output)
    x_values = [r[x_key] for r in rows]
    numeric_x = _is_numeric(x_values)
    categories = {}
    if not numeric_x:
        for v in x_values:
            categories.setdefault(json.dumps(v), len(categories))

    def xpos(v):
        return float(v) if numeric_x else float(categories[json.dumps(v)])

    groups: dict[str, list[dict]] = {}
    for r in rows:
        label = "" if (mode == "zip" or not others) else ", ".join(f"{k} = {json.dumps(r[k])}" for k in others)
        groups.setdefault(label, []).append(r)

    fig = new_figure(figsize=(7.5, 4.5))
    ax = fig.subplots()
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    missing_x = []
    for n, (label, grp) in enumerate(groups.items()):
        c = colours[n % len(colours)]
        grp = sorted(grp, key=lambda r: xpos(r[x_key]))
        pts = [(xpos(r[x_key]), _number(r.get(output))) for r in grp if r.get("status") in ("ok", "steady")]
        pts = [(x, y) for x, y in pts if y is not None]
        missing_x += [xpos(r[x_key]) for r in grp if r.get("status") not in ("ok", "steady")]
        if pts:
            ax.plot(*zip(*pts), "o-", color=c, label=(label or "simulation"))
        if rope_key is not None:
            ref = [(xpos(r[x_key]), _number(r.get(rope_key))) for r in grp]
            ref = [(x, y) for x, y in ref if y is not None]
            if ref:
                ax.plot(*zip(*ref), "--", color=c, lw=1.2,
                        label=f"rope reference{', ' + label if label else ''}")
    if missing_x:
        ax.plot(missing_x, [0.0] * len(missing_x), "x", color="r", ms=9, mew=2, transform=ax.get_xaxis_transform(),
                clip_on=False, label="failed / not run")
    if not numeric_x:
        ax.set_xticks(list(categories.values()), list(categories.keys()), rotation=20)
    ax.set_xlabel(x_key)
    ax.set_ylabel(_LABELS.get(output, output))
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    save_figure(fig, path, bbox_inches="tight")
