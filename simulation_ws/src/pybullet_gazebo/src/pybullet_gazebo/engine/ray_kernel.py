"""Exact ray-primitive and ray-triangle intersections for the ray caster, compiled by numba.

`nearest_hits` is the inner loop of `raycast.RayCaster.cast`: for every (shape, ray) pair
that can meet, the exact entry distance into a box (slabs), sphere, cylinder or capsule
(quadrics). `nearest_mesh_hits` does the same for triangle meshes (Moller-Trumbore on each
triangle of a mesh whose bounding sphere the ray meets). Written as plain loops and compiled to machine code, it does in ~0.05 ms what
the same arithmetic spread over numpy array calls did in ~0.4 ms for a 720-beam scan (numpy's
cost there was the ~100 calls, not the arithmetic).

numba caches the compiled code next to this file (__pycache__/*.nbi, *.nbc), or in
NUMBA_CACHE_DIR when that folder is read-only: the first cast after an edit or a fresh clone
compiles for ~1 s; scripts/setup.sh does it once (`warm_up`).

Arithmetic follows IEEE as numpy does (error_model="numpy"): a ray parallel to a face divides
by zero into an infinity, which the slab test needs; NaN from 0 * inf is handled as numpy's
fmin/fmax do (the other operand wins).
"""
import math

import numpy as np
from numba import njit

SPHERE, BOX, CYLINDER, CAPSULE = 0, 1, 2, 3     # shape kinds (sizes: see raycast._Shapes)
NO_FAN = np.zeros(8)           # the kernels' "the rays are not a known fan": every ray tried
FAN_MARGIN = 2                 # beams tried beyond each side of a shape's angular window
_PARALLEL = 1e-12      # squared sine below which a ray counts as parallel to a cylinder's axis
_JIT = dict(cache=True, error_model="numpy", nogil=True)


@njit(**_JIT)
def _divided_rows(rows, norms, out):
    """out[i] = rows[i] / norms[i]; False (out unfinished) when a norm is not a finite
    positive number."""
    for i in range(rows.shape[0]):
        norm = norms[i]
        if not (norm > 0.0 and norm < math.inf):
            return False
        out[i, 0] = rows[i, 0] / norm
        out[i, 1] = rows[i, 1] / norm
        out[i, 2] = rows[i, 2] / norm
    return True


def unit_rows(rows, norms):
    """rows (n, 3) divided by their norms (n,) (the same IEEE divisions numpy makes), or None
    when a norm is not a finite positive number."""
    out = np.empty((rows.shape[0], 3))
    return out if _divided_rows(np.ascontiguousarray(rows), norms, out) else None


@njit(**_JIT)
def fan_matches(fan, directions, tolerance):
    """True when the first and last of `directions` are the fan's (see _fan_windows) within
    `tolerance` in each coordinate, and the fan has a positive increment."""
    if not fan[7] > 0.0:
        return False
    last = directions.shape[0] - 1
    for index in (0, last):
        angle = fan[6] + fan[7] * index
        c, s = math.cos(angle), math.sin(angle)
        for axis in range(3):
            if not abs(c * fan[axis] + s * fan[3 + axis] - directions[index, axis]) <= tolerance:
                return False
    return True


@njit(**_JIT)
def _fmin(a, b):
    if a != a:
        return b
    if b != b:
        return a
    return a if a < b else b


@njit(**_JIT)
def _fmax(a, b):
    if a != a:
        return b
    if b != b:
        return a
    return a if a > b else b


@njit(**_JIT)
def _slab(o, d, half):
    """Entry and exit of |x| <= half along one axis, for origin o and direction d on it;
    (-inf, inf) when parallel inside, empty when parallel outside."""
    inverse = 1.0 / d
    t1 = (-half - o) * inverse
    t2 = (half - o) * inverse
    return _fmin(t1, t2), _fmax(t1, t2)


@njit(**_JIT)
def _quadratic(a, half_b, c):
    """Roots of a t^2 + 2 half_b t + c = 0 as (near, far); (inf, -inf) when none. The
    stable form: no cancellation when one root is much smaller than the other."""
    disc = half_b * half_b - a * c
    if disc < 0.0:
        return math.inf, -math.inf
    q = -(half_b + math.copysign(math.sqrt(disc), half_b))
    t1 = q / a
    t2 = c / q
    return _fmin(t1, t2), _fmax(t1, t2)


