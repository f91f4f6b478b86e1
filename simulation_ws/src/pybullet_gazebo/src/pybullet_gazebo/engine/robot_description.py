"""Reads a URDF robot description (the `robot_description` parameter, as xacro expands it) for
what Gazebo would take from it beyond links and joints, and cleans it for pybullet's loader.

- `parse_robot(urdf_xml, model_name)` -> `specs.RobotSpec`: the root link and the `<gazebo>`
  tags (model plugins such as libgazebo_ros_diff_drive.so, ray sensors with their
  libgazebo_ros_laser.so plugin, `<mu1>`/`<mu2>` and `<kp>`/`<kd>` per link).
  Anything it does not simulate becomes a warning naming the tag (`RobotSpec.warnings`);
  a description it cannot use raises `RobotDescriptionError` saying what and where. A
  plugin's or sensor's values are range-checked by the part that reads them, when it is
  built (engine/parameters.py's ParameterReader), not here.
- `bullet_tree(spec)` -> a copy of the parsed URDF with only URDF elements left (no `<gazebo>`
  blocks, no link `<pose>`, nothing but `<origin>` and `<geometry>` in a collision), for
  `loadURDF`; `strip_for_bullet(spec)` is the same as text.
The text is parsed once, by parse_robot; everything else reads the RobotSpec it returns (its
`urdf` element tree, links and joints).
- `effective_link_friction(spec)` / `effective_link_contact(spec)` -> (mu1, mu2) / (kp, kd)
  per link that `<gazebo reference>` gives them to.

Friction and contact, as Gazebo takes them from a URDF. urdfdom reads a `<collision>` for its
name, `<origin>` and `<geometry>` only, and sdformat's URDF-to-SDF conversion takes friction
and contact values only from `<gazebo reference="LINK">` (`<mu1>`, `<mu2>`, `<kp>`, `<kd>`),
for every collision of LINK. Anything else inside a `<collision>`, such as an SDF-style
`<surface><friction><ode><mu>`, never reaches Gazebo: the stand-in ignores it too, with one
warning per collision and element (Gazebo says nothing). m2wr's caster writes mu = mu2 = 0
that way, so in Gazebo, and here, it has SDF's default mu = mu2 = 1. A link without
`<gazebo reference>` values takes SDF's defaults: mu = mu2 = 1, kp 1e12 N/m, kd 1 N s/m; a
value missing from a pair (`<mu1>` without `<mu2>`) is its default. Bullet holds one friction
per link, which is exact here: Gazebo gives every collision of a link the same values.
A URDF `<visual>` keeps its `<origin>`, `<geometry>` and `<material>` (the colour:
appearance.py); anything else in it is dropped silently, as urdfdom drops it: nothing there
changes the simulation.

No pybullet here: plain XML (xml.etree) in, `specs` dataclasses and text out.
"""
import copy
import dataclasses
import math
import xml.etree.ElementTree as ET
from typing import Dict, List, Optional, Tuple

from .specs import PluginSpec, RaySensorSpec, RobotSpec
from .transforms import Pose


class RobotDescriptionError(Exception):
    """The robot description cannot be used; the message says what is wrong and where."""


DEFAULT_MU = 1.0                     # SDF's (ODE's) default friction coefficient
DEFAULT_KP = 1e12                    # [N/m] SDF's default <contact><ode><kp>
DEFAULT_KD = 1.0                     # [N s/m] SDF's default <contact><ode><kd>

# The elements a URDF may hold, per parent; strip_for_bullet drops everything else.
# `contact` under `link` is pybullet's own URDF extension and is kept for it.
_URDF_CHILDREN = {
    "robot": {"link", "joint", "material", "transmission"},
    "link": {"inertial", "visual", "collision", "contact"},
    "inertial": {"origin", "mass", "inertia"},
    "visual": {"origin", "geometry", "material"},
    "collision": {"origin", "geometry"},
    "joint": {"origin", "parent", "child", "axis", "limit", "dynamics", "calibration",
              "mimic", "safety_controller"},
}

# Children of a <sensor> that change nothing the stand-in simulates.
_SENSOR_TAGS_IGNORED = {"always_on", "topic"}


