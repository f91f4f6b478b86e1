"""Exact ray casting against Bullet's primitive collision shapes, in numpy.

Bullet's own `rayTestBatch` costs 3-4 ms for a 720-beam scan; this caster reads the bodies'
collision shapes once, keeps static ones in world coordinates, and intersects all rays with
all shapes at once (a bounding-sphere cull, then exact slab / quadric tests on the
remaining ray-shape pairs).

Shapes read from `client.getCollisionShapeData(body, link)` (pybullet's conventions, checked
against `client.rayTest`):
- the local frame of a shape is relative to the link's *inertial* (centre of mass) frame,
  which is what getBasePositionAndOrientation and getLinkState()[0:2] report;
- dimensions: box = full extents (x, y, z) [m]; sphere = (r, r, r); cylinder =
  (length, radius, 0) along local z; capsule = (length of the straight part, radius, 0)
  along local z; plane = its normal (x, y, z) through the local origin.
- Bullet's plane is two-sided: a ray crossing it from either side hits it.
- Meshes (including URDF cylinders loaded *without* URDF_USE_IMPLICIT_CYLINDER, which Bullet
  turns into convex hulls) and height fields are not cast against; their (body, link) pairs
  are listed in `RayCaster.skipped`.

Ray semantics (those of Gazebo's ray sensor, whose rays start at the minimum range): a ray
tests the segment [range_min, range_max] along its direction; hits nearer than range_min are
ignored as if the ray started there, and a ray starting inside a shape does not hit that
shape. Distances are measured from the origin [m]; no hit is `inf`.
"""
import numpy as np
import pybullet

_SPHERE, _BOX, _CYLINDER, _CAPSULE = 0, 1, 2, 3      # internal shape kinds, sorted order
_KINDS = {pybullet.GEOM_SPHERE: _SPHERE, pybullet.GEOM_BOX: _BOX,
          pybullet.GEOM_CYLINDER: _CYLINDER, pybullet.GEOM_CAPSULE: _CAPSULE}
_PLANE = pybullet.GEOM_PLANE
_PARALLEL = 1e-12          # squared sine below which a ray counts as parallel to an axis


