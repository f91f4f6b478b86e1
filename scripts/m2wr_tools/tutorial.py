"""The tutorial's programs (motion_plan/scripts/*.py) as Python modules, found the way rosrun
finds them (the motion_plan package on ROS_PACKAGE_PATH) and loaded by file path: they are
scripts, not an installed package, and import without side effects (`if __name__ ==
'__main__'`), so their functions (clbk_laser, take_action) can be called directly."""
import importlib.util
import os

import rospkg


class TutorialProgramError(RuntimeError):
    pass


def tutorial_program_path(name, package="motion_plan"):
    try:
        folder = rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound:
        raise TutorialProgramError("package %s not found on ROS_PACKAGE_PATH; run "
                                   "'source scripts/env.sh' first" % package) from None
    path = os.path.join(folder, "scripts", name)
    if not os.path.isfile(path):
        raise TutorialProgramError("%s not found in %s/scripts" % (name, folder))
    return path


def load_tutorial_program(name, package="motion_plan"):
    """The module of `package`/scripts/`name` (e.g. "obstacle_avoidance.py")."""
    path = tutorial_program_path(name, package)
    spec = importlib.util.spec_from_file_location(os.path.splitext(name)[0], path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
