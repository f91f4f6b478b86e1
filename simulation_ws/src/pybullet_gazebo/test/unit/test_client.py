"""engine.client.Client: a pybullet connection that prints nothing on the process's standard
output (pybullet_utils' BulletClient prints "argv[0]=" at every connection) and binds the
client id to every call as BulletClient does."""
import pybullet
from pybullet_utils.bullet_client import BulletClient

from pybullet_gazebo.engine.client import Client


def test_connecting_prints_nothing(capfd):
    capfd.readouterr()
    client = Client(connection_mode=pybullet.DIRECT)
    try:
        out, err = capfd.readouterr()
        assert out == "" and err == ""
    finally:
        client.disconnect()


def test_pybullet_utils_client_prints_the_line_this_one_avoids(capfd):
    # the reason for Client: if a pybullet release stops printing it, Client can go
    capfd.readouterr()
    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        assert "argv[0]=" in capfd.readouterr().out
    finally:
        client.disconnect()


def test_calls_go_to_its_own_physics_server():
    first, second = Client(), Client()
    try:
        assert first._client != second._client
        dt, steps = 1.0 / 240.0, 100
        for client, gravity in ((first, 9.81), (second, 1.62)):
            client.setGravity(0, 0, -gravity)
            shape = client.createCollisionShape(pybullet.GEOM_SPHERE, radius=0.1)
            client.createMultiBody(baseMass=1.0, baseCollisionShapeIndex=shape,
                                   basePosition=[0, 0, 1])
        for _ in range(steps):
            first.stepSimulation()
        second.stepSimulation()
        # semi-implicit Euler: the fall after n steps is g dt^2 n (n + 1) / 2, a little
        # less with Bullet's default linear damping (0.04)
        free_fall = 9.81 * dt * dt * steps * (steps + 1) / 2
        fallen = 1.0 - first.getBasePositionAndOrientation(0)[0][2]
        assert 0.97 * free_fall < fallen < 1.0001 * free_fall
        fallen = 1.0 - second.getBasePositionAndOrientation(0)[0][2]   # one step, moon
        assert 0.97 * 1.62 * dt * dt < fallen < 1.0001 * 1.62 * dt * dt
    finally:
        first.disconnect()
        second.disconnect()
