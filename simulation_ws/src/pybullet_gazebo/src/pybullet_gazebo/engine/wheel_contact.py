"""Wheels that meet the ground at their mid-plane, as in Gazebo.

A flat cylinder wheel standing on a plane touches it along a line. Gazebo's ODE puts a contact
at each rim, so the wheel's grip acts at its mid-plane. Bullet keeps one contact at one rim
edge and hops between edges: for m2wr (wheels 0.04 m wide, 0.3 m apart) the track width then
jumps between 0.26 m and 0.34 m and a turn on the spot runs 13 % fast or slow.

The fix keeps the wheel's own cylinder for everything but the ground, and adds to each driven
wheel a fixed child link with a sphere of the wheel's radius that touches *only* the ground:
its lowest point is the wheel's mid-plane contact. Collision groups (Bullet: two shapes touch
when each one's group is in the other's mask):
  ground          group GROUND, mask ALL but STATIC (a static model resting on the ground
                  would otherwise cost a plane-box test per step: half of world02's step)
  contact sphere  group CONTACT, mask GROUND
  wheel cylinder  group 1, mask ALL but GROUND and CONTACT
Touching only the ground lets the sphere's friction be chosen so that its pair with the
ground gets exactly Gazebo's friction, min(mu_wheel, mu_ground) (see surface.py).
  everything else Bullet's defaults (dynamic: group 1, mask ALL; static: group 2, mask ALL
                  but 2), which never include CONTACT in their group
"""
import xml.etree.ElementTree as ET

from . import surface

DEFAULT, STATIC = 1, 2         # Bullet's groups of dynamic and of static bodies
GROUND, CONTACT = 64, 128      # bits Bullet itself does not use
ALL = -1
SUFFIX = "__ground_contact"
CONTACT_MASS = 1e-3            # [kg] negligible next to the wheel's
# A real tyre's contact patch resists twisting about the vertical; a point contact does not,
# and a robot at rest would creep round (0.03 deg/s). A small torsional friction stops it.
SPINNING_FRICTION = 0.001      # [m] Bullet's spinning-friction lever
# Bullet's friction is a velocity constraint: what its iterative solver leaves unsolved each
# step adds up, and a robot at rest slid sideways at 5e-7 m/s. A friction anchor also pulls
# the contact back to where it started sticking (a position correction), as a tyre that does
# not slip stays put: the drift falls to 1e-11 m/s (the drive's wheel hold does the same for
# rolling, see diff_drive._hold). Anchors make each step about 60 us dearer (world02 + m2wr:
# 165 instead of 100 us), so they are off here and the diff drive turns them on only while
# the robot is told to stand still (DiffDrive._anchor).
FRICTION_ANCHOR = 0


def add_contact_links(root, wheel_links):
    """Adds to a URDF element tree (changed in place) a ground-contact sphere link fixed to
    each named wheel link whose collision is a cylinder; returns {wheel link: contact link}."""
    added = {}
    for link in root.findall("link"):
        name = link.get("name")
        if name not in wheel_links:
            continue
        cylinder = link.find("collision/geometry/cylinder")
        if cylinder is None:
            continue
        origin = link.find("collision/origin")
        xyz = origin.get("xyz", "0 0 0") if origin is not None else "0 0 0"
        contact = name + SUFFIX
        contact_link = ET.SubElement(root, "link", name=contact)
        inertial = ET.SubElement(contact_link, "inertial")
        ET.SubElement(inertial, "mass", value=repr(CONTACT_MASS))
        ET.SubElement(inertial, "inertia", ixx="1e-6", iyy="1e-6", izz="1e-6",
                      ixy="0", ixz="0", iyz="0")
        collision = ET.SubElement(contact_link, "collision")
        ET.SubElement(collision, "origin", xyz=xyz, rpy="0 0 0")
        geometry = ET.SubElement(collision, "geometry")
        ET.SubElement(geometry, "sphere", radius=cylinder.get("radius"))
        joint = ET.SubElement(root, "joint", name=contact + "_joint", type="fixed")
        ET.SubElement(joint, "parent", link=name)
        ET.SubElement(joint, "child", link=contact)
        added[name] = contact
    return added


def apply_groups(client, body, links, contacts, surfaces, ground_mu=None):
    """Sets the collision groups of a loaded robot, and gives each contact sphere its
    wheel's contact spring and the friction that makes the sphere-ground pair Gazebo's
    min(mu_wheel, mu_ground) (surface.ground_contact_friction). `links` maps link names to
    indices, `contacts` is add_contact_links' result, `surfaces` maps links to (Gazebo's mu,
    surface.Contact), `ground_mu` is the ground's mu (None: no ground yet)."""
    for wheel, contact in contacts.items():
        client.setCollisionFilterGroupMask(body, links[wheel], DEFAULT, ALL & ~(GROUND | CONTACT))
        client.setCollisionFilterGroupMask(body, links[contact], CONTACT, GROUND)
        mu, spring = surfaces[wheel]
        friction = surface.bullet_friction(mu) if ground_mu is None \
            else surface.ground_contact_friction(mu, ground_mu)
        surface.apply(client, body, links[contact], friction, spring)
        client.changeDynamics(body, links[contact], spinningFriction=SPINNING_FRICTION,
                              frictionAnchor=FRICTION_ANCHOR)


def mark_ground(client, body):
    client.setCollisionFilterGroupMask(body, -1, GROUND, ALL & ~STATIC)
