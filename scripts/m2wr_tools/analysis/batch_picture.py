"""A batch's pictures (PNG, matplotlib's Agg backend), over the world cut at scan height:

  trajectories.png  every run's path, green when it succeeded, red when it failed, a dot at
                    each start and a cross where a failed run ended
  starts.png        the start poses as arrows: left coloured by success, right by the run's
                    minimum clearance [m] (a colour bar)
"""
import math

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt                                  # noqa: E402
from matplotlib.collections import PatchCollection               # noqa: E402
from matplotlib.lines import Line2D                              # noqa: E402
from matplotlib.patches import Circle, FancyArrow, Polygon                  # noqa: E402
import numpy as np                                               # noqa: E402

from .picture import frame                                       # noqa: E402

SUCCESS, FAILURE = "#2ca02c", "#d62728"
ARROW = 0.9                  # [m] length of a start pose's arrow


def _obstacles(ax, outlines):
    patches = [Circle(o.center, o.radius) if o.kind == "circle"
               else Polygon(np.asarray(o.points), closed=True) for o in outlines]
    ax.add_collection(PatchCollection(patches, facecolor="#7f7f7f", edgecolor="#404040",
                                      linewidth=0.5, alpha=0.8, zorder=1))


def _frame(ax, outlines, records, margin=1.0):
    """The map framed on the obstacles, every start and every path."""
    points = [np.asarray(r["path"])[:, 1:3] for r in records if r.get("path")]
    points.append(np.array([[r["x"], r["y"]] for r in records]).reshape(-1, 2))
    frame(ax, outlines, points, margin)


def trajectories(path, outlines, records, title=""):
    fig, ax = plt.subplots(figsize=(9, 8.5), dpi=110)
    _obstacles(ax, outlines)
    for r in records:
        colour = SUCCESS if r.get("success") else FAILURE
        if r.get("path"):
            p = np.asarray(r["path"])
            ax.plot(p[:, 1], p[:, 2], "-", color=colour, linewidth=1.0, alpha=0.7, zorder=2)
            if not r.get("success"):
                ax.plot(p[-1, 1], p[-1, 2], "x", color=colour, markersize=6, mew=1.5, zorder=4)
        ax.plot(r["x"], r["y"], "o", color=colour, markersize=3.5, zorder=3)
    ok = sum(1 for r in records if r.get("success"))
    ax.legend(handles=[Line2D([], [], color=SUCCESS, label="succeeded (%d)" % ok),
                       Line2D([], [], color=FAILURE, label="failed (%d)" % (len(records) - ok)),
                       Line2D([], [], color="k", marker="o", ls="", markersize=3.5, label="start"),
                       Line2D([], [], color="k", marker="x", ls="", label="end of a failed run"),
                       Line2D([], [], color="#7f7f7f", lw=6, label="obstacles at scan height")],
              loc="upper left", bbox_to_anchor=(0.0, -0.07), ncol=3, fontsize=8, frameon=False)
    _frame(ax, outlines, records)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def starts(path, outlines, records, title=""):
    fig, axes = plt.subplots(1, 2, figsize=(15, 7), dpi=110)
    clear = np.array([r.get("min_clearance_m") if r.get("min_clearance_m") is not None
                      else np.nan for r in records], dtype=float)
    finite = clear[np.isfinite(clear)]
    norm = matplotlib.colors.Normalize(vmin=min(0.0, finite.min()) if len(finite) else 0.0,
                                       vmax=max(1.0, finite.max()) if len(finite) else 1.0)
    cmap = plt.get_cmap("viridis")
    for ax, by in zip(axes, ("success", "clearance")):
        _obstacles(ax, outlines)
        for r, c in zip(records, clear):
            if by == "success":
                colour = SUCCESS if r.get("success") else FAILURE
            else:
                colour = cmap(norm(c)) if math.isfinite(c) else "#bbbbbb"
            ax.add_patch(FancyArrow(r["x"], r["y"], ARROW * math.cos(r["yaw"]),
                                    ARROW * math.sin(r["yaw"]), width=0.12, head_width=0.45,
                                    head_length=0.35, length_includes_head=True, color=colour,
                                    zorder=3))
        _frame(ax, outlines, [dict(r, path=None) for r in records])
        ax.set_title("start poses by %s" % ("outcome (green succeeded, red failed)"
                                             if by == "success" else "minimum clearance"),
                     fontsize=10)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes[1],
                       shrink=0.8)
    bar.set_label("minimum clearance over the run [m]")
    fig.suptitle(title, fontsize=10)
    fig.savefig(path)
    plt.close(fig)
    return path
