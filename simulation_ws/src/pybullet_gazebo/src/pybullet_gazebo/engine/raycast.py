"""Exact ray casting against Bullet's primitive collision shapes.

Bullet's own `rayTestBatch` costs about 3 ms for a 720-beam scan; this caster about 0.1 ms in
the tutorial's world02. It reads the bodies' collision shapes once, keeps static ones in world
coordinates (numpy arrays), reads dynamic ones' poses at each cast and places again only the
bodies whose pose changed (resting barrels keep their rows), and hands all shapes and rays
to the compiled kernel `ray_kernel.nearest_hits`. That one drops shapes out of range or
(when the rays share a plane, as a laser's do) not crossing that plane, skips the rays that
miss a shape's bounding sphere, and solves the exact slab (box) or quadric (sphere,
cylinder, capsule) intersection for the rest.

Shapes read from `client.getCollisionShapeData(body, link)` (pybullet's conventions, checked
against `client.rayTest`):
- the local frame of a shape is relative to the link's *inertial* (centre of mass) frame,
  which is what getBasePositionAndOrientation and getLinkState()[0:2] report;
- dimensions: box = full extents (x, y, z) [m]; sphere = (r, r, r); cylinder =
  (length, radius, 0) along local z; capsule = (length of the straight part, radius, 0)
  along local z; plane = its normal (x, y, z) through the local origin.
- Bullet's plane is two-sided: a ray crossing it from either side hits it.
- Triangle meshes are cast against exactly (ray-triangle, either side of a triangle) when
  their triangles are handed over in `base_shapes` (the World does so for world models'
  mesh collisions). Meshes Bullet reports itself (including URDF cylinders loaded *without*
  URDF_USE_IMPLICIT_CYLINDER, which Bullet turns into convex hulls) and height fields are
  not cast against; their (body, link) pairs are listed in `RayCaster.skipped`.

Ray semantics (those of Gazebo's ray sensor, whose rays start at the minimum range): a ray
tests the segment [range_min, range_max] along its direction; hits nearer than range_min are
ignored as if the ray started there, and a ray starting inside a shape does not hit that
shape. Distances are measured from the origin [m]; no hit is `inf`.
"""

import numpy as np
import pybullet

from . import ray_kernel
from .transforms import cross

_SPHERE, _BOX, _CYLINDER, _CAPSULE = (ray_kernel.SPHERE, ray_kernel.BOX, ray_kernel.CYLINDER,
                                      ray_kernel.CAPSULE)
_KINDS = {pybullet.GEOM_SPHERE: _SPHERE, pybullet.GEOM_BOX: _BOX,
          pybullet.GEOM_CYLINDER: _CYLINDER, pybullet.GEOM_CAPSULE: _CAPSULE}
_PLANE = pybullet.GEOM_PLANE
_MESH = pybullet.GEOM_MESH
_ONES = np.ones(3)         # row sums as a matrix product, much faster than .sum(axis=1)


def rotation_matrices(quaternions):
    """(n, 3, 3) rotation matrices of (n, 4) unit quaternions (x, y, z, w)."""
    q = np.ascontiguousarray(quaternions, dtype=float).reshape(-1, 4)
    out = np.empty((len(q), 3, 3))
    ray_kernel.rotation_matrices(q, out)
    return out


def _placed_frames(link_row, position, rotation, link_position, link_rotation):
    """(position (n, 3), rotation (n, 3, 3)) in the world of frames given in their links'
    inertial frames (position, rotation), the links at rows link_row of link_position
    (m, 3) / link_rotation (m, 3, 3)."""
    link_rotation = link_rotation[link_row]
    return (link_position[link_row] + np.einsum("nij,nj->ni", link_rotation, position),
            link_rotation @ rotation)