def rotation_matrices(quaternions):
    """(n, 3, 3) rotation matrices of (n, 4) unit quaternions (x, y, z, w)."""
    q = np.asarray(quaternions, dtype=float).reshape(-1, 4)
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    out = np.empty((len(q), 3, 3))
    out[:, 0, 0] = 1 - 2 * (y * y + z * z)
    out[:, 0, 1] = 2 * (x * y - z * w)
    out[:, 0, 2] = 2 * (x * z + y * w)
    out[:, 1, 0] = 2 * (x * y + z * w)
    out[:, 1, 1] = 1 - 2 * (x * x + z * z)
    out[:, 1, 2] = 2 * (y * z - x * w)
    out[:, 2, 0] = 2 * (x * z - y * w)
    out[:, 2, 1] = 2 * (y * z + x * w)
    out[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return out


class _Shapes:
    """Primitive shapes of one body in their link's inertial frame (or, once placed, in the
    world): kind, link row, position (n, 3), rotation (n, 3, 3), size (n, 3) and bounding
    radius (n,). size is (hx, hy, hz) half extents for a box, (r, h, 0) for a cylinder or
    capsule (h = half length of the straight part), (r, 0, 0) for a sphere."""

    def __init__(self, body, kind, link_row, position, rotation, size):
        n = len(kind)
        self.body = np.full(n, body, dtype=int)
        self.kind = np.asarray(kind, dtype=int).reshape(n)
        self.link_row = np.asarray(link_row, dtype=int).reshape(n)
        self.position = np.asarray(position, dtype=float).reshape(n, 3)
        self.rotation = np.asarray(rotation, dtype=float).reshape(n, 3, 3)
        self.size = np.asarray(size, dtype=float).reshape(n, 3)
        r, h = self.size[:, 0], self.size[:, 1]
        self.bound = np.select(
            [self.kind == _BOX, self.kind == _CYLINDER, self.kind == _CAPSULE],
            [np.linalg.norm(self.size, axis=1), np.hypot(r, h), r + h], r)

    def placed(self, link_position, link_rotation):
        """These shapes moved to the world by their links' inertial poses (rows of
        link_position (m, 3) / link_rotation (m, 3, 3) picked by link_row)."""
        rot = link_rotation[self.link_row]
        placed = object.__new__(_Shapes)
        placed.body, placed.kind, placed.link_row = self.body, self.kind, self.link_row
        placed.size, placed.bound = self.size, self.bound
        placed.position = link_position[self.link_row] + np.einsum(
            "nij,nj->ni", rot, self.position)
        placed.rotation = rot @ self.rotation
        return placed

    @staticmethod
    def concatenate(parts):
        out = object.__new__(_Shapes)
        for name in ("body", "kind", "link_row", "position", "rotation", "size", "bound"):
            setattr(out, name, np.concatenate([getattr(p, name) for p in parts]))
        return out


class _Body:
    """What the caster knows of one body: its links with shapes, shapes, planes."""

    def __init__(self, body_id, static, links, shapes, planes):
        self.body_id = body_id
        self.static = static
        self.links = links                    # link indices, -1 = base; rows of link poses
        self.shapes = shapes                  # _Shapes in the links' inertial frames
        self.planes = planes                  # list of (link row, point (3,), normal (3,))


class _Group:
    """Bodies whose poses are read together: their shapes with link rows numbered across the
    group, so that one pass of numpy places them all."""

    def __init__(self, bodies):
        self.bodies = [b for b in bodies if b.links]
        self.shapes, self.planes, offset = [], [], 0
        for body in self.bodies:
            shapes = object.__new__(_Shapes)
            shapes.__dict__.update(body.shapes.__dict__)
            shapes.link_row = body.shapes.link_row + offset
            self.shapes.append(shapes)
            self.planes += [(body.body_id, row + offset, p, n) for row, p, n in body.planes]
            offset += len(body.links)
        self.shapes = _Shapes.concatenate(self.shapes) if self.shapes else None

    def place(self, client):
        """(_Shapes or None, [(body, point, normal)]) at the bodies' present poses."""
        if not self.bodies:
            return None, []
        positions, orientations = [], []
        for body in self.bodies:
            if body.links[0] == -1:
                pos, orn = client.getBasePositionAndOrientation(body.body_id)
                positions.append(pos)
                orientations.append(orn)
            if body.links[-1] >= 0:
                for state in client.getLinkStates(body.body_id, [i for i in body.links if i >= 0],
                                                  computeForwardKinematics=1):
                    positions.append(state[0])
                    orientations.append(state[1])
        position = np.asarray(positions, dtype=float)
        rotation = rotation_matrices(orientations)
        planes = [(body_id, position[row] + rotation[row] @ p, rotation[row] @ n)
                  for body_id, row, p, n in self.planes]
        shapes = self.shapes.placed(position, rotation) if self.shapes is not None else None
        return shapes, planes


class RayCaster:
    """Casts rays against the primitive collision shapes of the bodies added to it."""

    def __init__(self, client):
        self._client = client
        self._bodies = {}                     # body id -> _Body
        self.skipped = []                     # (body id, link index) of shapes not cast against
        self._static_placed = {}              # body id -> its shapes and planes in the world
        self._static_cache = None             # all static shapes and planes in the world
        self._dynamic_groups = {}             # exclude_body -> _Group of the other dynamics

    # --- the set of bodies --------------------------------------------------------------
    def add_body(self, body_id, static):
        """Read every collision shape of every link of `body_id`. A static body's shapes are
        placed in the world now and cached: add it again (or call reset) after moving it."""
        self.remove_body(body_id)
        client = self._client
        kinds, rows, positions, rotations, sizes, planes, links = [], [], [], [], [], [], []
        for link in range(-1, client.getNumJoints(body_id)):
            row = len(links)
            used = False
            for entry in client.getCollisionShapeData(body_id, link):
                # entry: (body, link, geometry type, dimensions, file, local pos, local orn);
                # body/link of the 2nd+ entries of a link are unreliable in pybullet 3.2.
                geometry, dims, pos, orn = entry[2], entry[3], entry[5], entry[6]
                rot = rotation_matrices(orn)[0]
                if geometry == _PLANE:
                    normal = np.asarray(dims, dtype=float)
                    normal = rot @ (normal / np.linalg.norm(normal))
                    planes.append((row, np.asarray(pos, dtype=float), normal))
                    used = True
                    continue
                kind = _KINDS.get(geometry)
                if kind is None:
                    if (body_id, link) not in self.skipped:
                        self.skipped.append((body_id, link))
                    continue
                if kind == _BOX:
                    size = (dims[0] / 2.0, dims[1] / 2.0, dims[2] / 2.0)
                elif kind == _SPHERE:
                    size = (dims[0], 0.0, 0.0)
                else:                                           # cylinder, capsule
                    size = (dims[1], dims[0] / 2.0, 0.0)
                kinds.append(kind)
                rows.append(row)
                positions.append(pos)
                rotations.append(rot)
                sizes.append(size)
                used = True
            if used:
                links.append(link)
        body = _Body(body_id, bool(static), links,
                     _Shapes(body_id, kinds, rows, positions, rotations, sizes), planes)
        self._bodies[body_id] = body
        if body.static:
            self._static_placed[body_id] = _Group([body]).place(client)
        self._static_cache = None
        self._dynamic_groups = {}

    def remove_body(self, body_id):
        """Forget `body_id` (no error when it was not added)."""
        if self._bodies.pop(body_id, None) is not None:
            self._static_placed.pop(body_id, None)
            self._static_cache = None
            self._dynamic_groups = {}
        self.skipped = [s for s in self.skipped if s[0] != body_id]

    def reset(self):
        """Re-read the poses of the static bodies (after some of them were moved)."""
        for body_id, body in self._bodies.items():
            if body.static:
                self._static_placed[body_id] = _Group([body]).place(self._client)
        self._static_cache = None

    def _static(self):
        """All static shapes in one _Shapes (or None) and all static planes."""
        if self._static_cache is None:
            shapes = [s for s, _ in self._static_placed.values() if s is not None]
            planes = [p for _, group_planes in self._static_placed.values() for p in group_planes]
            self._static_cache = (_Shapes.concatenate(shapes) if shapes else None, planes)
        return self._static_cache

    def _dynamic(self, exclude_body):
        """The dynamic bodies other than exclude_body, placed at their present poses."""
        group = self._dynamic_groups.get(exclude_body)
        if group is None:
            group = _Group(b for b in self._bodies.values()
                           if not b.static and b.body_id != exclude_body)
            self._dynamic_groups[exclude_body] = group
        return group.place(self._client)

    # --- casting -------------------------------------------------------------------------
    def cast(self, origin, directions, range_min, range_max, exclude_body=None):
        """Distances [m] from `origin` (3,) along each of `directions` (n, 3) (need not be
        unit) to the nearest hit in [range_min, range_max]; inf where nothing is hit there.
        Shapes of `exclude_body` are ignored."""
        origin = np.asarray(origin, dtype=float).reshape(3)
        directions = np.asarray(directions, dtype=float).reshape(-1, 3)
        norms = np.linalg.norm(directions, axis=1)
        if not np.all(norms > 0.0) or not np.all(np.isfinite(directions)):
            raise ValueError("RayCaster.cast: every direction must be a finite non-zero vector")
        directions = directions / norms[:, None]
        range_min = max(0.0, float(range_min))
        range_max = float(range_max)
        result = np.full(len(directions), np.inf)
        if not range_min < range_max or len(directions) == 0:
            return result

        static_shapes, static_planes = self._static()
        dynamic_shapes, dynamic_planes = self._dynamic(exclude_body)
        for body_id, point, normal in static_planes + dynamic_planes:
            if body_id != exclude_body:
                np.minimum(result, self._plane_hits(origin, directions, point, normal,
                                                    range_min, range_max), out=result)
        shapes = [s for s in (static_shapes, dynamic_shapes) if s is not None]
        if shapes:
            shapes = _Shapes.concatenate(shapes) if len(shapes) > 1 else shapes[0]
            np.minimum(result, self._shape_hits(origin, directions, shapes, range_min,
                                                range_max, exclude_body), out=result)
        return result

    @staticmethod
    def _plane_hits(origin, directions, point, normal, range_min, range_max):
        denominator = directions @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            t = float((point - origin) @ normal) / denominator
        return np.where((t >= range_min) & (t <= range_max), t, np.inf)

    @staticmethod
    def _coplanar_normal(directions):
        """Unit normal of the plane holding every direction, or None."""
        if len(directions) < 2:
            return None
        _, vectors = np.linalg.eigh(directions.T @ directions)
        normal = vectors[:, 0]
        if np.max(np.abs(directions @ normal)) > 1e-9:
            return None
        return normal

    def _shape_hits(self, origin, directions, shapes, range_min, range_max, exclude_body):
        # cull whole shapes: too far, inside the dead zone, off the rays' common plane
        relative = shapes.position - origin                      # (k, 3)
        distance = np.linalg.norm(relative, axis=1)
        bound = shapes.bound
        keep = (distance - bound <= range_max) & (distance + bound >= range_min)
        if exclude_body is not None:
            keep &= shapes.body != exclude_body
        normal = self._coplanar_normal(directions)
        if normal is not None:
            keep &= np.abs(relative @ normal) <= _support(shapes, normal)
        index = np.flatnonzero(keep)
        if len(index) == 0:
            return np.full(len(directions), np.inf)
        index = index[np.argsort(shapes.kind[index], kind="stable")]
        kind = shapes.kind[index]
        relative, distance, bound = relative[index], distance[index], bound[index]
        rotation, size = shapes.rotation[index], shapes.size[index]

        # cull ray-shape pairs by the shapes' bounding spheres
        along = relative @ directions.T                          # (k, n)
        off_axis = distance[:, None] ** 2 - along ** 2
        mask = off_axis <= (bound ** 2)[:, None]
        mask &= along >= range_min - bound[:, None]
        mask &= along <= range_max + bound[:, None]
        shape_of, ray_of = np.nonzero(mask)                      # sorted by shape, i.e. by kind
        hits = np.full(mask.shape, np.inf)
        if len(shape_of) == 0:
            return hits.min(axis=0)

        # exact intervals per kind; pairs of one kind are contiguous
        origin_local = np.einsum("kji,kj->ki", rotation, -relative)   # origin in shape frames
        first_shape = np.searchsorted(kind, np.arange(4))
        first_pair = np.searchsorted(shape_of, np.append(first_shape, len(kind)))
        for k in range(4):
            lo, hi = first_pair[k], first_pair[k + 1]
            if lo == hi:
                continue
            s, r = shape_of[lo:hi], ray_of[lo:hi]
            if k == _SPHERE:
                near, far = _sphere_interval(-relative[s], directions[r], size[s, 0])
            else:
                o = origin_local[s]
                d = np.einsum("pji,pj->pi", rotation[s], directions[r])
                if k == _BOX:
                    near, far = _box_interval(o, d, size[s])
                elif k == _CYLINDER:
                    near, far = _cylinder_interval(o, d, size[s, 0], size[s, 1])
                else:
                    near, far = _capsule_interval(o, d, size[s, 0], size[s, 1])
            hit = (near <= far) & (near >= range_min) & (near <= range_max)
            hits[s, r] = np.where(hit, near, np.inf)
        return hits.min(axis=0)


def _support(shapes, normal):
    """Half-width [m] of each shape along the unit vector `normal`."""
    local = np.einsum("kji,j->ki", shapes.rotation, normal)        # normal in shape frames
    r, h = shapes.size[:, 0], shapes.size[:, 1]
    axial = np.abs(local[:, 2])
    return np.select(
        [shapes.kind == _BOX, shapes.kind == _CYLINDER, shapes.kind == _CAPSULE],
        [np.einsum("ki,ki->k", np.abs(local), shapes.size),
         r * np.sqrt(np.maximum(0.0, 1.0 - axial * axial)) + h * axial,
         r + h * axial], r)


# --- exact entry/exit parameters of rays (origin o, unit direction d, per pair) ---------------
def _slab(o, d, half):
    """Entry and exit of the slab |x| <= half along one axis; (-inf, inf) when parallel inside,
    (inf, -inf) (empty) when parallel outside."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = 1.0 / d
        t1 = (-half - o) * inverse
        t2 = (half - o) * inverse
    return np.fmin(t1, t2), np.fmax(t1, t2)


def _box_interval(o, d, half):
    near, far = _slab(o, d, half)
    return np.max(near, axis=1), np.min(far, axis=1)


def _quadratic_interval(a, half_b, c):
    """Roots of a t^2 + 2 half_b t + c = 0 as (near, far); empty when none."""
    disc = half_b * half_b - a * c
    root = np.sqrt(np.maximum(disc, 0.0))
    q = -(half_b + np.copysign(root, half_b))
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = q / a
        t2 = c / q
    near, far = np.fmin(t1, t2), np.fmax(t1, t2)
    miss = disc < 0.0
    return np.where(miss, np.inf, near), np.where(miss, -np.inf, far)


def _sphere_interval(o, d, radius):
    half_b = np.einsum("pi,pi->p", o, d)
    c = np.einsum("pi,pi->p", o, o) - radius * radius
    return _quadratic_interval(np.ones_like(c), half_b, c)


def _cylinder_interval(o, d, radius, half_length):
    a = d[:, 0] ** 2 + d[:, 1] ** 2
    half_b = o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]
    c = o[:, 0] ** 2 + o[:, 1] ** 2 - radius * radius
    near, far = _quadratic_interval(a, half_b, c)
    parallel = a < _PARALLEL
    inside = c <= 0.0
    near = np.where(parallel, np.where(inside, -np.inf, np.inf), near)
    far = np.where(parallel, np.where(inside, np.inf, -np.inf), far)
    z_near, z_far = _slab(o[:, 2], d[:, 2], half_length)
    return np.maximum(near, z_near), np.minimum(far, z_far)


def _capsule_interval(o, d, radius, half_length):
    """A capsule is convex: its interval is the union of its cylinder's and end spheres'."""
    near, far = _cylinder_interval(o, d, radius, half_length)
    for sign in (1.0, -1.0):
        centre = np.zeros_like(o)
        centre[:, 2] = sign * half_length
        n2, f2 = _sphere_interval(o - centre, d, radius)
        near, far = _union(near, far, n2, f2)
    return near, far


def _union(n1, f1, n2, f2):
    """Union of two intervals that overlap when both are non-empty (parts of a convex shape)."""
    empty1, empty2 = n1 > f1, n2 > f2
    near = np.where(empty1, n2, np.where(empty2, n1, np.minimum(n1, n2)))
    far = np.where(empty1, f2, np.where(empty2, f1, np.maximum(f1, f2)))
    return near, far