def parse_robot(urdf_xml: str, model_name: str) -> RobotSpec:
    """The RobotSpec of a URDF text. Raises RobotDescriptionError when the text is empty,
    not XML, not a <robot>, still xacro, has no single root link, has a joint of no URDF
    type, or holds a value that is not a (finite, >= 0 where required) number where a
    number must be."""
    root = _parse_xml(urdf_xml)
    _check_expanded(root)
    links, joints = _links_and_joints(root)
    root_link = _root_link(links, joints)
    _check_urdf_values(root)
    warnings: List[str] = []
    plugins: List[PluginSpec] = []
    sensors: List[RaySensorSpec] = []
    mu_given: Dict[str, List[Optional[float]]] = {}
    contact_given: Dict[str, List[Optional[float]]] = {}

    for block in root.findall("gazebo"):
        reference = block.get("reference")
        if reference is None:
            for child in block:
                if child.tag == "plugin":
                    plugins.append(_plugin(child, "<gazebo>"))
                else:
                    warnings.append("<gazebo>: <%s> is not supported by the stand-in; ignored"
                                    % child.tag)
            continue
        where = '<gazebo reference="%s">' % reference
        if reference not in links:
            if any(child.tag == "sensor" for child in block):
                raise RobotDescriptionError(
                    "%s holds a <sensor> but the robot has no link '%s'; name one of its "
                    "links: %s" % (where, reference, ", ".join(links)))
            what = "joint" if reference in joints else "no link of the robot"
            for child in block:
                warnings.append("%s (%s): <%s> is not supported by the stand-in; ignored"
                                % (where, what, child.tag))
            continue
        for child in block:
            if child.tag in ("mu1", "mu2"):
                pair = mu_given.setdefault(reference, [None, None])
                pair[0 if child.tag == "mu1" else 1] = _float(child, "%s <%s>" % (where,
                                                                                  child.tag))
            elif child.tag in ("kp", "kd"):
                pair = contact_given.setdefault(reference, [None, None])
                pair[0 if child.tag == "kp" else 1] = _contact_value(
                    child.tag, _float(child, "%s <%s>" % (where, child.tag)), where)
            elif child.tag == "material":
                pass                       # a colour: nothing to simulate
            elif child.tag == "sensor":
                sensor_type = child.get("type", "")
                if sensor_type == "ray":
                    sensors.append(_ray_sensor(child, reference, warnings))
                else:
                    warnings.append("%s: sensor '%s' of type '%s' on link '%s' is not "
                                    "simulated by the stand-in; ignored"
                                    % (where, child.get("name", ""), sensor_type, reference))
            else:
                warnings.append("%s: <%s> is not supported by the stand-in; ignored"
                                % (where, child.tag))

    link_friction = {link: tuple(DEFAULT_MU if v is None else v for v in pair)
                     for link, pair in mu_given.items()}
    link_contact = {link: tuple(pair) for link, pair in contact_given.items()}
    warnings.extend(_collision_extras(root, link_friction))
    return RobotSpec(name=model_name, root_link=root_link, plugins=tuple(plugins),
                     sensors=tuple(sensors), link_friction=link_friction,
                     link_contact=link_contact, warnings=tuple(warnings), links=tuple(links),
                     joints=joints, urdf=root)


def bullet_tree(spec: RobotSpec) -> ET.Element:
    """A copy of the robot's URDF tree with only URDF elements kept (see _URDF_CHILDREN):
    `<gazebo>` blocks, a link's `<pose>`, a collision's `<surface>` and any other foreign
    element are removed; comments go too. The spec's own tree is left as it is."""
    root = copy.deepcopy(spec.urdf)
    _strip(root)
    return root


