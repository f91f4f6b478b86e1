"""Bullet bodies for the models of a world file: one body per link that has a collision the
stand-in can simulate. A link becomes a rigid body in maximal coordinates (world02 steps 15 %
faster than with multibodies), or a multibody when it holds a plane (pybullet cannot report a
maximal body's shapes, and the ground checks read the plane back). A static model's bodies
have no mass. Friction and contact stiffness/damping as surface.py turns Gazebo's into
Bullet's. A triangle mesh goes to Bullet as an OBJ file: a concave triangle mesh on a
static body, its convex hull on a dynamic one (Bullet collides concave meshes only when
static); the ray caster gets its triangles (shape_data).
"""
import contextlib
from dataclasses import dataclass
import os
import tempfile
from typing import List

import pybullet

from . import mesh_files, surface
from .specs import Box, Cylinder, LinkSpec, Mesh, ModelSpec, Plane, Sphere, TriangleMesh
from .transforms import Pose


@dataclass
class ModelBodies:
    """The bodies built for one model, in link order."""
    body_ids: List[int]
    link_offsets: List[Pose]        # each body's link frame in the model frame
    inertial_offsets: List[Pose]    # each body's inertial frame in its link frame
    shapes: List[list]              # per body: shape_data() of each collision
    is_ground: bool                 # every collision is a plane
    links: List[LinkSpec]           # the link each body stands for


def build_model(client, model: ModelSpec) -> ModelBodies:
    """Creates the model's bodies at its pose; an empty body list when no collision of it can
    be simulated (meshes are reported by the world reader)."""
    built = ModelBodies([], [], [], [], True, [])
    for link in model.links:
        collisions = [c for c in link.collisions if not isinstance(c.geometry, Mesh)]
        if not collisions:
            continue
        built.is_ground &= all(isinstance(c.geometry, Plane) for c in collisions)
        built.body_ids.append(_create_link_body(client, model, link, collisions))
        built.link_offsets.append(link.pose)
        built.inertial_offsets.append(link.inertial.pose)
        built.links.append(link)
        built.shapes.append([shape_data(c, link.inertial.pose) for c in collisions])
    return built


def _create_link_body(client, model, link, collisions):
    if len(collisions) == 1 and isinstance(collisions[0].geometry, Plane):
        shape = client.createCollisionShape(pybullet.GEOM_PLANE,
                                            planeNormal=collisions[0].geometry.normal)
    else:
        kwargs = dict(shapeTypes=[], radii=[], halfExtents=[], lengths=[], planeNormals=[],
                      fileNames=[], meshScales=[], flags=[],
                      collisionFramePositions=[], collisionFrameOrientations=[])
        # a folder for the OBJ files only when there are meshes: making and removing one
        # for every link was a third of building world02
        has_mesh = any(isinstance(c.geometry, TriangleMesh) for c in collisions)
        with tempfile.TemporaryDirectory(prefix="pybullet_gazebo_mesh_") if has_mesh \
                else contextlib.nullcontext() as folder:
            for collision in collisions:
                _append_shape(kwargs, collision, model.static, folder)
            shape = client.createCollisionShapeArray(**kwargs)
    world_pose = model.pose.compose(link.pose)
    inertial = link.inertial
    mass = 0.0 if model.static else inertial.mass
    body = client.createMultiBody(
        baseMass=mass, baseCollisionShapeIndex=shape,
        basePosition=world_pose.position, baseOrientation=world_pose.orientation,
        baseInertialFramePosition=inertial.pose.position,
        baseInertialFrameOrientation=inertial.pose.orientation,
        useMaximalCoordinates=not any(isinstance(c.geometry, Plane) for c in collisions))
    if mass > 0.0:
        # Gazebo lets resting bodies sleep (auto-disable); so does Bullet, when asked
        # (the mass again: without it pybullet 3.2 sets a maximal body's mass to 0 -> NaN)
        client.changeDynamics(body, -1, mass=mass, localInertiaDiagonal=list(inertial.inertia),
                              activationState=pybullet.ACTIVATION_STATE_ENABLE_SLEEPING)
    # Bullet's friction and contact spring are per body: the lowest mu, the softest spring
    surface.apply(client, body, -1, surface.bullet_friction(min(c.mu for c in collisions)),
                  surface.Contact(min(c.kp for c in collisions), max(c.kd for c in collisions)))
    return body