@njit(**_JIT)
def _support(kind, r, size, nx, ny, nz):
    """Half-width [m] of a shape (rotation r, size) along the unit vector (nx, ny, nz)."""
    c0 = abs(nx * r[0, 0] + ny * r[1, 0] + nz * r[2, 0])
    c1 = abs(nx * r[0, 1] + ny * r[1, 1] + nz * r[2, 1])
    c2 = abs(nx * r[0, 2] + ny * r[1, 2] + nz * r[2, 2])
    if kind == BOX:
        return c0 * size[0] + c1 * size[1] + c2 * size[2]
    if kind == SPHERE:
        return size[0]
    if kind == CYLINDER:
        return size[0] * math.sqrt(max(0.0, 1.0 - c2 * c2)) + size[1] * c2
    return size[0] + size[1] * c2                                          # capsule


@njit(**_JIT)
def _interval(kind, size, ox, oy, oz, dx, dy, dz):
    """(near, far) along a ray with origin o and unit direction d, both in the shape's
    frame; empty (near > far) when it misses."""
    if kind == BOX:
        nx, fx = _slab(ox, dx, size[0])
        ny, fy = _slab(oy, dy, size[1])
        nz, fz = _slab(oz, dz, size[2])
        return max(nx, max(ny, nz)), min(fx, min(fy, fz))
    if kind == SPHERE:
        return _quadratic(1.0, ox * dx + oy * dy + oz * dz,
                          ox * ox + oy * oy + oz * oz - size[0] * size[0])
    # cylinder about local z: radius size[0], half length size[1]; a capsule adds end spheres
    a = dx * dx + dy * dy
    c = ox * ox + oy * oy - size[0] * size[0]
    if a < _PARALLEL:
        near, far = (-math.inf, math.inf) if c <= 0.0 else (math.inf, -math.inf)
    else:
        near, far = _quadratic(a, ox * dx + oy * dy, c)
    z_near, z_far = _slab(oz, dz, size[1])
    near, far = max(near, z_near), min(far, z_far)
    if kind == CAPSULE:                  # convex: the union of the overlapping parts
        for sign in (1.0, -1.0):
            ez = oz - sign * size[1]
            s_near, s_far = _quadratic(1.0, ox * dx + oy * dy + ez * dz,
                                       ox * ox + oy * oy + ez * ez - size[0] * size[0])
            if near > far:
                near, far = s_near, s_far
            elif s_near <= s_far:
                near, far = min(near, s_near), max(far, s_far)
    return near, far


@njit(**_JIT)
def _fan_windows(fan, kind, r, size, rx, ry, rz, distance2, reach, n, windows):
    """The rays of a fan that can meet a shape, as up to three index ranges windows[w] =
    (first, last); returns how many. fan = (x axis (3), y axis (3), angle_min, increment):
    ray i points along cos(a) x + sin(a) y, a = angle_min + i increment, in the plane the
    kernels' plane_normal gives; zeros: not a fan, every ray. The shape: kind, rotation r,
    size as for nearest_hits, its centre at (rx, ry, rz) from the origin (squared distance
    distance2), bounding radius reach. The rays that can meet it lie between the angles
    of its box's corners seen in the plane (a box ahead of the origin), or within
    acos(sqrt(distance2 - reach^2) / rho) of its centre's direction (its bounding sphere,
    farther than reach * sqrt 2; rho: the centre's distance in the plane); FAN_MARGIN more
    beams on each side keep rounding out of it. Every ray when the origin is nearer."""
    increment = fan[7]
    x = rx * fan[0] + ry * fan[1] + rz * fan[2]
    y = rx * fan[3] + ry * fan[4] + rz * fan[5]
    rho2 = x * x + y * y
    if not (increment > 0.0 and rho2 > 0.0):
        return _all_rays(n, windows)
    centre = math.atan2(y, x)
    if kind == BOX:
        found, low, high = _box_span(fan, r, size, x, y, rho2)
        if found:
            return _index_windows(fan, n, centre + low, centre + high, windows)
    reach2 = reach * reach
    if distance2 <= 2.0 * reach2:
        return _all_rays(n, windows)
    cosine = math.sqrt(distance2 - reach2) / math.sqrt(rho2)
    half = 0.0 if cosine >= 1.0 else math.acos(cosine)
    return _index_windows(fan, n, centre - half, centre + half, windows)


