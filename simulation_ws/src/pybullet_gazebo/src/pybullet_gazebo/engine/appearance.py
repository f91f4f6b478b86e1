"""What things look like: colours of SDF and URDF materials (which sensors Gazebo would draw:
RaySensorSpec.visualize). Data only (no pybullet, no ROS); the GUI (pybullet_gazebo.gui) paints with it.

Colours are RGBA in 0..1. Gazebo's material scripts are named in `<material><script><name>`
(SDF) or `<gazebo reference="link"><material>` (URDF); GAZEBO_MATERIALS holds the diffuse
colour of the common ones as Gazebo's media/materials/scripts/gazebo.material defines them
(the textured ones by the colour their texture mostly shows). An SDF `<diffuse>` (else
`<ambient>`) is used as written. A URDF link is painted with its `<gazebo><material>` when it
has one (Gazebo does the same), else with its `<visual><material>` colour.
"""
import xml.etree.ElementTree as ET
from typing import Dict, Optional, Tuple

RGBA = Tuple[float, float, float, float]

GAZEBO_MATERIALS: Dict[str, RGBA] = {
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/FlatBlack": (0.1, 0.1, 0.1, 1.0),
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/RedBright": (0.87, 0.26, 0.07, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/SkyBlue": (0.13, 0.44, 0.70, 1.0),      # its ambient; the diffuse is plain blue
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/ZincYellow": (0.9725, 0.9529, 0.2078, 1.0),
    "Gazebo/DarkYellow": (0.7, 0.7, 0.0, 1.0),
    "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
    "Gazebo/Gold": (0.8, 0.64869, 0.120759, 1.0),
    "Gazebo/Indigo": (0.33, 0.0, 0.5, 1.0),
    "Gazebo/GreyTransparent": (0.5, 0.5, 0.5, 0.5),
    "Gazebo/RedTransparent": (1.0, 0.0, 0.0, 0.5),
    "Gazebo/GreenTransparent": (0.0, 1.0, 0.0, 0.5),
    "Gazebo/BlueTransparent": (0.0, 0.0, 1.0, 0.5),
    "Gazebo/OrangeTransparent": (1.0, 0.44, 0.0, 0.4),
    "Gazebo/WoodFloor": (0.55, 0.4, 0.25, 1.0),      # textured: hardwood
    "Gazebo/Wood": (0.6, 0.45, 0.3, 1.0),
    "Gazebo/WoodPallet": (0.7, 0.55, 0.35, 1.0),
    "Gazebo/Bricks": (0.6, 0.3, 0.2, 1.0),
    "Gazebo/PaintedWall": (0.9, 0.9, 0.85, 1.0),
    "Gazebo/CeilingTiled": (0.85, 0.85, 0.85, 1.0),
    "Gazebo/Road": (0.3, 0.3, 0.3, 1.0),
}
DEFAULT_COLOUR: RGBA = (0.7, 0.7, 0.7, 1.0)   # Gazebo's untextured grey


def _floats(text, count=4) -> Optional[RGBA]:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        return None
    if len(values) == 3:
        values.append(1.0)
    if len(values) != count or not all(0.0 <= v <= 1.0 for v in values):
        return None
    return tuple(values)


def sdf_material_colour(material) -> Optional[RGBA]:
    """The colour of an SDF `<material>` element: <diffuse>, else <ambient>, else its script
    name looked up in GAZEBO_MATERIALS; None when none of them gives one."""
    if material is None:
        return None
    for tag in ("diffuse", "ambient"):
        colour = _floats(material.findtext(tag))
        if colour is not None:
            return colour
    name = (material.findtext("script/name") or "").strip()
    return GAZEBO_MATERIALS.get(name)


def sdf_link_colour(link) -> Optional[RGBA]:
    """The colour of an SDF `<link>`: its first `<visual>` with a usable `<material>`."""
    for visual in link.findall("visual"):
        colour = sdf_material_colour(visual.find("material"))
        if colour is not None:
            return colour
    return None


def urdf_link_colours(root: ET.Element) -> Dict[str, RGBA]:
    """{link name: colour} for the links of a parsed URDF (RobotSpec.urdf) that name one (see
    the module docstring for which wins)."""
    named = {}                                     # top-level <material name> -> colour
    for material in root.findall("material"):
        colour = _floats(material.find("color").get("rgba")) \
            if material.find("color") is not None else None
        if colour is not None:
            named[material.get("name")] = colour
    colours = {}
    for link in root.findall("link"):
        for material in link.findall("visual/material"):
            colour_el = material.find("color")
            colour = (_floats(colour_el.get("rgba")) if colour_el is not None
                      else named.get(material.get("name")))
            if colour is not None:
                colours[link.get("name")] = colour
                break
    for gazebo in root.findall("gazebo"):
        link, name = gazebo.get("reference"), (gazebo.findtext("material") or "").strip()
        if link and name in GAZEBO_MATERIALS:
            colours[link] = GAZEBO_MATERIALS[name]
    return colours