class _Shapes:
    """Primitive shapes as parallel arrays: body id, kind, link row (index into the poses of
    the links they hang on), position (n, 3), rotation (n, 3, 3), size (n, 3) and bounding
    radius (n,), either in their link's inertial frame or, once placed, in the world.
    size is (hx, hy, hz) half extents for a box, (r, h, 0) for a cylinder or capsule
    (h = half length of the straight part, along local z), (r, 0, 0) for a sphere."""

    FIELDS = ("body", "kind", "link_row", "position", "rotation", "size", "bound")

    def __init__(self, **arrays):
        for name in self.FIELDS:      # contiguous: the kernel is compiled for that layout
            setattr(self, name, np.ascontiguousarray(arrays[name]))

    @classmethod
    def of_body(cls, body, kind, link_row, position, rotation, size):
        n = len(kind)
        kind = np.asarray(kind, dtype=np.int64).reshape(n)
        size = np.asarray(size, dtype=float).reshape(n, 3)
        r, h = size[:, 0], size[:, 1]
        bound = np.select([kind == _BOX, kind == _CYLINDER, kind == _CAPSULE],
                          [np.sqrt((size * size) @ _ONES), np.hypot(r, h), r + h], r)
        return cls(body=np.full(n, body, dtype=np.int64), kind=kind,
                   link_row=np.asarray(link_row, dtype=np.int64).reshape(n),
                   position=np.asarray(position, dtype=float).reshape(n, 3),
                   rotation=np.asarray(rotation, dtype=float).reshape(n, 3, 3),
                   size=size, bound=bound)

    def replace(self, **changes):
        arrays = {name: getattr(self, name) for name in self.FIELDS}
        arrays.update(changes)
        return _Shapes(**arrays)

    def placed(self, link_position, link_rotation):
        """These shapes moved to the world by their links' inertial poses (rows of
        link_position (m, 3) / link_rotation (m, 3, 3) picked by link_row)."""
        position, rotation = _placed_frames(self.link_row, self.position, self.rotation,
                                            link_position, link_rotation)
        return self.replace(position=position, rotation=rotation)

    @staticmethod
    def concatenate(parts):
        return _Shapes(**{name: np.concatenate([getattr(p, name) for p in parts])
                          for name in _Shapes.FIELDS})


class _Meshes:
    """Triangle meshes as parallel arrays: body id, link row, position (k, 3) and rotation
    (k, 3, 3) of each mesh's frame, bounding radius (k,) about that origin, and each mesh's
    triangles as triangles[start:start + count] ((T, 3, 3) corners in the mesh's frame, never
    moved: rays are turned into the mesh's frame instead)."""

    FIELDS = ("body", "link_row", "position", "rotation", "bound", "start", "count",
              "triangles")

    def __init__(self, **arrays):
        for name in self.FIELDS:
            setattr(self, name, np.ascontiguousarray(arrays[name]))

    @classmethod
    def of_body(cls, body, link_row, position, rotation, triangles):
        """Meshes of one body: triangles is a list of (m_i, 3, 3) arrays."""
        n = len(triangles)
        counts = np.array([len(t) for t in triangles], dtype=np.int64)
        bound = np.array([np.sqrt(np.max(np.sum(t.reshape(-1, 3) ** 2, axis=1)))
                          for t in triangles])
        return cls(body=np.full(n, body, dtype=np.int64),
                   link_row=np.asarray(link_row, dtype=np.int64).reshape(n),
                   position=np.asarray(position, dtype=float).reshape(n, 3),
                   rotation=np.asarray(rotation, dtype=float).reshape(n, 3, 3),
                   bound=bound.reshape(n), start=np.cumsum(counts) - counts, count=counts,
                   triangles=(np.concatenate(triangles).astype(float) if n
                              else np.zeros((0, 3, 3))))

    def replace(self, **changes):
        arrays = {name: getattr(self, name) for name in self.FIELDS}
        arrays.update(changes)
        return _Meshes(**arrays)

    def placed(self, link_position, link_rotation):
        position, rotation = _placed_frames(self.link_row, self.position, self.rotation,
                                            link_position, link_rotation)
        return self.replace(position=position, rotation=rotation)

    @staticmethod
    def concatenate(parts):
        offsets = np.cumsum([0] + [len(p.triangles) for p in parts[:-1]])
        arrays = {name: np.concatenate([getattr(p, name) for p in parts])
                  for name in _Meshes.FIELDS if name != "start"}
        arrays["start"] = np.concatenate([p.start + o for p, o in zip(parts, offsets)])
        return _Meshes(**arrays)