def urdf_text(root: ET.Element) -> str:
    """A URDF element tree as indented text, for pybullet's loader (which reads files)."""
    for element in root.iter():         # re-indent what removals left ragged
        if element.text is not None and not element.text.strip():
            element.text = None
        element.tail = None
    ET.indent(root, "  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def strip_for_bullet(spec: RobotSpec) -> str:
    """bullet_tree(spec) as text."""
    return urdf_text(bullet_tree(spec))


def driven_wheel_links(spec: RobotSpec, plugin_keys) -> set:
    """Child links of the joints named by `leftJoint`/`rightJoint` of the robot's plugins
    whose filename is in `plugin_keys` (its drives)."""
    joint_names = {value for plugin in spec.plugins if plugin.filename in plugin_keys
                   for key, value in plugin.params.items() if key in ("leftJoint", "rightJoint")}
    return {spec.joints[name][1] for name in joint_names if name in spec.joints}


def effective_link_contact(spec: RobotSpec) -> Dict[str, Tuple[float, float]]:
    """(kp, kd) for every link whose <gazebo reference> gives a <kp> or <kd>; the other value
    of the pair, when not given, is SDF's default."""
    return {link: (DEFAULT_KP if kp is None else kp, DEFAULT_KD if kd is None else kd)
            for link, (kp, kd) in spec.link_contact.items()}


def effective_link_friction(spec: RobotSpec) -> Dict[str, Tuple[float, float]]:
    """(mu1, mu2) for every link whose <gazebo reference> gives a <mu1> or <mu2>; other links
    have SDF's default, mu = mu2 = 1 (see the module docstring)."""
    return dict(spec.link_friction)


# --- helpers -----------------------------------------------------------------------------
def _parse_xml(urdf_xml):
    if urdf_xml is None or not str(urdf_xml).strip():
        raise RobotDescriptionError(
            "robot_description is empty: there is no URDF to load; fill the parameter with "
            "the output of xacro, as spawn.launch does")
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError as err:
        line, column = err.position
        raise RobotDescriptionError(
            "robot_description is not valid XML: line %d, column %d: %s; check the file "
            "(or run xacro on it and read the output)" % (line, column + 1, _reason(err)))
    if root.tag != "robot":
        raise RobotDescriptionError(
            "robot_description's root element is <%s>, not <robot>: it is not a URDF; pass a "
            "URDF (spawn_model -urdf)" % root.tag)
    return root


def _reason(err):
    """ParseError's message without its own ': line L, column C' suffix."""
    text = str(err)
    return text.split(": line ")[0] if ": line " in text else text


def _links_and_joints(root):
    links: List[str] = []
    for link in root.findall("link"):
        name = link.get("name")
        if not name:
            raise RobotDescriptionError("a <link> of the URDF has no name=; name every link")
        if name in links:
            raise RobotDescriptionError("link '%s' is defined twice in the URDF; rename one"
                                        % name)
        links.append(name)
    if not links:
        raise RobotDescriptionError("the URDF <robot name=\"%s\"> has no <link>; a robot "
                                    "needs at least one" % root.get("name", ""))
    joints: Dict[str, Tuple[str, str]] = {}
    for joint in root.findall("joint"):
        name = joint.get("name", "")
        parent, child = joint.find("parent"), joint.find("child")
        ends = []
        for end, tag in ((parent, "parent"), (child, "child")):
            link = None if end is None else end.get("link")
            if link not in links:
                raise RobotDescriptionError(
                    "joint '%s': its <%s link=...> names %s, which is not a link of the URDF; "
                    "name one of: %s" % (name, tag, "no link" if link is None else
                                         "'%s'" % link, ", ".join(links)))
            ends.append(link)
        joints[name] = (ends[0], ends[1])
    return links, joints


# URDF attributes that must hold numbers: (element path under a link or joint, attribute,
# count, lowest value or None). Bullet's loader reads text such as "a b c" or "nan" without a
# word and builds a body with no collision or a NaN mass; urdfdom (Gazebo) refuses them.
_LINK_NUMBERS = (
    ("inertial/origin", "xyz", 3, None), ("inertial/origin", "rpy", 3, None),
    ("inertial/mass", "value", 1, 0.0),
    *(("inertial/inertia", key, 1, None) for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")),
    *((part + "/origin", key, 3, None) for part in ("visual", "collision")
      for key in ("xyz", "rpy")),
    *((part + "/geometry/box", "size", 3, 0.0) for part in ("visual", "collision")),
    *((part + "/geometry/cylinder", key, 1, 0.0) for part in ("visual", "collision")
      for key in ("radius", "length")),
    *((part + "/geometry/sphere", "radius", 1, 0.0) for part in ("visual", "collision")),
    *((part + "/geometry/mesh", "scale", 3, None) for part in ("visual", "collision")),
)
_JOINT_NUMBERS = (
    ("origin", "xyz", 3, None), ("origin", "rpy", 3, None), ("axis", "xyz", 3, None),
    ("limit", "lower", 1, None), ("limit", "upper", 1, None),
    ("limit", "effort", 1, 0.0), ("limit", "velocity", 1, 0.0),
    ("dynamics", "damping", 1, None), ("dynamics", "friction", 1, None),
)
_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


def _check_expanded(root):
    """A description passed before xacro ran on it still holds <xacro:...> elements (its
    macros, includes and ${...} values would be silently missing)."""
    for element in root.iter():
        namespace, _, tag = str(element.tag).rpartition("}")
        if "xacro" in namespace:
            raise RobotDescriptionError(
                "the description holds <xacro:%s>: it is a xacro file, not yet a URDF; expand "
                "it first (xacro FILE > robot.urdf), as spawn.launch does" % tag)


def _check_urdf_values(root):
    """Every number the URDF hands to Bullet is a finite number (>= 0 where the URDF
    demands it), every joint has a URDF type and a non-zero axis; else RobotDescriptionError
    naming the link or joint, the element and the text."""
    def check(owner, element, path, attribute, count, lowest):
        for found in element.findall(path):
            text = found.get(attribute)
            if text is None:
                continue
            try:
                values = [float(v) for v in text.split()]
            except ValueError:
                values = []
            if len(values) != count or not all(math.isfinite(v) for v in values) or (
                    lowest is not None and min(values) < lowest):
                raise RobotDescriptionError(
                    "%s <%s %s=\"%s\">: expected %d finite number%s%s; fix the URDF"
                    % (owner, path, attribute, text, count, "s" if count > 1 else "",
                       "" if lowest is None else " >= %g" % lowest))
    for link in root.findall("link"):
        for rule in _LINK_NUMBERS:
            check("link '%s'" % link.get("name"), link, *rule)
    for joint in root.findall("joint"):
        owner = "joint '%s'" % joint.get("name", "")
        if joint.get("type") not in _JOINT_TYPES:
            raise RobotDescriptionError("%s has type '%s'; a URDF joint is one of %s"
                                        % (owner, joint.get("type"), ", ".join(_JOINT_TYPES)))
        for rule in _JOINT_NUMBERS:
            check(owner, joint, *rule)
        axis = joint.find("axis")
        if axis is not None and axis.get("xyz") is not None and \
                not any(float(v) for v in axis.get("xyz").split()):
            raise RobotDescriptionError("%s <axis xyz=\"%s\"> is a zero vector; give the "
                                        "joint's axis" % (owner, axis.get("xyz")))


def _root_link(links, joints):
    children = {child for _, child in joints.values()}
    roots = [link for link in links if link not in children]
    if len(roots) == 1:
        return roots[0]
    if not roots:
        raise RobotDescriptionError(
            "the URDF has no root link: every link is the child of a joint (a loop?); the "
            "joints must form a tree")
    raise RobotDescriptionError(
        "the URDF has %d root links (%s): every link but one must be the child of a joint; "
        "connect them with joints" % (len(roots), ", ".join(roots)))


def _float(element, where):
    text = (element.text or "").strip()
    try:
        value = float(text)
    except ValueError:
        raise RobotDescriptionError("%s is '%s', not a number; fix the URDF" % (where, text))
    if math.isnan(value):
        raise RobotDescriptionError("%s is NaN; fix the URDF" % where)
    return value


def _number(parent, path, where, default, cast=float):
    element = parent.find(path)
    if element is None:
        return default
    value = _float(element, "%s <%s>" % (where, path))
    if cast is int:
        if value != int(value):
            raise RobotDescriptionError("%s <%s> is %s, not a whole number; fix the URDF"
                                        % (where, path, element.text.strip()))
        return int(value)
    return value


def _plugin(element, where):
    filename = element.get("filename")
    if not filename:
        raise RobotDescriptionError("%s: a <plugin> has no filename=; give the library, "
                                    "e.g. libgazebo_ros_diff_drive.so" % where)
    params = {child.tag: "".join(child.itertext()).strip() for child in element}
    return PluginSpec(name=element.get("name", filename), filename=filename, params=params)


def _ray_sensor(sensor, link, warnings):
    name = sensor.get("name", "")
    where = "sensor '%s' on link '%s':" % (name, link)
    pose_element = sensor.find("pose")
    try:
        pose = Pose.parse_sdf(pose_element.text if pose_element is not None else "")
    except ValueError as err:
        raise RobotDescriptionError("%s <pose>: %s" % (where, err))
    ray = sensor.find("ray")
    if ray is None:
        ray = ET.Element("ray")
        warnings.append("%s has no <ray>; Gazebo's defaults are used" % where)
    defaults = RaySensorSpec(name=name, link=link)
    horizontal = "scan/horizontal/"
    spec = RaySensorSpec(
        name=name, link=link, pose=pose,
        update_rate=_number(sensor, "update_rate", where, defaults.update_rate),
        samples=_number(ray, horizontal + "samples", where, defaults.samples, int),
        min_angle=_number(ray, horizontal + "min_angle", where, defaults.min_angle),
        max_angle=_number(ray, horizontal + "max_angle", where, defaults.max_angle),
        range_min=_number(ray, "range/min", where, defaults.range_min),
        range_max=_number(ray, "range/max", where, defaults.range_max),
        resolution=_number(ray, "range/resolution", where, defaults.resolution),
        noise_mean=_number(ray, "noise/mean", where, defaults.noise_mean),
        noise_stddev=_number(ray, "noise/stddev", where, defaults.noise_stddev),
        plugin=None,      # the ranges of these values: RaySensor._check, when it is built
        visualize=(sensor.findtext("visualize") or "false").strip().lower() in ("true", "1"))

    if _number(ray, horizontal + "resolution", where, 1.0) != 1.0:
        warnings.append("%s <scan><horizontal><resolution> other than 1 is not simulated; "
                        "one ray per sample is cast" % where)
    if ray.find("scan/vertical") is not None:
        warnings.append("%s <scan><vertical> is not simulated; the scan is planar" % where)
    noise_type = ray.find("noise/type")
    if noise_type is not None and (noise_type.text or "").strip() not in ("gaussian", "none"):
        warnings.append("%s noise type '%s' is not simulated; Gaussian noise is used"
                        % (where, (noise_type.text or "").strip()))

    plugin = None
    for child in sensor:
        if child.tag == "plugin":
            if plugin is None:
                plugin = _plugin(child, where)
            else:
                warnings.append("%s a second <plugin> (%s) is ignored; one per sensor"
                                % (where, child.get("filename", "")))
        elif child.tag not in {"pose", "update_rate", "ray", "visualize"} | _SENSOR_TAGS_IGNORED:
            warnings.append("%s <%s> is not supported by the stand-in; ignored"
                            % (where, child.tag))
    return dataclasses.replace(spec, plugin=plugin)


def _collision_extras(root, link_friction):
    """One warning per collision and element for what a URDF <collision> holds besides
    <origin> and <geometry>: Gazebo never reads it (see the module docstring)."""
    warnings = []
    for link in root.findall("link"):
        name = link.get("name")
        if name in link_friction:
            friction = "mu1 = %g, mu2 = %g (its <gazebo reference>)" % link_friction[name]
        else:
            friction = "mu = mu2 = 1 (SDF's default)"
        for index, collision in enumerate(link.findall("collision")):
            which = ("collision '%s'" % collision.get("name") if collision.get("name")
                     else "collision %d (unnamed, counted from 0)" % index)
            for tag in dict.fromkeys(child.tag for child in collision
                                     if child.tag not in _URDF_CHILDREN["collision"]):
                warnings.append(
                    "link '%s' %s: <%s> is ignored, as in Gazebo: a URDF <collision> is read "
                    "for its name, <origin> and <geometry> only, so this collision has the "
                    "link's friction, %s. To set friction or contact values, use "
                    "<gazebo reference=\"%s\"> with <mu1>/<mu2> (<kp>/<kd>) instead"
                    % (name, which, tag, friction, name))
    return warnings


def _contact_value(tag, value, where):
    if (tag == "kp" and not value > 0.0) or (tag == "kd" and not value >= 0.0):
        raise RobotDescriptionError("%s: <%s> %g must be %s; fix the value" % (
            where, tag, value, "above 0 [N/m]" if tag == "kp" else "0 or more [N s/m]"))
    return value


def _strip(element):
    allowed = _URDF_CHILDREN.get(element.tag)
    for child in list(element):
        if allowed is not None and child.tag not in allowed:
            element.remove(child)
        else:
            _strip(child)
