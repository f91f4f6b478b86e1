"""Our gazebo_msgs must be wire-compatible with ROS Noetic's: a client built against Gazebo's
gazebo_msgs only talks to a service whose md5sum matches. Figures from
shared/reference/m2wr_and_gazebo.md (md5sums of gazebo_msgs as shipped for Noetic)."""
import pytest

from gazebo_msgs import msg, srv

NOETIC_MD5SUMS = {
    srv.SpawnModel: "9ed9c82c96abe1a00c3e8cdaeee24413",
    srv.DeleteModel: "9ce56b4e9e54616de25d796dc972a262",
    srv.GetModelState: "4c515e936d3319c9610c559c60bfc3d4",
    srv.SetModelState: "5b3ab0281d4f5445def017e3a2e4a07b",
    srv.GetWorldProperties: "36bb0f2eccf4d8be971410c22818ba3f",
    srv.GetPhysicsProperties: "575a5e74786981b7df2e3afc567693a6",
    msg.ModelState: "9330fd35f2fcd82d457e54bd54e10593",
    msg.ModelStates: "48c080191eb15c41858319b4d8a609c2",
}


@pytest.mark.parametrize("kind", list(NOETIC_MD5SUMS), ids=lambda k: k._type)
def test_md5sum_matches_noetic(kind):
    assert kind._md5sum == NOETIC_MD5SUMS[kind]