def _join_parts(parts, kind):
    """parts (some None) in one kind (_Shapes or _Meshes), or None."""
    parts = [p for p in parts if p is not None and len(p.body)]
    if not parts:
        return None
    return parts[0] if len(parts) == 1 else kind.concatenate(parts)


class _Body:
    """What the caster knows of one body: its links with shapes, shapes, planes, meshes."""

    def __init__(self, body_id, static, links, shapes, planes, meshes=None):
        self.body_id = body_id
        self.static = static
        self.links = links                    # link indices, -1 = base; rows of link poses
        self.shapes = shapes                  # _Shapes in the links' inertial frames
        self.planes = planes                  # list of (link row, point (3,), normal (3,))
        self.meshes = meshes                  # _Meshes in the links' inertial frames, or None
        self._joints = [i for i in links if i >= 0]

    def read_pose(self, base_pose, link_states):
        """The inertial poses of its links as pybullet reports them (a tuple of
        ((x, y, z), (x, y, z, w)), one per link): compared exactly to tell whether the body
        moved. base_pose, link_states: the client's getBasePositionAndOrientation and
        getLinkStates."""
        pose = (base_pose(self.body_id),) if self.links[0] == -1 else ()
        if self._joints:
            pose += tuple((state[0], state[1]) for state in
                          link_states(self.body_id, self._joints, computeForwardKinematics=1))
        return pose

    def placed(self, pose):
        """(_Shapes, [(body, point, normal)], _Meshes or None): its shapes, planes and
        meshes in the world with its links at `pose` (read_pose's)."""
        position, rotation = self._link_frames(pose)
        meshes = self.meshes.placed(position, rotation) if self.meshes is not None else None
        return (self.shapes.placed(position, rotation), self._placed_planes(position, rotation),
                meshes)

    def place_into(self, pose, shapes, shape_rows, meshes, mesh_rows):
        """Writes its shapes' (and meshes') world frames with its links at `pose` into rows
        shape_rows of `shapes` (mesh_rows of `meshes`); returns its planes in the world.
        The same numbers placed() gives."""
        position, rotation = self._link_frames(pose)
        own = self.shapes
        if len(own.body):
            shapes.position[shape_rows], shapes.rotation[shape_rows] = _placed_frames(
                own.link_row, own.position, own.rotation, position, rotation)
        if self.meshes is not None:
            own = self.meshes
            meshes.position[mesh_rows], meshes.rotation[mesh_rows] = _placed_frames(
                own.link_row, own.position, own.rotation, position, rotation)
        return self._placed_planes(position, rotation)

    @staticmethod
    def _link_frames(pose):
        return (np.array([p for p, _ in pose], dtype=float),
                rotation_matrices([q for _, q in pose]))

    def _placed_planes(self, position, rotation):
        return [(self.body_id, position[row] + rotation[row] @ p, rotation[row] @ n)
                for row, p, n in self.planes]


