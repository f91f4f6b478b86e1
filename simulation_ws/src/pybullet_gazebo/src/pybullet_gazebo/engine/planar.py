"""Geometry on the ground plane (x, y [m]), shared by the tools that look at a world from above
(the gym's footprints, the demo's scene cuts). Plain math: no pybullet, no ROS.

- `convex_hull(points)`: the counter-clockwise convex hull of 2-D points, without repeated or
  collinear points: a corner whose turn is within rounding noise (|cross product| <=
  1e-12 m^2, e.g. two crossings at one vertex of a cut) is dropped. `decimals`: round the
  coordinates first (9: points 1 nm apart merge, as a box's top and bottom corners seen from
  above do; the gym's footprints use it).
"""
from typing import List, Optional, Tuple

_COLLINEAR = 1e-12           # [m^2] |cross product| at or below which three points are in line


def convex_hull(points, decimals: Optional[int] = None) -> List[Tuple[float, float]]:
    """Counter-clockwise convex hull of 2-D points (Andrew's monotone chain), starting at the
    lowest-x (then lowest-y) point; fewer than 3 distinct points are returned sorted.
    `decimals`: coordinates rounded to this many decimals first (None: as given)."""
    if decimals is None:
        pts = sorted(set((float(x), float(y)) for x, y in points))
    else:
        pts = sorted(set((round(float(x), decimals), round(float(y), decimals))
                         for x, y in points))
    if len(pts) <= 2:
        return pts

    def turns_left(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) > _COLLINEAR

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and not turns_left(lower[-2], lower[-1], p):
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and not turns_left(upper[-2], upper[-1], p):
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]