@njit(**_JIT)
def _box_span(fan, r, size, x, y, rho2):
    """(True, low, high): the angles [rad] of a box's corners seen in the fan's plane,
    relative to its centre's direction (x, y in the plane), when all of them are ahead of
    the origin along that direction; (False, 0, 0) otherwise."""
    length = math.sqrt(rho2)
    ux, uy = x / length, y / length                  # towards the centre, and across
    low, high = math.inf, -math.inf
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            for sz in (-1.0, 1.0):
                cx, cy, cz = sx * size[0], sy * size[1], sz * size[2]
                wx = r[0, 0] * cx + r[0, 1] * cy + r[0, 2] * cz      # corner - centre, world
                wy = r[1, 0] * cx + r[1, 1] * cy + r[1, 2] * cz
                wz = r[2, 0] * cx + r[2, 1] * cy + r[2, 2] * cz
                px = x + wx * fan[0] + wy * fan[1] + wz * fan[2]     # corner in the plane
                py = y + wx * fan[3] + wy * fan[4] + wz * fan[5]
                ahead = px * ux + py * uy
                if not ahead > 0.0:
                    return False, 0.0, 0.0
                slope = (py * ux - px * uy) / ahead
                low = min(low, slope)
                high = max(high, slope)
    return True, math.atan(low), math.atan(high)


@njit(**_JIT)
def _index_windows(fan, n, low, high, windows):
    """The beams between the angles low and high [rad] (and FAN_MARGIN more each side), the
    angles taken modulo a turn, as index ranges in windows; returns how many."""
    angle_min, increment = fan[6], fan[7]
    count = 0
    after = 0                      # windows never overlap: each starts after the last
    for turn in (-2.0 * math.pi, 0.0, 2.0 * math.pi):
        first = int(math.ceil((low + turn - angle_min) / increment)) - FAN_MARGIN
        last = int(math.floor((high + turn - angle_min) / increment)) + FAN_MARGIN
        first = max(first, after)
        last = min(last, n - 1)
        if first <= last:
            windows[count, 0] = first
            windows[count, 1] = last
            count += 1
            after = last + 1
    return count


@njit(**_JIT)
def _nearest_first(origin, kind, position, rotation, size, bound):
    """(order, start): shape indices by how near the origin any of their points can be,
    nearest first, and that distance [m] for each shape (a box's own distance from the
    origin, 0 inside; else where its bounding sphere starts)."""
    start = np.empty(position.shape[0])
    for j in range(position.shape[0]):
        rx = position[j, 0] - origin[0]
        ry = position[j, 1] - origin[1]
        rz = position[j, 2] - origin[2]
        if kind is not None and kind[j] == BOX:
            r = rotation[j]
            gap = 0.0
            for axis in range(3):
                local = abs(r[0, axis] * rx + r[1, axis] * ry + r[2, axis] * rz) \
                    - size[j, axis]
                if local > 0.0:
                    gap += local * local
            start[j] = math.sqrt(gap)
        else:
            start[j] = math.sqrt(rx * rx + ry * ry + rz * rz) - bound[j]
    return np.argsort(start), start


@njit(**_JIT)
def _origin_in_shape_frame(r, rx, ry, rz):
    """The rays' origin in a shape's frame, r^T (origin - position), given (rx, ry, rz) =
    position - origin and the shape's rotation r."""
    return (-(r[0, 0] * rx + r[1, 0] * ry + r[2, 0] * rz),
            -(r[0, 1] * rx + r[1, 1] * ry + r[2, 1] * rz),
            -(r[0, 2] * rx + r[1, 2] * ry + r[2, 2] * rz))


@njit(**_JIT)
def _misses_bound(along, distance2, reach, reach2, range_min, range_max):
    """True when a ray misses a shape's bounding sphere (radius reach, centre at squared
    distance distance2 and at `along` down the ray; reach2 the padded radius squared) or
    meets it out of [range_min, range_max]."""
    return along < range_min - reach or along > range_max + reach \
        or distance2 - along * along > reach2