class _Scene:
    """What a cast that ignores one body (or none) sees, laid out for the kernels: the static
    shapes and the other dynamic bodies' shapes in one set of arrays (static rows first, then
    each dynamic body's in the caster's order), all planes, the static and the dynamic
    meshes. A dynamic body's rows are placed again, in place, only when its links' poses
    differ from those they were placed at (compared exactly, so the arrays hold what placing
    them at every cast would give, bit for bit): resting bodies sleep and keep theirs."""

    def __init__(self, static, bodies):
        static_shapes, self._static_planes, self.static_meshes = static
        self._bodies = [b for b in bodies if b.links]
        rows, shape_parts, mesh_parts = 0, [], []
        if static_shapes is not None and len(static_shapes.body):
            shape_parts.append(static_shapes)
            rows = len(static_shapes.body)
        self._slices, mesh_rows = [], 0       # per dynamic body: its shape rows, mesh rows
        for body in self._bodies:
            count = len(body.shapes.body)
            mesh_count = 0 if body.meshes is None else len(body.meshes.body)
            self._slices.append((slice(rows, rows + count),
                                 slice(mesh_rows, mesh_rows + mesh_count)))
            rows, mesh_rows = rows + count, mesh_rows + mesh_count
            shape_parts.append(body.shapes)
            mesh_parts.append(body.meshes)
        # copies (concatenate of one part copies too): the dynamic rows are written in place
        self.shapes = _Shapes.concatenate(shape_parts) if rows else None
        meshes = [m for m in mesh_parts if m is not None and len(m.body)]
        self.dynamic_meshes = _Meshes.concatenate(meshes) if meshes else None
        self._poses = [None] * len(self._bodies)
        self.changes = 0                      # how many times some body was placed anew
        self._planes = [[] for _ in self._bodies]
        self.planes = list(self._static_planes)
        # (index, body id) of the bodies with a base and no links, whose pose is one call's
        # answer (most are: barrels, cans); the others read through _Body.read_pose
        self._base_only = [(index, body.body_id) for index, body in enumerate(self._bodies)
                           if body.links == [-1]]
        self._linked = [index for index, body in enumerate(self._bodies)
                        if body.links != [-1]]

    def update(self, base_pose, link_states):
        """Re-places the dynamic bodies that moved since the last update (all at the first)."""
        poses, moved = self._poses, []
        for index, body_id in self._base_only:
            pose = (base_pose(body_id),)
            if pose != poses[index]:
                moved.append((index, pose))
        for index in self._linked:
            pose = self._bodies[index].read_pose(base_pose, link_states)
            if pose != poses[index]:
                moved.append((index, pose))
        if moved:
            self._place(moved)

    def _place(self, moved):
        """Writes the rows of the bodies moved, [(index, pose)]."""
        self.changes += 1
        planes_moved = False
        for index, pose in moved:
            body = self._bodies[index]
            shape_rows, mesh_rows = self._slices[index]
            planes = body.place_into(pose, self.shapes, shape_rows, self.dynamic_meshes,
                                     mesh_rows)
            if planes or self._planes[index]:
                self._planes[index] = planes
                planes_moved = True
            self._poses[index] = pose
        if planes_moved:
            self.planes = self._static_planes + [p for body in self._planes for p in body]


