"""The demo's top-down picture (PNG, matplotlib's Agg backend, no display needed).

Draws, in world coordinates [m] with equal aspect: the obstacles cut at scan height
(scene.Outline polygons and circles), the trajectory coloured by sim time with a colorbar,
the start and end poses as arrows, the last scan's beams from the sensor to each finite
return, the collisions (if any) as crosses, and a 1 m (or 2 m) scale bar.
"""
import math

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt                                   # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.legend_handler import HandlerPatch                # noqa: E402
from matplotlib.lines import Line2D                              # noqa: E402
from matplotlib.patches import Circle, FancyArrow, Polygon       # noqa: E402
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar  # noqa: E402
import numpy as np                                               # noqa: E402

OBSTACLE_COLOUR = "#7f7f7f"
BEAM_COLOUR = "#d62728"


class _ArrowHandler(HandlerPatch):
    """Legend entry of a pose arrow: a small arrow, not a filled box."""

    def create_artists(self, legend, orig_handle, xdescent, ydescent, width, height,
                       fontsize, trans):
        arrow = FancyArrow(0, height / 2.0, width, 0, width=height / 4.0, head_width=height,
                           head_length=height * 0.8, length_includes_head=True,
                           color=orig_handle.get_facecolor(), transform=trans)
        return [arrow]


def beam_segments(origin, yaw, angle_min, angle_increment, ranges):
    """(n, 2, 2) segments from the sensor at `origin` (x, y) [m] heading `yaw` [rad] to each
    finite return of a planar scan (index i at angle_min + i * angle_increment [rad])."""
    ranges = np.asarray(ranges, dtype=float)
    angles = yaw + angle_min + angle_increment * np.arange(len(ranges))
    hit = np.isfinite(ranges)
    ends = np.stack([origin[0] + ranges[hit] * np.cos(angles[hit]),
                     origin[1] + ranges[hit] * np.sin(angles[hit])], axis=1)
    starts = np.broadcast_to(np.asarray(origin[:2], dtype=float), ends.shape)
    return np.stack([starts, ends], axis=1)


def scale_length(span):
    """A round scale-bar length [m] about a tenth of `span` [m]: 0.5, 1, 2, 5, 10, ..."""
    target = max(span / 10.0, 1e-3)
    base = 10.0 ** math.floor(math.log10(target))
    for step in (1.0, 2.0, 5.0, 10.0):
        if base * step >= target:
            return base * step
    return 10.0 * base


def frame(ax, outlines, points, margin=1.0):
    """Frames the axes on every obstacle and the given (n, 2) point arrays plus a margin [m],
    in metres, x and y to scale, with a light grid; returns the (low, high) corners."""
    xy = list(points)
    for outline in outlines:
        if outline.kind == "circle":
            cx, cy, r = outline.center + (outline.radius,)
            xy.append(np.array([[cx - r, cy - r], [cx + r, cy + r]]))
        else:
            xy.append(np.asarray(outline.points))
    xy = np.vstack(xy) if xy else np.zeros((1, 2))
    low, high = xy.min(axis=0) - margin, xy.max(axis=0) + margin
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return low, high


def draw(path, outlines, times, xs, ys, yaws, beams=None, collisions=(), title="",
         margin=1.0, dpi=120):
    """Writes the picture to `path`.

    outlines: scene.Outline list; times, xs, ys, yaws: the trajectory (sim s, m, m, rad);
    beams: (n, 2, 2) segments (beam_segments) or None; collisions: [(x, y)] [m]."""
    times, xs, ys, yaws = (np.asarray(a, dtype=float) for a in (times, xs, ys, yaws))
    fig, ax = plt.subplots(figsize=(9, 8.5), dpi=dpi)
    patches = []
    for outline in outlines:
        if outline.kind == "circle":
            patches.append(Circle(outline.center, outline.radius))
        else:
            patches.append(Polygon(np.asarray(outline.points), closed=True))
    ax.add_collection(PatchCollection(patches, facecolor=OBSTACLE_COLOUR, edgecolor="#404040",
                                      linewidth=0.5, alpha=0.8, zorder=1))
    if beams is not None and len(beams):
        ax.add_collection(LineCollection(beams, colors=BEAM_COLOUR, linewidths=0.3, alpha=0.5,
                                         zorder=2, label="last scan (%d returns)" % len(beams)))
        ax.plot(beams[:, 1, 0], beams[:, 1, 1], ".", color=BEAM_COLOUR, markersize=1.2, zorder=2)
    if len(xs) >= 2:
        points = np.stack([xs, ys], axis=1)
        segments = np.stack([points[:-1], points[1:]], axis=1)
        line = LineCollection(segments, cmap="viridis", linewidths=2.0, zorder=3,
                              capstyle="round", joinstyle="round")
        line.set_array(times[:-1])
        ax.add_collection(line)
        colorbar = fig.colorbar(line, ax=ax, shrink=0.8, pad=0.02)
        colorbar.set_label("sim time [s]")
    arrow_length = 0.6     # [m]
    for index, colour, label in ((0, "#2ca02c", "start"), (-1, "#1f1f1f", "end")):
        if len(xs):
            ax.add_patch(FancyArrow(xs[index], ys[index], arrow_length * math.cos(yaws[index]),
                                    arrow_length * math.sin(yaws[index]), width=0.08,
                                    head_width=0.3, head_length=0.25, length_includes_head=True,
                                    color=colour, zorder=4, label=label))
    if len(collisions):
        c = np.asarray(collisions, dtype=float).reshape(-1, 2)
        ax.plot(c[:, 0], c[:, 1], "x", color="#ff7f0e", markersize=10, mew=2.5, zorder=5,
                label="collision (%d)" % len(c))
    points = [np.stack([xs, ys], axis=1)] if len(xs) else []
    if beams is not None and len(beams):
        points.append(beams[:, 1, :])
    low, high = frame(ax, outlines, points, margin)
    length = scale_length(float(high[0] - low[0]))
    ax.add_artist(AnchoredSizeBar(ax.transData, length, "%g m" % length, "upper right",
                                  bbox_to_anchor=(1.0, -0.07), bbox_transform=ax.transAxes,
                                  pad=0.2, borderpad=0.0, sep=3, frameon=False,
                                  size_vertical=0.04 * length))
    handles = [Line2D([], [], color=OBSTACLE_COLOUR, lw=6, label="obstacles cut at scan height")]
    handles += ax.get_legend_handles_labels()[0]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.0, -0.07), ncol=2,
              fontsize=8, frameon=False, handler_map={FancyArrow: _ArrowHandler()})
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