@njit(**_JIT)
def _all_rays(n, windows):
    windows[0, 0] = 0
    windows[0, 1] = n - 1
    return 1


@njit(**_JIT)
def nearest_hits(origin, directions, plane_normal, kind, position, rotation, size, bound,
                 body, exclude_body, range_min, range_max, out, fan):
    """Lowers out[i] to the nearest entry in [range_min, range_max] of ray i (origin (3,),
    unit directions (n, 3)) into any shape (kind (k,), position (k, 3), rotation (k, 3, 3),
    size (k, 3), bounding radius (k,), body (k,)) whose body is not exclude_body.
    plane_normal (3,): the unit normal of a plane through the origin holding every ray, or
    zeros; shapes that do not cross that plane are skipped whole. fan (8,): when the rays
    are a fan in that plane (see _fan_windows), each shape is tried only on the rays that
    can reach it: the same answer, as every other ray misses it; zeros: every ray."""
    in_plane = plane_normal[0] != 0.0 or plane_normal[1] != 0.0 or plane_normal[2] != 0.0
    windows = np.empty((3, 2), dtype=np.int64)
    culled = in_plane and fan[7] > 0.0
    if culled:
        # (all shapes sorted: which of two hits at 0 m, +0.0 or -0.0, is kept depends on
        # the order of the shapes that tie there)
        order, nearest = _nearest_first(origin, kind, position, rotation, size, bound)
    else:
        order, nearest = np.arange(kind.shape[0]), np.zeros(0)
    for j in order:
        if body[j] == exclude_body:
            continue
        rx = position[j, 0] - origin[0]
        ry = position[j, 1] - origin[1]
        rz = position[j, 2] - origin[2]
        distance2 = rx * rx + ry * ry + rz * rz
        distance = math.sqrt(distance2)
        reach = bound[j]
        if distance - reach > range_max or distance + reach < range_min:
            continue
        r = rotation[j]
        if in_plane and abs(rx * plane_normal[0] + ry * plane_normal[1] + rz * plane_normal[2]) \
                > _support(kind[j], r, size[j], plane_normal[0], plane_normal[1], plane_normal[2]):
            continue
        ox, oy, oz = _origin_in_shape_frame(r, rx, ry, rz)
        reach2 = (reach + 1e-9) * (reach + 1e-9)
        count = _fan_windows(fan, kind[j], r, size[j], rx, ry, rz, distance2, reach + 1e-9,
                             directions.shape[0], windows) \
            if culled else _all_rays(directions.shape[0], windows)
        # a fan's shapes come nearest first: a ray that already hit nearer than any point of
        # this shape cannot hit it nearer (1e-9 m for the rounding of that distance)
        beyond = nearest[j] - 1e-9 if culled else -math.inf
        for w in range(count):
            for i in range(windows[w, 0], windows[w, 1] + 1):
                if out[i] < beyond:
                    continue
                dx, dy, dz = directions[i, 0], directions[i, 1], directions[i, 2]
                along = rx * dx + ry * dy + rz * dz
                if _misses_bound(along, distance2, reach, reach2, range_min, range_max):
                    continue
                lx = r[0, 0] * dx + r[1, 0] * dy + r[2, 0] * dz     # the ray in the shape's
                ly = r[0, 1] * dx + r[1, 1] * dy + r[2, 1] * dz     # frame
                lz = r[0, 2] * dx + r[1, 2] * dy + r[2, 2] * dz
                if kind[j] == BOX:
                    # _interval's slabs one by one: entering a slab beyond the nearest hit so
                    # far, the ray cannot enter the box nearer (max() keeps an entry that
                    # large, or gives NaN, which hits nothing); the rest as _interval does
                    half = size[j]
                    near_x, far_x = _slab(ox, lx, half[0])
                    if near_x > out[i]:
                        continue
                    near_y, far_y = _slab(oy, ly, half[1])
                    if near_y > out[i]:
                        continue
                    near_z, far_z = _slab(oz, lz, half[2])
                    near, far = max(near_x, max(near_y, near_z)), min(far_x, min(far_y, far_z))
                else:
                    near, far = _interval(kind[j], size[j], ox, oy, oz, lx, ly, lz)
                if near <= far and range_min <= near <= range_max and near < out[i]:
                    out[i] = near