class RayCaster:
    """Casts rays against the primitive collision shapes of the bodies added to it."""

    def __init__(self, client):
        self._client = client
        self._bodies = {}                     # body id -> _Body
        self.skipped = []                     # (body id, link index) of shapes not cast against
        self._static_placed = {}              # body id -> its shapes and planes in the world
        self._static_cache = None             # all static shapes and planes in the world
        self._scenes = {}                     # exclude_body -> _Scene
        self._last_fan = None                 # cast_fan's last question and answer
        # bound once: a BulletClient makes a new partial at every attribute read
        self._base_pose = client.getBasePositionAndOrientation
        self._link_states = client.getLinkStates

    # --- the set of bodies --------------------------------------------------------------
    def add_body(self, body_id, static, base_shapes=None):
        """Read every collision shape of every link of `body_id`. A static body's shapes are
        placed in the world now and cached: add it again (or call reset) after moving it.
        `base_shapes` gives the shapes of a body with a base and no links instead, for the
        bodies whose shapes pybullet cannot report (those made with useMaximalCoordinates):
        (geometry type, dimensions, local position, local orientation) each, as
        getCollisionShapeData reports them; a triangle mesh as (GEOM_MESH, its triangles
        (m, 3, 3) in its own frame, local position, local orientation)."""
        self.remove_body(body_id)
        client = self._client
        if base_shapes is not None:
            shapes_per_link = [(-1, base_shapes)]
        else:
            # an entry: (body, link, geometry type, dimensions, file, local pos, local orn);
            # body/link of the 2nd+ entries of a link are unreliable in pybullet 3.2.
            shapes_per_link = [(link, [(e[2], e[3], e[5], e[6])
                                       for e in client.getCollisionShapeData(body_id, link)])
                               for link in range(-1, client.getNumJoints(body_id))]
        kinds, rows, positions, rotations, sizes, planes, links = [], [], [], [], [], [], []
        mesh_rows, mesh_positions, mesh_rotations, mesh_triangles = [], [], [], []
        for link, entries in shapes_per_link:
            row = len(links)
            used = False
            for geometry, dims, pos, orn in entries:
                rot = rotation_matrices(orn)[0]
                if geometry == _MESH and isinstance(dims, np.ndarray) and dims.ndim == 3:
                    mesh_rows.append(row)                       # triangles from the World
                    mesh_positions.append(pos)
                    mesh_rotations.append(rot)
                    mesh_triangles.append(dims)
                    used = True
                    continue
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
        meshes = (_Meshes.of_body(body_id, mesh_rows, mesh_positions, mesh_rotations,
                                  mesh_triangles) if mesh_triangles else None)
        body = _Body(body_id, bool(static), links,
                     _Shapes.of_body(body_id, kinds, rows, positions, rotations, sizes), planes,
                     meshes)
        self._bodies[body_id] = body
        if body.static:
            self._static_placed[body_id] = self._placed(body)
        self._static_cache = None
        self._scenes = {}

    def remove_body(self, body_id):
        """Forget `body_id` (no error when it was not added)."""
        if self._bodies.pop(body_id, None) is not None:
            self._static_placed.pop(body_id, None)
            self._static_cache = None
            self._scenes = {}
        self.skipped = [s for s in self.skipped if s[0] != body_id]

    def reset(self):
        """Re-read the poses of the static bodies (after some of them were moved)."""
        for body_id, body in self._bodies.items():
            if body.static:
                self._static_placed[body_id] = self._placed(body)
        self._static_cache = None
        self._scenes = {}

    def _placed(self, body):
        """body's shapes, planes, meshes (see _Body.placed) at its present pose."""
        if not body.links:
            return None, [], None
        return body.placed(body.read_pose(self._base_pose, self._link_states))

    def _static(self):
        """All static shapes in one _Shapes (or None), all static planes, all static meshes
        in one _Meshes (or None)."""
        if self._static_cache is None:
            placed = list(self._static_placed.values())
            shapes = [s for s, _, _ in placed if s is not None]
            planes = [p for _, group_planes, _ in placed for p in group_planes]
            self._static_cache = (_Shapes.concatenate(shapes) if shapes else None, planes,
                                  _join_parts([m for _, _, m in placed], _Meshes))
        return self._static_cache

    def _scene(self, exclude_body):
        """The _Scene of casts ignoring exclude_body, its dynamic bodies at their present
        poses."""
        scene = self._scenes.get(exclude_body)
        if scene is None:
            scene = _Scene(self._static(), (b for b in self._bodies.values()
                                            if not b.static and b.body_id != exclude_body))
            self._scenes[exclude_body] = scene
        scene.update(self._base_pose, self._link_states)
        return scene

    # --- casting -------------------------------------------------------------------------
    def cast(self, origin, directions, range_min, range_max, exclude_body=None, fan=None):
        """Distances [m] from `origin` (3,) along each of `directions` (n, 3) (need not be
        unit) to the nearest hit in [range_min, range_max]; inf where nothing is hit there.
        Shapes of `exclude_body` are ignored. `fan` (x axis (3,), y axis (3,), angle_min,
        angle_increment [rad]): a hint that direction i is cos(a) x + sin(a) y with a =
        angle_min + i angle_increment (a laser's fan); each shape is then tried only on the
        rays that can reach it. The distances are the same with or without it."""
        origin = np.asarray(origin, dtype=float).reshape(3)
        directions = np.asarray(directions, dtype=float).reshape(-1, 3)
        norms = np.sqrt((directions * directions) @ _ONES)
        directions = ray_kernel.unit_rows(directions, norms)
        if directions is None:
            raise ValueError("RayCaster.cast: every direction must be a finite non-zero vector")
        normal = self._coplanar_normal(directions)
        fan = ray_kernel.NO_FAN if fan is None or normal is None else _fan_array(fan, directions)
        return self._nearest(origin, directions, normal, fan, range_min, range_max,
                             exclude_body)

    def cast_fan(self, frame, directions, fan, range_min, range_max, exclude_body=None,
                 cull=True, same_rays=False):
        """A laser's fan, as ray_kernel.fan_rays lays it out: frame (4, 3) the sensor's
        origin and x, y, z axes, directions (n, 3) unit vectors in its xy plane, fan (8,)
        the kernels' fan. Distances as cast() gives them (a new array each call); `cull`:
        try each shape only on the beams that can reach it (the same distances to the last
        bit as without). `same_rays`: the caller's word that these three arrays are the
        ones it passed at its last call, unchanged since (a laser at rest); asked again so
        with the same ranges and no body moved since, the last answer is given again
        without casting."""
        fan = fan if cull else ray_kernel.NO_FAN
        scene = self._scene(exclude_body)
        question = (range_min, range_max, exclude_body, cull, scene, scene.changes)
        last = self._last_fan
        if same_rays and last is not None and last[0] is directions and last[1] == question:
            return last[2].copy()
        ranges = self._nearest(frame[0], directions, frame[3], fan, range_min, range_max,
                               exclude_body, scene)
        self._last_fan = (directions, question, ranges.copy())
        return ranges

    def _nearest(self, origin, directions, normal, fan, range_min, range_max, exclude_body,
                 scene=None):
        """The distances to the nearest hits, inf where none (cast's job once its rays are
        checked): normal, the unit normal of a plane through origin holding every ray, or
        None; fan, the kernels' fan or NO_FAN; scene: _scene(exclude_body) when just got."""
        result = np.full(len(directions), np.inf)
        range_min = max(0.0, float(range_min))
        range_max = float(range_max)
        if not range_min < range_max or len(directions) == 0:
            return result
        if scene is None:
            scene = self._scene(exclude_body)
        for body_id, point, plane_normal in scene.planes:
            if body_id != exclude_body:
                np.minimum(result, self._plane_hits(origin, directions, point, plane_normal,
                                                    range_min, range_max), out=result)
        shapes = scene.shapes
        if normal is None:
            normal, fan = _NO_PLANE, ray_kernel.NO_FAN
        exclude = -1 if exclude_body is None else int(exclude_body)
        for meshes in (scene.static_meshes, scene.dynamic_meshes):
            if meshes is not None:
                ray_kernel.nearest_mesh_hits(
                    origin, directions, normal, meshes.position, meshes.rotation, meshes.bound,
                    meshes.start, meshes.count, meshes.triangles, meshes.body, exclude,
                    range_min, range_max, result, fan)
        if shapes is not None:
            ray_kernel.nearest_hits(origin, directions, normal, shapes.kind, shapes.position,
                                    shapes.rotation, shapes.size, shapes.bound, shapes.body,
                                    exclude, range_min, range_max, result, fan)
        return result

    @staticmethod
    def _plane_hits(origin, directions, point, normal, range_min, range_max):
        denominator = directions @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            t = float((point - origin) @ normal) / denominator
        return np.where((t >= range_min) & (t <= range_max), t, np.inf)

    @staticmethod
    def _coplanar_normal(directions):
        """Unit normal of the plane holding every (unit) direction, or None: the first
        direction crossed with the one most nearly perpendicular to it, checked on all."""
        if len(directions) < 2:
            return None
        first = directions[0]
        other = directions[np.abs(directions @ first).argmin()]
        normal = np.array(cross(first, other))
        length = np.sqrt(normal @ normal)
        if length < 1e-6:                          # all (anti)parallel: no single plane
            return None
        normal /= length
        if np.abs(directions @ normal).max() > 1e-9:
            return None
        return normal


_NO_PLANE = np.zeros(3)            # the kernel's "no common plane"
_FAN_CHECK = 1e-6                  # how closely a fan hint must give the end directions


def _fan_array(fan, directions):
    """The kernels' fan (8,) for a cast's hint, checked on the first and last (unit)
    directions; the kernels' NO_FAN when the hint does not describe them."""
    x_axis, y_axis, angle_min, increment = fan
    array = np.empty(8)
    array[0:3] = x_axis
    array[3:6] = y_axis
    array[6] = angle_min
    array[7] = increment
    return array if ray_kernel.fan_matches(array, directions, _FAN_CHECK) else ray_kernel.NO_FAN
