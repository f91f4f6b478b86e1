"""Gazebo world files (SDF 1.6) read into a `specs.WorldSpec`. Pure Python: xml.etree and
numpy, no pybullet; `world.World` turns the spec into Bullet bodies.

What is read
- `<world name>`: `<gravity>` (or, as in older files, `<physics><gravity>`) [m/s^2];
  `<physics>` (the one marked `default="true"`, else the first): `max_step_size` [s],
  `real_time_factor`, `real_time_update_rate` [Hz].
- `<model>`: name, `<static>`, `<pose>`; each `<link>` with `<pose>`, `<inertial>` (mass [kg],
  pose, ixx iyy izz [kg m^2]; without one, Gazebo's default of 1 kg and unit inertia) and
  `<collision>`s with `<pose>`, `<geometry>` box / cylinder / sphere / plane / mesh and
  `<surface><friction><ode><mu>/<mu2>` (default 1, as Gazebo's ODE) and
  `<surface><contact><ode><kp>/<kd>` (defaults 1e12 N/m and 1 N s/m, SDF's); see surface.py.
  A nested `<model>` or `<include>` inside a model is flattened into it: its links become links
  of the outer model named `inner::link`, with their poses composed into the outer model frame.
- `<include>` of `<uri>model://NAME</uri>` with optional `<name>`, `<pose>`, `<static>`
  (each replaces the included model's own value). NAME is looked up in the model path, a list
  of directories each holding `NAME/model.config`; the config's `<sdf>` child (the highest
  `version` when there are several) names the model's SDF file, `model.sdf` by default.
- `<state>`: `<model name=X><pose>` replaces the pose of model X, as Gazebo does when it loads
  the world. A `<link name=L><pose>` in a model's state is L's pose in the *world*; it is turned
  into L's pose in the model frame (relative to the model's state pose), so the link ends up
  where the state puts it.

Poses (`x y z roll pitch yaw`) are relative to the parent element's frame (SDF 1.6): the
spec keeps model poses in the world frame, link poses in the model frame, collision and
inertial poses in the link frame, so a collision's world pose is
`model.pose.compose(link.pose).compose(collision.pose)`.

Mesh collisions, in this order
1. A model directory may hold `pybullet_collision.sdf` beside its model.sdf: an ordinary
   `<sdf><model><link name=L><collision>...` file whose collisions (primitives, poses in L's
   frame) replace *all mesh collisions* of the model's link L; L's primitive collisions are
   kept (an explicit choice of the model's author, so it wins).
2. A mesh whose file resolves (mesh_files: model://, file://, package://, a path) and reads
   (.obj, .stl, .dae) becomes a `TriangleMesh` (its triangles, scaled by `<scale>`): the World
   gives Bullet a concave triangle mesh for a static model, a convex hull for a dynamic one,
   and the ray caster tests the triangles exactly.
3. A `model://NAME/...` mesh whose file is missing, when the model path holds a model NAME
   made of primitives only (the project ships construction_barrel, jersey_barrier, coke_can):
   NAME's primitive collisions stand in, scaled by the mesh's `<scale>` and placed at the
   mesh collision's pose; the model gets a warning saying so. This is the series' world03,
   whose barrels are inline models with a model://construction_barrel mesh as collision.
4. Anything else stays a `Mesh` in the spec (the World builder leaves it out) and the model
   gets one warning naming its mesh collisions and their URIs.

What is ignored, and what is reported
- Silently ignored: purely visual or rendering elements (`visual`, `light`, `scene`, `gui`,
  `audio`, `spherical_coordinates`, `wind`, `magnetic_field`, `atmosphere`, `material`, ...),
  elements with no effect on the stand-in (`laser_retro`, `max_contacts`,
  `allow_auto_disable`), flags left at Gazebo's default (`<self_collide>0`, `<kinematic>0`,
  `<gravity>1` in a link, `<enable_wind>0`) and elements that carry no value at all
  (e.g. `<contact><ode/></contact>` as Gazebo writes when it saves a world).
- Anything else that is not read (a `<joint>`, a world `<plugin>`, an `<actor>`, `<road>`,
  `<population>`, a `heightmap` geometry, solver settings, ...) gives ONE warning per
  element name and model in `WorldSpec.warnings`.

Errors (`WorldFileError`) name the file and say what to do: a missing file, malformed XML
(with line and column), an include that is not in the model path (listing the path searched),
a value that is not numbers (naming the model and the text), two models with one name.
"""
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import replace

