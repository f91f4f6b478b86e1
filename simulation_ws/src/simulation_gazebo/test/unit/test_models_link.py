"""simulation_gazebo's models/ is our model folder, so GAZEBO_MODEL_PATH set to
$(find simulation_gazebo)/models (episode 5's launch file) resolves every model the
tutorial's worlds include."""
import os
import re

SRC = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
MODELS = os.path.join(SRC, "simulation_gazebo", "models")


def test_models_is_pybullet_gazebo_s_models():
    assert os.path.realpath(MODELS) == os.path.realpath(os.path.join(SRC, "pybullet_gazebo", "models"))


def test_every_model_the_tutorial_worlds_include_is_there():
    wanted = set()
    for world in ("world01", "world02"):
        with open(os.path.join(SRC, "my_worlds", "worlds", world + ".world")) as source:
            wanted.update(re.findall(r"<uri>model://([^<]+)</uri>", source.read()))
    assert wanted, "the tutorial's worlds include no model://"
    for name in sorted(wanted):
        assert os.path.isfile(os.path.join(MODELS, name, "model.config")), name
