"""A top-down picture of an episode (render_mode "rgb_array"), like the demo's: the
obstacles' footprints, the path so far, the robot's footprint, its last scan and the goal.
Drawn with matplotlib's Agg canvas into an (H, W, 3) uint8 array."""
import math

import numpy as np

from . import geometry


class TopDown:
    def __init__(self, footprints, size_px=480):
        import matplotlib
        matplotlib.use("Agg", force=False)
        from matplotlib.figure import Figure
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        self.footprints = footprints
        self.figure = Figure(figsize=(size_px / 100.0, size_px / 100.0), dpi=100)
        self.canvas = FigureCanvasAgg(self.figure)

    def draw(self, path, scan=None, goal=None, title=""):
        from matplotlib.patches import Circle, Polygon
        self.figure.clear()
        ax = self.figure.add_axes([0.02, 0.02, 0.96, 0.9])
        for polygon in self.footprints.polygons:
            ax.add_patch(Polygon(polygon, closed=True, color="0.45", lw=0))
        for x, y, r in self.footprints.circles:
            ax.add_patch(Circle((x, y), r, color="0.45", lw=0))
        path = np.asarray(path, dtype=float).reshape(-1, 3)
        if len(path) > 1:
            ax.plot(path[:, 0], path[:, 1], color="tab:blue", lw=1.2)
        if len(path):
            x, y, yaw = path[-1]
            if scan is not None:
                ranges, angle_min, increment = scan
                angles = yaw + angle_min + increment * np.arange(len(ranges))
                hit = np.isfinite(ranges)
                ax.scatter(x + ranges[hit] * np.cos(angles[hit]), y + ranges[hit] * np.sin(angles[hit]),
                           s=1, color="tab:red")
            ax.add_patch(Polygon(_corners(x, y, yaw), closed=True, color="tab:orange"))
            ax.plot([x, x + 0.4 * math.cos(yaw)], [y, y + 0.4 * math.sin(yaw)], color="k", lw=1)
        if goal is not None:
            ax.plot([goal[0]], [goal[1]], marker="*", color="tab:green", markersize=12)
        low, high = self.footprints.bounds
        ax.set_xlim(low[0] - 0.5, high[0] + 0.5)
        ax.set_ylim(low[1] - 0.5, high[1] + 0.5)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(title, fontsize=8)
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()


def _corners(x, y, yaw):
    (x0, x1), (y0, y1) = geometry.FOOTPRINT_X, geometry.FOOTPRINT_Y
    c, s = math.cos(yaw), math.sin(yaw)
    return [(x + c * px - s * py, y + s * px + c * py)
            for px, py in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