from . import mesh_files
from . import surface as surface_defaults
from .appearance import sdf_link_colour
from .specs import (Box, CollisionSpec, Cylinder, InertialSpec, LinkSpec, Mesh, ModelSpec,
                    PhysicsSpec, Plane, Sphere, TriangleMesh, WorldSpec)
from .transforms import Pose

REPLACEMENT_FILE = "pybullet_collision.sdf"

# Visual and rendering elements, and elements with no effect on the stand-in: never reported.
IGNORED = frozenset((
    "visual", "light", "scene", "gui", "audio", "spherical_coordinates", "wind",
    "magnetic_field", "atmosphere", "material", "audio_sink", "audio_source", "projector",
    "laser_retro", "max_contacts", "allow_auto_disable",
))
# Flags that are silent when they hold Gazebo's default value, reported otherwise.
FLAG_DEFAULTS = {"self_collide": False, "kinematic": False, "gravity": True,
                 "enable_wind": False, "must_be_base_link": False}
# Bookkeeping of a <state> block that does not change the layout.
STATE_SILENT = frozenset(("sim_time", "real_time", "wall_time", "iterations", "light"))
_TRUE, _FALSE = ("1", "true"), ("0", "false")


class WorldFileError(Exception):
    """A world file, or a model file it includes, cannot be read as the stand-in needs it."""


def model_path_from_env(package_models_dir):
    """Directories to resolve `model://NAME` in: the package's own models directory first,
    then each entry of GAZEBO_MODEL_PATH (colon separated, empty entries skipped)."""
    path = [package_models_dir]
    path.extend(entry for entry in os.environ.get("GAZEBO_MODEL_PATH", "").split(":") if entry)
    return path


def find_world(name_or_path, worlds_dir, resource_path=()):
    """The absolute path of a world given as `world02`, `world02.world` (looked up in
    worlds_dir) or a path to a .world file. A relative path is also looked up in each folder
    of `resource_path`, as Gazebo looks up `worlds/empty.world` in GAZEBO_RESOURCE_PATH.
    Raises WorldFileError listing the known worlds."""
    text = (name_or_path or "").strip()
    candidates = []
    if text and "/" not in text and os.sep not in text:
        candidates.append(os.path.join(worlds_dir, text if text.endswith(".world")
                                       else text + ".world"))
    if text:
        candidates.append(text)
    if text and not os.path.isabs(text):
        candidates.extend(os.path.join(folder, text) for folder in resource_path if folder)
    for candidate in candidates:
        if os.path.isfile(candidate):
            return os.path.abspath(candidate)
    known = []
    if os.path.isdir(worlds_dir):
        known = sorted(f[:-len(".world")] for f in os.listdir(worlds_dir) if f.endswith(".world"))
    raise WorldFileError(
        "world '%s' not found; pass world:=NAME with NAME one of %s (from %s) or a path to a "
        ".world file" % (text, ", ".join(known) or "(none)", worlds_dir))


def load_world(path, model_path):
    """Read the world file at `path` into a WorldSpec, resolving `model://` includes in the
    directories of `model_path` (see model_path_from_env)."""
    return _WorldReader(path, model_path).read()