def _append_shape(kwargs, collision, static, folder):
    """One shape of createCollisionShapeArray; a triangle mesh as an OBJ file in folder
    (None when the link has no triangle mesh)."""
    radius, half, length, normal = 0.0, [0.0, 0.0, 0.0], 0.0, [0.0, 0.0, 1.0]
    file_name, flags = "", 0
    if isinstance(collision.geometry, TriangleMesh):
        kind = pybullet.GEOM_MESH
        file_name = os.path.join(folder, "%d.obj" % len(kwargs["fileNames"]))
        mesh_files.write_obj(file_name, collision.geometry.vertices, collision.geometry.faces)
        flags = pybullet.GEOM_FORCE_CONCAVE_TRIMESH if static else 0
    else:
        kind, dimensions = bullet_geometry(collision)
    kwargs["fileNames"].append(file_name)
    kwargs["meshScales"].append([1.0, 1.0, 1.0])
    kwargs["flags"].append(flags)
    if kind == pybullet.GEOM_MESH:
        pass
    elif kind == pybullet.GEOM_BOX:
        half = [s / 2.0 for s in dimensions]
    elif kind == pybullet.GEOM_CYLINDER:
        length, radius = dimensions[0], dimensions[1]
    elif kind == pybullet.GEOM_SPHERE:
        radius = dimensions[0]
    else:
        normal = list(dimensions)
    kwargs["shapeTypes"].append(kind)
    kwargs["radii"].append(radius)
    kwargs["halfExtents"].append(half)
    kwargs["lengths"].append(length)
    kwargs["planeNormals"].append(normal)
    kwargs["collisionFramePositions"].append(list(collision.pose.position))
    kwargs["collisionFrameOrientations"].append(list(collision.pose.orientation))


def shape_data(collision, inertial_pose):
    """A collision as pybullet's getCollisionShapeData reports one: (geometry type,
    dimensions, position, orientation), the pose in the link's inertial frame. The caster
    needs it for the bodies whose shapes pybullet cannot report. A triangle mesh: (GEOM_MESH,
    its triangles (m, 3, 3) in the collision frame, position, orientation)."""
    local = inertial_pose.inverse().compose(collision.pose)
    if isinstance(collision.geometry, TriangleMesh):
        return (pybullet.GEOM_MESH, collision.geometry.triangles(), local.position,
                local.orientation)
    kind, dimensions = bullet_geometry(collision)
    return kind, dimensions, local.position, local.orientation


def bullet_geometry(collision):
    """(Bullet geometry type, dimensions as getCollisionShapeData gives them: box full
    extents, cylinder (length, radius, 0), sphere (r, r, r), plane normal) of a collision;
    ValueError for a geometry the stand-in cannot simulate."""
    geometry = collision.geometry
    if isinstance(geometry, Box):
        kind, dimensions = pybullet.GEOM_BOX, tuple(geometry.size)
    elif isinstance(geometry, Cylinder):
        kind, dimensions = pybullet.GEOM_CYLINDER, (geometry.length, geometry.radius, 0.0)
    elif isinstance(geometry, Sphere):
        kind, dimensions = pybullet.GEOM_SPHERE, (geometry.radius,) * 3
    elif isinstance(geometry, Plane):
        kind, dimensions = pybullet.GEOM_PLANE, tuple(geometry.normal)
    else:
        raise ValueError("collision '%s': geometry %r is not supported"
                         % (collision.name, geometry))
    return kind, dimensions