@njit(**_JIT)
def _triangle_hit(ox, oy, oz, dx, dy, dz, t):
    """Distance along the ray (origin o, unit direction d) to triangle t ((3, 3) corners),
    either side; inf when it misses (Moller-Trumbore)."""
    e1x, e1y, e1z = t[1, 0] - t[0, 0], t[1, 1] - t[0, 1], t[1, 2] - t[0, 2]
    e2x, e2y, e2z = t[2, 0] - t[0, 0], t[2, 1] - t[0, 1], t[2, 2] - t[0, 2]
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if abs(det) < 1e-15:                     # the ray runs in the triangle's plane
        return math.inf
    inverse = 1.0 / det
    sx, sy, sz = ox - t[0, 0], oy - t[0, 1], oz - t[0, 2]
    u = (sx * px + sy * py + sz * pz) * inverse
    if u < 0.0 or u > 1.0:
        return math.inf
    qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    v = (dx * qx + dy * qy + dz * qz) * inverse
    if v < 0.0 or u + v > 1.0:
        return math.inf
    return (e2x * qx + e2y * qy + e2z * qz) * inverse


@njit(**_JIT)
def nearest_mesh_hits(origin, directions, plane_normal, position, rotation, bound, start,
                      count, triangles, body, exclude_body, range_min, range_max, out,
                      fan):
    """Lowers out[i] to the nearest crossing in [range_min, range_max] of ray i (origin (3,),
    unit directions (n, 3)) with a triangle of any mesh (position (k, 3), rotation (k, 3, 3),
    bounding radius about its origin (k,), triangles[start[j]:start[j] + count[j]] in its own
    frame, body (k,)) whose body is not exclude_body. A mesh is a surface: a triangle is hit
    from either side. plane_normal and fan as for nearest_hits."""
    in_plane = plane_normal[0] != 0.0 or plane_normal[1] != 0.0 or plane_normal[2] != 0.0
    windows = np.empty((3, 2), dtype=np.int64)
    culled = in_plane and fan[7] > 0.0
    if culled:
        order, nearest = _nearest_first(origin, None, position, rotation, bound, bound)
    else:
        order, nearest = np.arange(position.shape[0]), np.zeros(0)
    for j in order:
        if body[j] == exclude_body:
            continue
        rx = position[j, 0] - origin[0]
        ry = position[j, 1] - origin[1]
        rz = position[j, 2] - origin[2]
        distance2 = rx * rx + ry * ry + rz * rz
        distance = math.sqrt(distance2)
        reach = bound[j]
        if distance - reach > range_max or distance + reach < range_min:
            continue
        if in_plane and abs(rx * plane_normal[0] + ry * plane_normal[1]
                            + rz * plane_normal[2]) > reach:
            continue
        r = rotation[j]
        ox, oy, oz = _origin_in_shape_frame(r, rx, ry, rz)
        reach2 = (reach + 1e-9) * (reach + 1e-9)
        windows_count = _fan_windows(fan, SPHERE, r, bound[j:j + 1], rx, ry, rz, distance2,
                                     reach + 1e-9, directions.shape[0], windows) \
            if culled else _all_rays(directions.shape[0], windows)
        beyond = nearest[j] - 1e-9 if culled else -math.inf     # as in nearest_hits
        for w in range(windows_count):
            for i in range(windows[w, 0], windows[w, 1] + 1):
                if out[i] < beyond:
                    continue
                dx, dy, dz = directions[i, 0], directions[i, 1], directions[i, 2]
                along = rx * dx + ry * dy + rz * dz
                if _misses_bound(along, distance2, reach, reach2, range_min, range_max):
                    continue
                lx = r[0, 0] * dx + r[1, 0] * dy + r[2, 0] * dz
                ly = r[0, 1] * dx + r[1, 1] * dy + r[2, 1] * dz
                lz = r[0, 2] * dx + r[1, 2] * dy + r[2, 2] * dz
                for t in range(start[j], start[j] + count[j]):
                    hit = _triangle_hit(ox, oy, oz, lx, ly, lz, triangles[t])
                    if range_min <= hit <= range_max and hit < out[i]:
                        out[i] = hit


