"""What the browser draws, as plain JSON-able data (no pybullet, no ROS).

A shape: {"kind": "box", "size": [x, y, z]} | {"kind": "cylinder", "radius", "length"} |
{"kind": "sphere", "radius"} | {"kind": "plane", "size": [x, y], "normal": [x, y, z]} |
{"kind": "mesh", "uri", "url" (where the page loads it, or None), "scale", and with
`inline_meshes` "vertices"/"faces" (flat lists, the triangles the engine read)} |
{"kind": "missing", "uri"} (a mesh nobody could read: the page says so); each with "pose"
[x, y, z, qx, qy, qz, qw] in its link frame and "colour" [r, g, b, a]. Lengths in metres.

world_scene(spec): {"world", "models": [{"name", "static", "ground", "links": [{"name",
"pose" (the link in the world at load), "shapes"}]}], "problems": [text]}. World models are
drawn from their collision shapes, coloured by their visual's material: the stand-in reads
no SDF <visual> geometry (the page says so once per model whose visuals it cannot show).
robot_scene(name, urdf_xml): {"name", "links": {link: [shapes]}, "problems"}, from the
URDF's <visual> elements.
"""
import math
import xml.etree.ElementTree as ET

from ..engine.appearance import DEFAULT_COLOUR, urdf_link_colours
from ..engine.specs import Box, Cylinder, Mesh, Plane, Sphere, TriangleMesh
from ..engine.transforms import Pose

GROUND_COLOUR = (0.8, 0.8, 0.8, 1.0)      # Gazebo's ground plane (Gazebo/Grey lit)


def pose_list(pose: Pose, digits=5):
    return [round(float(v), digits) for v in tuple(pose.position) + tuple(pose.orientation)]


def shape_of(geometry, pose: Pose, colour, mesh_url=None, inline_meshes=False):
    """The JSON shape of an engine geometry (specs.Box, ...); None for an unknown kind."""
    shape = {"pose": pose_list(pose), "colour": [round(float(c), 4) for c in colour]}
    if isinstance(geometry, Box):
        shape.update(kind="box", size=[float(v) for v in geometry.size])
    elif isinstance(geometry, Cylinder):
        shape.update(kind="cylinder", radius=float(geometry.radius),
                     length=float(geometry.length))
    elif isinstance(geometry, Sphere):
        shape.update(kind="sphere", radius=float(geometry.radius))
    elif isinstance(geometry, Plane):
        shape.update(kind="plane", size=[float(v) for v in geometry.size],
                     normal=[float(v) for v in geometry.normal])
    elif isinstance(geometry, TriangleMesh):
        shape.update(kind="mesh", uri=geometry.uri,
                     url=mesh_url(geometry.path) if mesh_url else None, scale=[1, 1, 1])
        if inline_meshes:
            shape.update(vertices=[round(float(v), 5) for v in geometry.vertices.ravel()],
                         faces=[int(v) for v in geometry.faces.ravel()])
    elif isinstance(geometry, Mesh):
        shape.update(kind="missing", uri=geometry.uri)
    else:
        return None
    return shape


def world_scene(spec, mesh_url=None, inline_meshes=False):
    """The scene of a WorldSpec (see the module docstring). `mesh_url(path)`: the URL the
    page loads a mesh file from (the live server's), or None."""
    models, problems = [], []
    for model in spec.models:
        links = []
        ground = any(isinstance(c.geometry, Plane) for link in model.links
                     for c in link.collisions)
        for link in model.links:
            colour = GROUND_COLOUR if ground else (link.colour or DEFAULT_COLOUR)
            shapes = []
            for collision in link.collisions:
                shape = shape_of(collision.geometry, collision.pose, colour, mesh_url,
                                 inline_meshes)
                if shape is None:
                    problems.append("%s::%s: a %s is not drawn" % (
                        model.name, link.name, type(collision.geometry).__name__))
                elif shape["kind"] == "missing":
                    problems.append("%s::%s: mesh %s could not be read, not drawn" % (
                        model.name, link.name, shape["uri"]))
                else:
                    shapes.append(shape)
            links.append({"name": link.name, "pose": pose_list(model.pose.compose(link.pose)),
                          "shapes": shapes})
        models.append({"name": model.name, "static": bool(model.static), "ground": ground,
                       "links": links})
    return {"world": spec.name, "models": models, "problems": problems}


def _floats(text, count, default):
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        return default
    return values if len(values) == count and all(math.isfinite(v) for v in values) \
        else default


def _origin(element):
    origin = element.find("origin")
    if origin is None:
        return Pose()
    return Pose.from_xyz_rpy(*_floats(origin.get("xyz"), 3, [0.0] * 3),
                             *_floats(origin.get("rpy"), 3, [0.0] * 3))


def _urdf_geometry(geometry):
    """(engine geometry or None, mesh (filename, scale) or None) of a URDF <geometry>."""
    if geometry is None:
        return None, None
    box = geometry.find("box")
    if box is not None:
        return Box(tuple(_floats(box.get("size"), 3, [0.0] * 3))), None
    cylinder = geometry.find("cylinder")
    if cylinder is not None:
        return Cylinder(float(cylinder.get("radius", 0)), float(cylinder.get("length", 0))), None
    sphere = geometry.find("sphere")
    if sphere is not None:
        return Sphere(float(sphere.get("radius", 0))), None
    mesh = geometry.find("mesh")
    if mesh is not None:
        return None, (mesh.get("filename", ""), _floats(mesh.get("scale"), 3, [1.0] * 3))
    return None, None


def robot_scene(name, urdf_xml, mesh_url=None):
    """The scene of a robot from its URDF text (see the module docstring)."""
    problems = []
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError as err:
        return {"name": name, "links": {}, "problems": ["%s: its URDF is not XML (%s): "
                                                        "not drawn" % (name, err)]}
    colours = urdf_link_colours(root)
    links = {}
    for link in root.findall("link"):
        shapes = []
        colour = colours.get(link.get("name"), DEFAULT_COLOUR)
        for visual in link.findall("visual"):
            try:
                geometry, mesh = _urdf_geometry(visual.find("geometry"))
            except ValueError:
                geometry, mesh = None, None
            pose = _origin(visual)
            if geometry is not None:
                shapes.append(shape_of(geometry, pose, colour))
            elif mesh is not None:
                url = mesh_url(mesh[0]) if mesh_url else None
                shapes.append({"kind": "mesh", "uri": mesh[0], "url": url, "scale": mesh[1],
                               "pose": pose_list(pose), "colour": list(colour)})
            else:
                problems.append("%s::%s: a visual without a geometry the page knows, not "
                                "drawn" % (name, link.get("name")))
        links[link.get("name")] = shapes
    return {"name": name, "links": links, "problems": problems}
