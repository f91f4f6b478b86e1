"""Gazebo's contact surfaces (friction, stiffness, damping) as Bullet's per-body coefficients.

Gazebo 11 with ODE, for two colliding surfaces a and b (ODEPhysics::Collide):
  friction     mu = min(mu_a, mu_b), mu2 = min(mu2_a, mu2_b)
  stiffness    kp = 1 / (1/kp_a + 1/kp_b)        (two springs in series)
  damping      kd = kd_a + kd_b
  and from them the contact's ERP = dt kp / (dt kp + kd) and CFM = 1 / (dt kp + kd).
SDF's defaults (<surface><friction><ode>, <surface><contact><ode>): mu = mu2 = 1, kp = 1e12,
kd = 1. A URDF's `<gazebo reference="LINK">` `<mu1>` `<mu2>` `<kp>` `<kd>` become those of
every collision of LINK (the URDF-to-SDF conversion).

Bullet (btManifoldResult) combines a body's contactStiffness and contactDamping by the same
two rules and turns them into ERP and CFM by the same formulas, so a kp and kd that a model
or URDF gives go to Bullet as they are. Gazebo's defaults do not: kp 1e12 makes ERP 1, a
contact whose whole penetration is undone in one step, and Gazebo tames that with a limit
Bullet lacks (each body's correcting velocity, SDF's <max_vel> 0.01 m/s); through Bullet, m2wr
spawned with its wheels 0.1 m in the ground was thrown 11 m up. A body with default values
keeps Bullet's own rigid contact (its default ERP) instead, which is Gazebo's default in
effect: stiff, with a gentle correction. (A pair of one body with given values and one
with defaults then gets kd + 0.1 where Gazebo has kd + 1: Bullet's default damping.) Friction it combines differently: the PRODUCT of the two bodies'
coefficients, clamped to 10. Products cannot equal minima for every pair, so:
- every body gets `bullet_friction(mu)` = min(mu, 1). The product of two such coefficients is
  min(mu_a, mu_b) whenever one mu is at most 1 and the other at least 1, or one is 0
  (`exact_pair`). Gazebo's default is 1, so every pair with a default surface is exact; in
  the tutorial's worlds all are (ground 100, walls and barrels 1, m2wr's wheels and caster 1:
  the caster's mu 0 is written where Gazebo never reads it, see robot_description).
  Before this module, bodies took their mu as it was: wheel 1 x ground 100 gave 100, clamped
  to 10, where Gazebo has 1.
- the wheels' ground-contact spheres (wheel_contact) touch nothing but the ground, so theirs
  is chosen to make the pair exact for any values: min(mu_wheel, mu_ground) / f_ground.
- mu2: Bullet's friction is isotropic; mu is used. (The tutorial's surfaces give the same
  minimum for mu and mu2: ground (100, 50) against (1, 1).)
No pybullet import: pure rules; `apply` takes the client.
"""
from dataclasses import dataclass

DEFAULT_MU = 1.0                 # SDF's <mu>, <mu2>
DEFAULT_KP = 1e12                # SDF's <contact><ode><kp> [N/m]
DEFAULT_KD = 1.0                 # SDF's <contact><ode><kd> [N s/m]
BULLET_MAX_FRICTION = 10.0       # btManifoldResult clamps the combined friction to this
PIVOT = 1.0                      # coefficients are capped here (see the module docstring)


@dataclass(frozen=True)
class Contact:
    """A surface's contact spring and damper (<surface><contact><ode>)."""
    kp: float = DEFAULT_KP
    kd: float = DEFAULT_KD


def gazebo_friction(mu_a, mu_b):
    """The friction coefficient Gazebo's ODE gives a contact between two surfaces."""
    return min(mu_a, mu_b)


def bullet_friction(mu):
    """A body's Bullet lateralFriction for a surface whose Gazebo mu is `mu`."""
    return min(mu, PIVOT)


def bullet_pair_friction(coefficient_a, coefficient_b):
    """The friction coefficient Bullet gives a contact between two bodies."""
    return min(coefficient_a * coefficient_b, BULLET_MAX_FRICTION)


def exact_pair(mu_a, mu_b):
    """True when Bullet's friction for bodies set by bullet_friction equals Gazebo's."""
    return abs(bullet_pair_friction(bullet_friction(mu_a), bullet_friction(mu_b))
               - gazebo_friction(mu_a, mu_b)) <= 1e-12


def ground_contact_friction(mu_wheel, mu_ground):
    """lateralFriction of a wheel's ground-contact sphere (it touches only the ground, whose
    coefficient is bullet_friction(mu_ground)) so that the pair gets Gazebo's min."""
    ground = bullet_friction(mu_ground)
    if ground <= 0.0:
        return bullet_friction(mu_wheel)      # any coefficient gives 0 against it
    return gazebo_friction(mu_wheel, mu_ground) / ground


def combined_contact(a: Contact, b: Contact) -> Contact:
    """The contact spring and damper of a pair, by Gazebo's (and Bullet's) rules."""
    return Contact(1.0 / (1.0 / a.kp + 1.0 / b.kp), a.kd + b.kd)


def apply(client, body, link, friction, contact: Contact):
    """Sets a Bullet body's (link -1: base) lateralFriction and, when not Gazebo's defaults,
    its contact stiffness and damping (see the module docstring)."""
    if contact == Contact():
        client.changeDynamics(body, link, lateralFriction=friction)
    else:
        client.changeDynamics(body, link, lateralFriction=friction, contactStiffness=contact.kp,
                              contactDamping=contact.kd)
