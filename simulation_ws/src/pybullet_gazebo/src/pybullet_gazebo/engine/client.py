"""The pybullet client the engine's users create: pybullet_utils' BulletClient, connected
without an options string.

pybullet prints "argv[0]=" on its standard output for every connection that is given an
options string, and BulletClient always gives one (an empty one): every simulator, every
Gymnasium environment (eight lines for an AsyncVectorEnv of eight) and every offline scene
printed that line. Connected without one, nothing is printed; the physics is the same.
"""
import os

import pybullet
from pybullet_utils.bullet_client import BulletClient


class Client(BulletClient):
    """BulletClient (same methods, the client id bound to each call), quiet at connection.
    `options`: pybullet's connection options (e.g. the GUI's window size), if any."""

    def __init__(self, connection_mode=pybullet.DIRECT, options=""):
        # what BulletClient.__init__ sets (pybullet_utils 3.2.7), bar its options=''
        self._shapes = {}
        self._pid = os.getpid()
        if options:
            self._client = pybullet.connect(connection_mode, options=options)
        else:
            self._client = pybullet.connect(connection_mode)
