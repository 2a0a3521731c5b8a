"""Regenerate docs/plan_example/: `exucable plan` on the CommScope ConQuest run A-H, and preview.png,
a one-picture summary of report.html (route, tension both ways, SWBP per bend, the forward table).

Run from the repository root:  .venv/bin/python docs/plan_example/make_preview.py
"""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib.image as mpimg

from exucable.cli import main as cli_main
from exucable.io import new_figure, save_figure
from exucable.plan.report import section_rows
from exucable.scenario.units import display_unit, from_si

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def main() -> int:
    import json

    status = cli_main(["plan", str(ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml"),
                       "--out", str(HERE)])
    plan = json.loads((HERE / "plan.json").read_text())
    units = plan["inputs"]["units"]
    f, p = display_unit("force", units), display_unit("force_per_length", units)
    fig = new_figure(figsize=(13.0, 9.0), dpi=90)
    fig.suptitle(f"exucable plan — {plan['inputs']['scenario']}: recommended direction "
                 f"{plan['recommended_direction']}, {'all checks pass' if plan['passed'] else 'a check fails'}",
                 fontsize=13)
    ax = fig.add_axes((-0.02, 0.36, 0.56, 0.6))
    ax.imshow(mpimg.imread(io.BytesIO((HERE / "route.png").read_bytes()), format="png"))
    ax.set_axis_off()
    ax = fig.add_axes((0.58, 0.62, 0.4, 0.3))
    for name, style in (("forward", "-"), ("reverse", "--")):
        prof = plan["directions"][name]["profile"]
        ax.plot([from_si(s, "length", units) for s in prof["s_m"]],
                [from_si(t, "force", units) for t in prof["tension_N"]], style, label=name)
    ax.set_ylabel(f"tension [{f}]")
    ax.set_xlabel(f"distance from the tail [{display_unit('length', units)}]")
    ax.legend()
    ax.grid(alpha=0.3)
    ax = fig.add_axes((0.58, 0.4, 0.4, 0.15))
    for k, name in enumerate(("forward", "reverse")):
        v = [from_si(r["sidewall_pressure_N_per_m"], "force_per_length", units)
             for r in plan["directions"][name]["sections"] if r["sidewall_pressure_N_per_m"] is not None]
        ax.bar([i + (k - 0.5) * 0.38 for i in range(len(v))], v, 0.38, label=name)
    ax.set_xticks(range(len(v)), [f"B{i + 1}" for i in range(len(v))])
    ax.set_ylabel(f"SWBP [{p}]")
    ax.set_xlabel("bend, in pull order")
    ax.legend(fontsize=8)
    header, rows = section_rows(plan["directions"]["forward"], units)
    cells = [["–" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v)) for v in r] for r in rows]
    ax = fig.add_axes((0.03, 0.02, 0.94, 0.3))
    ax.set_axis_off()
    ax.set_title("sections, forward pull", fontsize=10)
    table = ax.table(cellText=cells, colLabels=header, loc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    save_figure(fig, HERE / "preview.png")
    return status


if __name__ == "__main__":
    raise SystemExit(main())