@njit(**_JIT)
def rotation_matrices(quaternions, out):
    """out (n, 3, 3) = the rotation matrices of quaternions (n, 4), unit, (x, y, z, w)."""
    for k in range(quaternions.shape[0]):
        x, y, z, w = quaternions[k, 0], quaternions[k, 1], quaternions[k, 2], quaternions[k, 3]
        out[k, 0, 0] = 1.0 - 2.0 * (y * y + z * z)
        out[k, 0, 1] = 2.0 * (x * y - z * w)
        out[k, 0, 2] = 2.0 * (x * z + y * w)
        out[k, 1, 0] = 2.0 * (x * y + z * w)
        out[k, 1, 1] = 1.0 - 2.0 * (x * x + z * z)
        out[k, 1, 2] = 2.0 * (y * z - x * w)
        out[k, 2, 0] = 2.0 * (x * z - y * w)
        out[k, 2, 1] = 2.0 * (y * z + x * w)
        out[k, 2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(**_JIT)
def _rotated(q, vx, vy, vz):
    """(vx, vy, vz) rotated by the unit quaternion q (x, y, z, w): v + 2 w (u x v) +
    2 u x (u x v), u the vector part (transforms.rotate's arithmetic)."""
    ux, uy, uz, w = q[0], q[1], q[2], q[3]
    tx = 2.0 * (uy * vz - uz * vy)
    ty = 2.0 * (uz * vx - ux * vz)
    tz = 2.0 * (ux * vy - uy * vx)
    return (vx + w * tx + (uy * tz - uz * ty), vy + w * ty + (uz * tx - ux * tz),
            vz + w * tz + (ux * ty - uy * tx))


@njit(**_JIT)
def fan_rays(link_position, link_orientation, offset_position, offset_orientation, cos_sin,
             angle_min, increment, frame, fan, directions):
    """A laser's rays in the world: the sensor frame is the link's pose (position (3,),
    quaternion (4,) x, y, z, w) composed with the sensor's offset in the link (the same);
    frame (4, 3) receives its origin and its x, y, z axes (unit columns of its rotation),
    fan (8,) the kernels' fan (x axis, y axis, angle_min, increment), directions (n, 3)
    the unit vectors cos(a_i) x + sin(a_i) y for cos_sin (n, 2) = (cos a_i, sin a_i).
    Returns False (outputs unfinished) when a direction is not a finite non-zero vector."""
    lq = link_orientation
    ox, oy, oz = _rotated(lq, offset_position[0], offset_position[1], offset_position[2])
    frame[0, 0] = link_position[0] + ox
    frame[0, 1] = link_position[1] + oy
    frame[0, 2] = link_position[2] + oz
    ax, ay, az, aw = lq[0], lq[1], lq[2], lq[3]
    bx, by, bz, bw = (offset_orientation[0], offset_orientation[1], offset_orientation[2],
                      offset_orientation[3])
    x = aw * bx + ax * bw + ay * bz - az * by             # the Hamilton product lq * offset
    y = aw * by - ax * bz + ay * bw + az * bx
    z = aw * bz + ax * by - ay * bx + az * bw
    w = aw * bw - ax * bx - ay * by - az * bz
    frame[1, 0] = 1.0 - 2.0 * (y * y + z * z)             # x axis: the matrix's columns
    frame[1, 1] = 2.0 * (x * y + z * w)
    frame[1, 2] = 2.0 * (x * z - y * w)
    frame[2, 0] = 2.0 * (x * y - z * w)
    frame[2, 1] = 1.0 - 2.0 * (x * x + z * z)
    frame[2, 2] = 2.0 * (y * z + x * w)
    frame[3, 0] = 2.0 * (x * z + y * w)
    frame[3, 1] = 2.0 * (y * z - x * w)
    frame[3, 2] = 1.0 - 2.0 * (x * x + y * y)
    for axis in range(3):
        fan[axis] = frame[1, axis]
        fan[3 + axis] = frame[2, axis]
    fan[6] = angle_min
    fan[7] = increment
    for i in range(cos_sin.shape[0]):
        c, s = cos_sin[i, 0], cos_sin[i, 1]
        dx = c * frame[1, 0] + s * frame[2, 0]
        dy = c * frame[1, 1] + s * frame[2, 1]
        dz = c * frame[1, 2] + s * frame[2, 2]
        norm = math.sqrt(dx * dx + dy * dy + dz * dz)
        if not (norm > 0.0 and norm < math.inf):
            return False
        directions[i, 0] = dx / norm
        directions[i, 1] = dy / norm
        directions[i, 2] = dz / norm
    return True


@njit(**_JIT)
def noisy_ranges(ranges, normals, mean, stddev, range_min, range_max, out):
    """out (float32) = ranges with mean + stddev * normals[i] added to every finite one and
    kept inside [range_min, range_max]; normals empty: no noise. (numpy's
    Generator.normal(mean, stddev) is mean + stddev * standard_normal(), draw for draw.)"""
    noisy = normals.shape[0] > 0
    for i in range(ranges.shape[0]):
        r = ranges[i]
        if noisy and r < math.inf:
            r = r + (mean + stddev * normals[i])
            r = _fmin(_fmax(r, range_min), range_max)
        out[i] = r


def warm_up():
    """Compiles (or loads from numba's cache) the kernels with the argument types the
    caster passes; returns the seconds it took."""
    import time
    start = time.perf_counter()
    assert unit_rows(np.array([[3.0, 0.0, 4.0]]), np.array([5.0]))[0, 2] == 0.8
    assert fan_matches(np.array([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, math.pi / 2]),
                       np.eye(3)[:2].copy(), 1e-6)
    fan = np.array([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, math.pi / 2])   # rays at 0 and 90 deg
    for hint in (NO_FAN, fan):
        out = np.full(2, np.inf)
        nearest_hits(np.zeros(3), np.eye(3)[:2].copy(), np.array([0.0, 0.0, 1.0]),
                     np.array([BOX], dtype=np.int64), np.array([[2.0, 0.0, 0.0]]),
                     np.eye(3).reshape(1, 3, 3).copy(), np.full((1, 3), 0.5), np.array([0.9]),
                     np.array([7], dtype=np.int64), -1, 0.0, 10.0, out, hint)
        assert out[0] == 1.5 and out[1] == np.inf, out
        out = np.full(2, np.inf)
        triangle = np.array([[[0.0, -1.0, -1.0], [0.0, 1.0, -1.0], [0.0, 0.0, 1.0]]])
        nearest_mesh_hits(np.zeros(3), np.eye(3)[:2].copy(), np.array([0.0, 0.0, 1.0]),
                          np.array([[2.0, 0.0, 0.0]]), np.eye(3).reshape(1, 3, 3).copy(),
                          np.array([1.5]), np.array([0], dtype=np.int64),
                          np.array([1], dtype=np.int64), triangle, np.array([7], dtype=np.int64),
                          -1, 0.0, 10.0, out, hint)
        assert out[0] == 2.0 and out[1] == np.inf, out
    frame, fan, directions = np.empty((4, 3)), np.empty(8), np.empty((2, 3))
    assert fan_rays(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), np.zeros(3),
                    np.array([0.0, 0.0, 0.0, 1.0]), np.array([[1.0, 0.0], [0.0, 1.0]]), 0.0,
                    math.pi / 2, frame, fan, directions)
    assert directions[1, 1] == 1.0 and frame[3, 2] == 1.0, (directions, frame)
    matrix = np.empty((1, 3, 3))
    rotation_matrices(np.array([[0.0, 0.0, 1.0, 0.0]]), matrix)      # half a turn about z
    assert matrix[0, 0, 0] == -1.0 and matrix[0, 2, 2] == 1.0, matrix
    out = np.empty(2, dtype=np.float32)
    noisy_ranges(np.array([1.0, np.inf]), np.array([0.5, 0.5]), 0.0, 0.1, 0.1, 10.0, out)
    assert out[0] == np.float32(1.05) and out[1] == np.inf, out
    noisy_ranges(np.array([1.0, np.inf]), np.zeros(0), 0.0, 0.1, 0.1, 10.0, out)
    return time.perf_counter() - start