def load_model_text(text, model_path=()):
    """(ModelSpec, warnings) of the model in an SDF text, as spawn_sdf_model receives it:
    `<sdf><model>` or `<sdf><include>`, also inside a `<world>` (as spawn_model -database
    sends it); Gazebo also takes a `<gazebo>` root. The model's pose
    and name are its own; the caller replaces them. ValueError, naming what is wrong, for text
    that is not such a model."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as error:
        line, column = error.position
        raise ValueError("model_xml is malformed XML at line %d, column %d (%s); send an "
                         "<sdf><model> document" % (line, column, str(error).rsplit(": line", 1)[0]))
    if root.tag not in ("sdf", "gazebo"):
        raise ValueError("model_xml's root element is <%s>; an SDF model is <sdf version='1.6'>"
                         "<model name='...'>..." % root.tag)
    reader = _WorldReader("<spawn_sdf_model request>", model_path)
    parent = root.find("world") if root.find("world") is not None else root
    elem = parent.find("model")       # spawn_model -database sends <sdf><world><include>
    try:
        if elem is not None:
            model = reader.model(elem)
        elif parent.find("include") is not None:
            model = reader.include(parent.find("include"), "spawn request")
        else:
            raise ValueError("model_xml has no <model> (nor <include>) under <%s>; the stand-in "
                             "spawns models (lights and actors are not simulated)" % root.tag)
    except WorldFileError as error:
        raise ValueError(str(error).replace("<spawn_sdf_model request>: ", ""))
    return model, tuple(reader.warnings)


def _read_xml(path, what):
    try:
        return ET.parse(path).getroot()
    except FileNotFoundError:
        raise WorldFileError("%s not found: %s; check the path" % (what, path)) from None
    except OSError as error:
        raise WorldFileError("cannot read %s %s (%s); pass a readable file"
                             % (what, path, error.strerror)) from None
    except ET.ParseError as error:
        line, column = error.position
        reason = str(error).rsplit(": line", 1)[0]
        raise WorldFileError("malformed XML in %s %s at line %d, column %d (%s); fix the file"
                             % (what, path, line, column, reason)) from None


def _text(elem, tag, default=None):
    child = elem.find(tag)
    if child is None or child.text is None or not child.text.strip():
        return default
    return child.text.strip()


def _all_zero(text):
    """True when text is empty or only zeros (a link at rest in a <state>)."""
    try:
        return all(float(v) == 0.0 for v in (text or "").split())
    except ValueError:
        return False


def _scaled(geometry, scale):
    """A primitive geometry stretched by a mesh's <scale> (sx, sy, sz): a cylinder (along z)
    takes the larger of sx, sy for its radius, a sphere the largest of the three."""
    sx, sy, sz = scale
    if isinstance(geometry, Box):
        return Box(tuple(v * k for v, k in zip(geometry.size, scale)))
    if isinstance(geometry, Cylinder):
        return Cylinder(radius=geometry.radius * max(sx, sy), length=geometry.length * sz)
    if isinstance(geometry, Sphere):
        return Sphere(radius=geometry.radius * max(scale))
    return geometry


def _carries_value(elem):
    """True when the element or a descendant has text or a non-empty attribute."""
    for node in elem.iter():
        if (node.text and node.text.strip()) or any(v.strip() for v in node.attrib.values()):
            return True
    return False


class _WorldReader:
    def __init__(self, path, model_path):
        self.path = os.path.abspath(path)
        self.model_path = list(model_path)
        self.files = [self.path]            # the file being read now is files[-1]
        self.warnings = []
        self._warned = set()
        self._stand_ins = {}                # model name -> its primitive collisions, or None

    # --- reporting ------------------------------------------------------------------------
    def error(self, message):
        return WorldFileError("%s: %s" % (self.files[-1], message))

    def warn(self, owner, key, message):
        """One warning per (owner, key): owner names the model (or the world)."""
        if (owner, key) not in self._warned:
            self._warned.add((owner, key))
            self.warnings.append("%s: %s" % (owner, message))

    def check_rest(self, elem, handled, owner, where):
        """Report each child of elem that is not in `handled` and is not silently ignorable."""
        for child in elem:
            tag = child.tag
            if tag in handled or tag in IGNORED or not _carries_value(child):
                continue
            if tag in FLAG_DEFAULTS:
                if self.boolean(child.text, owner, tag, None) == FLAG_DEFAULTS[tag]:
                    continue
                self.warn(owner, tag, "<%s>%s</%s> in %s is not supported; Gazebo's default "
                          "is used" % (tag, (child.text or "").strip(), tag, where))
                continue
            self.warn(owner, tag, "<%s> in %s is not supported; ignored" % (tag, where))

    # --- values -----------------------------------------------------------------------------
    def numbers(self, text, count, owner, what):
        parts = (text or "").split()
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = None
        if values is None or len(values) != count or not all(map(math.isfinite, values)):
            raise self.error("%s: <%s> '%s' must be %d finite number(s); fix the value"
                             % (owner, what, text, count))
        return values

    def sizes(self, values, owner, what, where):
        """values, when none is negative (a shape's extents [m])."""
        if min(values) < 0.0:
            raise self.error("%s: %s %s in %s must not be negative [m]; fix the value"
                             % (owner, what, " ".join("%g" % v for v in values), where))
        return values

    def number(self, elem, tag, default, owner):
        text = _text(elem, tag)
        if text is None:
            return default
        return self.numbers(text, 1, owner, tag)[0]

    def boolean(self, text, owner, tag, default):
        value = (text or "").strip().lower()
        if not value:
            return default
        if value in _TRUE:
            return True
        if value in _FALSE:
            return False
        raise self.error("%s: <%s> '%s' must be true or false; fix the value"
                         % (owner, tag, text))

    def pose(self, elem, owner):
        """The <pose> child of elem (identity when absent)."""
        child = elem.find("pose")
        if child is None:
            return Pose()
        if child.get("frame", "").strip():
            self.warn(owner, "pose frame", "<pose frame='%s'> is not supported; the pose is "
                      "read relative to its parent element" % child.get("frame"))
        try:
            return Pose.parse_sdf(child.text)
        except ValueError as error:
            raise self.error("%s: %s; fix the <pose>" % (owner, error)) from None

    # --- the world ------------------------------------------------------------------------
    def read(self):
        root = _read_xml(self.path, "world file")
        world = root.find("world") if root.tag == "sdf" else None
        if world is None:
            raise self.error("no <sdf><world> element; a Gazebo world file is "
                             "<sdf version='1.6'><world name='...'>...")
        name = world.get("name", "default")
        owner = "world '%s'" % name
        physics = self.physics(world, owner)
        models = []
        for child in world:
            if child.tag == "model":
                models.append(self.model(child))
            elif child.tag == "include":
                models.append(self.include(child, owner))
        names = [m.name for m in models]
        for model_name in names:
            if names.count(model_name) > 1:
                raise self.error("two models are named '%s'; give each <model> or <include> a "
                                 "unique name" % model_name)
        for state in world.findall("state"):
            models = self.apply_state(state, models, owner)
        self.check_rest(world, {"physics", "gravity", "model", "include", "state"},
                        owner, "the world")
        return WorldSpec(name=name, source=self.path, physics=physics, models=tuple(models),
                         warnings=tuple(self.warnings))

    def physics(self, world, owner):
        candidates = world.findall("physics")
        chosen = None
        for candidate in candidates:
            if self.boolean(candidate.get("default"), owner, "physics default", False):
                chosen = candidate
                break
        if chosen is None and candidates:
            chosen = candidates[0]
        default = PhysicsSpec()
        gravity_text = _text(world, "gravity")
        if gravity_text is None and chosen is not None:
            gravity_text = _text(chosen, "gravity")
        gravity = (tuple(self.numbers(gravity_text, 3, owner, "gravity"))
                   if gravity_text is not None else default.gravity)
        if chosen is None:
            return replace(default, gravity=gravity)
        owner_physics = owner + " <physics>"
        spec = PhysicsSpec(
            max_step_size=self.number(chosen, "max_step_size", default.max_step_size,
                                      owner_physics),
            real_time_factor=self.number(chosen, "real_time_factor", default.real_time_factor,
                                         owner_physics),
            real_time_update_rate=self.number(chosen, "real_time_update_rate",
                                              default.real_time_update_rate, owner_physics),
            gravity=gravity)
        if spec.max_step_size <= 0.0:
            raise self.error("%s: <max_step_size> %g must be > 0 [s]; fix the value"
                             % (owner_physics, spec.max_step_size))
        self.check_rest(chosen, {"max_step_size", "real_time_factor", "real_time_update_rate",
                                 "gravity"}, owner, "<physics>")
        return spec

    # --- models ---------------------------------------------------------------------------
    def model(self, elem, model_dir=None, name=None, pose=None, static=None,
              check_meshes=True):
        """A ModelSpec from a <model> element; name/pose/static replace the element's own.
        Links of nested models are flattened in; an inline nested model's meshes are checked
        by the outer model, an included one's by itself (against its own directory)."""
        name = name or elem.get("name")
        if not name:
            raise self.error("a <model> has no name attribute; add name='...'")
        owner = "model '%s'" % name
        if pose is None:
            pose = self.pose(elem, owner)
        if static is None:
            static = self.boolean(_text(elem, "static"), owner, "static", False)
        links, checked = [], []             # checked[i]: links[i]'s meshes are already handled
        for child in elem:
            if child.tag == "link":
                links.append(self.link(child, owner))
                checked.append(False)
            elif child.tag in ("model", "include"):
                included = child.tag == "include"
                inner = (self.include(child, owner) if included
                         else self.model(child, check_meshes=False))
                if inner.static != static:
                    self.warn(owner, "nested static", "nested model '%s' is %s inside a %s "
                              "model; the outer model's <static> is used" % (
                                  inner.name, "static" if inner.static else "dynamic",
                                  "static" if static else "dynamic"))
                for link in inner.links:
                    links.append(replace(link, name="%s::%s" % (inner.name, link.name),
                                         pose=inner.pose.compose(link.pose)))
                    checked.append(included)
        self.check_rest(elem, {"link", "model", "include", "pose", "static"}, owner,
                        "the model")
        if check_meshes:
            mine = self.replace_meshes([l for l, c in zip(links, checked) if not c],
                                       model_dir, owner)
            mine.reverse()
            links = [link if c else mine.pop() for link, c in zip(links, checked)]
        return ModelSpec(name=name, pose=pose, static=static, links=tuple(links))

    def link(self, elem, owner):
        name = elem.get("name", "link")
        where = "link '%s'" % name
        collisions = []
        for child in elem.findall("collision"):
            collision = self.collision(child, owner, where)
            if collision is not None:
                collisions.append(collision)
        inertial_elem = elem.find("inertial")
        inertial = (self.inertial(inertial_elem, owner, where) if inertial_elem is not None
                    else InertialSpec())
        self.check_rest(elem, {"pose", "inertial", "collision"}, owner, where)
        return LinkSpec(name=name, pose=self.pose(elem, owner), inertial=inertial,
                        collisions=tuple(collisions), colour=sdf_link_colour(elem))

    def inertial(self, elem, owner, where):
        default = InertialSpec()
        mass = self.number(elem, "mass", default.mass, owner)
        if mass <= 0.0:
            raise self.error("%s: <mass> %g in %s must be > 0 [kg]; fix the value"
                             % (owner, mass, where))
        inertia = default.inertia
        inertia_elem = elem.find("inertia")
        if inertia_elem is not None:
            inertia = tuple(self.number(inertia_elem, tag, 0.0, owner)
                            for tag in ("ixx", "iyy", "izz"))
            if any(self.number(inertia_elem, tag, 0.0, owner) != 0.0
                   for tag in ("ixy", "ixz", "iyz")):
                self.warn(owner, "inertia products", "off-diagonal inertia (ixy ixz iyz) in "
                          "%s is not supported; only ixx iyy izz are used" % where)
        self.check_rest(elem, {"mass", "pose", "inertia"}, owner, "<inertial> of " + where)
        return InertialSpec(mass=mass, pose=self.pose(elem, owner), inertia=inertia)

    def collision(self, elem, owner, where):
        """A CollisionSpec, or None when the geometry is empty or not supported."""
        name = elem.get("name", "collision")
        where = "collision '%s' of %s" % (name, where)
        geometry_elem = elem.find("geometry")
        geometry = self.geometry(geometry_elem, owner, where) if geometry_elem is not None \
            else None
        mu, mu2 = 1.0, 1.0
        kp, kd = surface_defaults.DEFAULT_KP, surface_defaults.DEFAULT_KD
        surface = elem.find("surface")
        if surface is not None:
            friction = surface.find("friction")
            if friction is not None:
                ode = friction.find("ode")
                if ode is not None:
                    mu = self.number(ode, "mu", mu, owner)
                    mu2 = self.number(ode, "mu2", mu2, owner)
                    self.check_rest(ode, {"mu", "mu2"}, owner, "<friction><ode> of " + where)
                self.check_rest(friction, {"ode"}, owner, "<friction> of " + where)
            contact = surface.find("contact")
            if contact is not None:
                ode = contact.find("ode")
                if ode is not None:
                    kp = self.number(ode, "kp", kp, owner)
                    kd = self.number(ode, "kd", kd, owner)
                    if not (kp > 0.0 and kd >= 0.0):
                        raise self.error("%s: <kp> %g and <kd> %g of the <contact><ode> of %s "
                                         "must be kp > 0 and kd >= 0; fix the values"
                                         % (owner, kp, kd, where))
                    self.check_rest(ode, {"kp", "kd"}, owner, "<contact><ode> of " + where)
                self.check_rest(contact, {"ode"}, owner, "<contact> of " + where)
            self.check_rest(surface, {"friction", "contact"}, owner, "<surface> of " + where)
        self.check_rest(elem, {"pose", "geometry", "surface"}, owner, where)
        if geometry is None:
            return None
        return CollisionSpec(name=name, geometry=geometry, pose=self.pose(elem, owner),
                             mu=mu, mu2=mu2, kp=kp, kd=kd)

    def geometry(self, elem, owner, where):
        shapes = list(elem)
        if not shapes or shapes[0].tag == "empty":
            return None
        shape = shapes[0]
        tag = shape.tag
        if tag == "box":
            return Box(tuple(self.sizes(self.numbers(_text(shape, "size", "1 1 1"), 3, owner,
                                                     "size"), owner, "box <size>", where)))
        if tag == "cylinder":
            radius, length = self.sizes([self.number(shape, "radius", 1.0, owner),
                                         self.number(shape, "length", 1.0, owner)],
                                        owner, "cylinder <radius> <length>", where)
            return Cylinder(radius=radius, length=length)
        if tag == "sphere":
            return Sphere(radius=self.sizes([self.number(shape, "radius", 1.0, owner)], owner,
                                            "sphere <radius>", where)[0])
        if tag == "plane":
            normal = tuple(self.numbers(_text(shape, "normal", "0 0 1"), 3, owner, "normal"))
            if not any(normal):
                raise self.error("%s: plane <normal> 0 0 0 in %s is not a direction; write "
                                 "0 0 1 for flat ground" % (owner, where))
            return Plane(
                normal=normal,
                size=tuple(self.numbers(_text(shape, "size", "1 1"), 2, owner, "size")))
        if tag == "mesh":
            return self.mesh(shape, owner, where)
        self.warn(owner, tag, "<%s> geometry of %s is not supported; the collision is "
                  "left out" % (tag, where))
        return None

    def mesh(self, shape, owner, where):
        """A TriangleMesh when the file resolves and reads, else a Mesh (see replace_meshes)."""
        uri = _text(shape, "uri", "")
        scale = tuple(self.numbers(_text(shape, "scale", "1 1 1"), 3, owner, "scale"))
        path = mesh_files.resolve(uri, self.model_path, os.path.dirname(self.files[-1]))
        if path is not None and not mesh_files.readable(path):
            self.warn(owner, "mesh format " + uri, "mesh %s of %s: the stand-in reads %s files "
                      "only; convert it to one of them" % (
                          uri, where, ", ".join(mesh_files.FORMATS)))
        elif path is not None:
            try:
                vertices, faces = mesh_files.load_triangles(path, scale)
                return TriangleMesh(uri=uri, path=path, vertices=vertices, faces=faces)
            except mesh_files.MeshFileError as error:
                self.warn(owner, "mesh file " + uri, "%s (mesh of %s); fix or replace the file"
                          % (error, where))
        return Mesh(uri=uri, scale=scale)

    def stand_in(self, name):
        """The collisions (in the stand-in's model frame) of model NAME from the model path
        when all of them are primitives, else None. Read once per name."""
        if name not in self._stand_ins:
            collisions = None
            try:
                model_dir = self.find_model(name)
            except WorldFileError:
                model_dir = None
            if model_dir is not None:
                sdf_path = self.model_sdf_file(model_dir)
                self.files.append(sdf_path)
                root = _read_xml(sdf_path, "model file of model://%s" % name)
                model_elem = root.find("model") if root.tag == "sdf" else None
                model = (self.model(model_elem, model_dir, check_meshes=False)
                         if model_elem is not None else None)
                self.files.pop()
                if model is not None:
                    collisions = [replace(c, pose=link.pose.compose(c.pose))
                                  for link in model.links for c in link.collisions]
                    if not collisions or any(isinstance(c.geometry, (Mesh, TriangleMesh))
                                             for c in collisions):
                        collisions = None
            self._stand_ins[name] = collisions
        return self._stand_ins[name]

    def stand_in_for(self, collision):
        """Collisions replacing a mesh collision whose file is missing, from the primitive
        model its model://NAME URI names, scaled by the mesh's <scale> and placed at the
        mesh's pose; None when there is no such model."""
        name = mesh_files.model_name(collision.geometry.uri)
        primitives = self.stand_in(name) if name else None
        if primitives is None:
            return None
        scale = collision.geometry.scale
        return [replace(c, name="%s::%s" % (collision.name, c.name),
                        geometry=_scaled(c.geometry, scale),
                        pose=collision.pose.compose(Pose(
                            tuple(p * k for p, k in zip(c.pose.position, scale)),
                            c.pose.orientation)),
                        mu=collision.mu, mu2=collision.mu2, kp=collision.kp, kd=collision.kd)
                for c in primitives]

    def replace_meshes(self, links, model_dir, owner):
        """Links with mesh collisions replaced from REPLACEMENT_FILE where it names them;
        then each mesh whose file is missing by the primitives of the model its URI names
        (stand_in_for); what is left is reported."""
        if not any(isinstance(c.geometry, (Mesh, TriangleMesh))
                   for link in links for c in link.collisions):
            return links
        replacements = {}
        path = os.path.join(model_dir, REPLACEMENT_FILE) if model_dir else None
        if path and os.path.isfile(path):
            self.files.append(os.path.abspath(path))
            root = _read_xml(path, "collision replacement file")
            model_elem = root.find("model")
            for link_elem in (model_elem.findall("link") if model_elem is not None else []):
                where = "link '%s' of %s" % (link_elem.get("name", "link"), REPLACEMENT_FILE)
                replacements[link_elem.get("name", "link")] = [
                    c for c in (self.collision(e, owner, where)
                                for e in link_elem.findall("collision")) if c is not None]
            self.files.pop()
        result, meshes = [], []
        for link in links:
            has_mesh = any(isinstance(c.geometry, (Mesh, TriangleMesh)) for c in link.collisions)
            if has_mesh and link.name in replacements:
                kept = [c for c in link.collisions
                        if not isinstance(c.geometry, (Mesh, TriangleMesh))]
                link = replace(link, collisions=tuple(kept + replacements[link.name]))
            collisions = []
            for c in link.collisions:
                stand_in = self.stand_in_for(c) if isinstance(c.geometry, Mesh) else None
                if stand_in is not None:
                    self.warn(owner, "stand-in " + c.geometry.uri, "mesh %s of collision '%s' "
                              "(link '%s') is not in the model path; the primitive collisions "
                              "of model://%s are used instead, scaled by %s" % (
                                  c.geometry.uri, c.name, link.name,
                                  mesh_files.model_name(c.geometry.uri),
                                  " ".join("%g" % k for k in c.geometry.scale)))
                    collisions.extend(stand_in)
                else:
                    collisions.append(c)
            link = replace(link, collisions=tuple(collisions))
            meshes.extend("'%s' (link '%s', %s)" % (c.name, link.name, c.geometry.uri)
                          for c in link.collisions if isinstance(c.geometry, Mesh))
            result.append(link)
        if meshes:
            self.warn(owner, "mesh", "mesh collision%s %s: file not found or not readable and "
                      "no primitive replacement, so the World builder leaves %s out; add "
                      "primitive collisions in %s" % (
                          "s" if len(meshes) > 1 else "", ", ".join(meshes),
                          "them" if len(meshes) > 1 else "it",
                          os.path.join(model_dir, REPLACEMENT_FILE) if model_dir
                          else "the model's directory (or use primitives in the world file)"))
        return result

    # --- includes -------------------------------------------------------------------------
    def include(self, elem, owner):
        uri = _text(elem, "uri", "")
        if not uri.startswith("model://") or not uri[len("model://"):].strip("/"):
            raise self.error("%s: <include> uri '%s' is not supported; use model://NAME with "
                             "NAME a directory in the model path" % (owner, uri))
        model_name = uri[len("model://"):].strip("/")
        model_dir = self.find_model(model_name)
        sdf_path = self.model_sdf_file(model_dir)
        self.files.append(sdf_path)
        root = _read_xml(sdf_path, "model file of model://%s" % model_name)
        model_elem = root.find("model") if root.tag == "sdf" else None
        if model_elem is None:
            raise self.error("no <sdf><model> element; a model file is "
                             "<sdf version='1.6'><model name='...'>...")
        self.files.pop()
        name = _text(elem, "name")
        include_owner = "model '%s'" % (name or model_elem.get("name") or model_name)
        pose = self.pose(elem, include_owner) if elem.find("pose") is not None else None
        static = self.boolean(_text(elem, "static"), include_owner, "static", None)
        self.check_rest(elem, {"uri", "name", "pose", "static"}, include_owner, "<include>")
        self.files.append(sdf_path)
        model = self.model(model_elem, model_dir, name=name, pose=pose, static=static)
        self.files.pop()
        return model

    def find_model(self, model_name):
        for directory in self.model_path:
            candidate = os.path.join(directory, model_name)
            if os.path.isfile(os.path.join(candidate, "model.config")):
                return os.path.abspath(candidate)
        raise self.error(
            "<include> of unknown model 'model://%s': no %s/model.config in the model path "
            "[%s]; add the directory that holds %s/ to GAZEBO_MODEL_PATH"
            % (model_name, model_name, ", ".join(self.model_path), model_name))

    def model_sdf_file(self, model_dir):
        config_path = os.path.join(model_dir, "model.config")
        self.files.append(config_path)
        config = _read_xml(config_path, "model config")
        best_version, best_file = None, None
        for sdf in config.findall("sdf"):
            try:
                version = tuple(int(p) for p in sdf.get("version", "0").split("."))
            except ValueError:
                version = (0,)
            if best_version is None or version > best_version:
                best_version, best_file = version, (sdf.text or "").strip()
        self.files.pop()
        return os.path.join(model_dir, best_file or "model.sdf")

    # --- <state> --------------------------------------------------------------------------
    def apply_state(self, state, models, owner):
        by_name = {m.name: i for i, m in enumerate(models)}
        models = list(models)
        self.check_rest(state, {"model"} | STATE_SILENT, owner, "<state>")
        for child in state.findall("model"):
            name = child.get("name", "")
            model_owner = "model '%s'" % name
            if name not in by_name:
                self.warn(owner, "state " + name, "<state> names model '%s', which the world "
                          "does not have; ignored" % name)
                continue
            model = models[by_name[name]]
            if child.find("pose") is not None:
                model = replace(model, pose=self.pose(child, model_owner))
            links = list(model.links)
            link_index = {link.name: i for i, link in enumerate(links)}
            for link_state in child.findall("link"):
                link_name = link_state.get("name", "")
                if link_name not in link_index:
                    self.warn(model_owner, "state link " + link_name, "<state> names link "
                              "'%s', which the model does not have; ignored" % link_name)
                    continue
                if link_state.find("pose") is not None:
                    world_pose = self.pose(link_state, model_owner)
                    i = link_index[link_name]
                    links[i] = replace(links[i], pose=model.pose.inverse().compose(world_pose))
                for motion in link_state:
                    if motion.tag != "pose" and not _all_zero(motion.text):
                        self.warn(model_owner, "state " + motion.tag, "<%s> in the <state> of "
                                  "link '%s' is not supported; the link starts at rest"
                                  % (motion.tag, link_name))
            scale = _text(child, "scale", "1 1 1")
            if self.numbers(scale, 3, model_owner, "scale") != [1.0, 1.0, 1.0]:
                self.warn(model_owner, "state scale", "<scale> %s in <state> is not "
                          "supported; the model keeps its size" % scale)
            if child.find("model") is not None:
                self.warn(model_owner, "state model", "nested <model> states are not "
                          "supported; the nested model keeps its poses")
            models[by_name[name]] = replace(model, links=tuple(links))
        return models
