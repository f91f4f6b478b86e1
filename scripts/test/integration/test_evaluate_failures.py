"""scripts/evaluate.sh with controllers that fail: one that exits 1 at once and one that
never publishes on /cmd_vel. Each run is marked failed with the reason and the controller's
log, the batch finishes (exit 0, every run in the results) and no process is left."""
import glob
import os

from m2wr_tools.paths import ROOT

FIXTURES = os.path.join(ROOT, "scripts", "test", "fixtures")


def test_crashing_and_silent_controllers_fail_their_runs_not_the_batch(tmp_path, run_evaluate,
                                                                       no_process_left):
    status, text, data = run_evaluate(
        ["--controller", os.path.join(FIXTURES, "crash_controller.py"), "--workers", "1",
         "--start", "0", "8", "0", "--start", "-3", "2", "1"], tmp_path / "crash")
    assert status == 0, text
    assert len(data["runs"]) == 2
    for r in data["runs"]:
        assert r["success"] is False
        assert r["reason"].startswith("controller exited with status 1 while starting"), r["reason"]
        with open(r["controller_log"]) as log:
            assert "giving up on purpose" in log.read()
    assert "2 x controller exited with status 1 while starting" in text
    no_process_left(data)

    status, text, data = run_evaluate(
        ["--controller", os.path.join(FIXTURES, "silent_controller.py"), "--workers", "1",
         "--connect-timeout", "5"], tmp_path / "silent")
    assert status == 0, text
    [r] = data["runs"]
    assert r["success"] is False
    assert r["reason"].startswith("the controller published no /cmd_vel within 5 s"), r["reason"]
    assert os.path.exists(r["controller_log"])
    no_process_left(data)


def test_a_hung_controller_does_not_hold_the_simulator(tmp_path, run_evaluate,
                                                       no_process_left):
    """Blocked for ever in its second callback: lockstep waits for it lockstep_timeout (3 s
    here), steps on without it and says so; the run goes its full length and fails because
    the robot stood still."""
    status, text, data = run_evaluate(
        ["--controller", os.path.join(FIXTURES, "hung_controller.py"), "--workers", "1",
         "--duration", "10", "--run-timeout", "60", "--lockstep-timeout", "3"],
        tmp_path / "hung")
    assert status == 0, text
    [r] = data["runs"]
    assert r["success"] is False
    assert r["reason"].startswith("travelled 0.00 m, under the 1.00 m asked"), r["reason"]
    assert r["cmd_vel_messages"] >= 1            # it did answer once
    assert r["sim_time_s"] >= 9.9                # the whole run (its last step), not held
    [world_log] = glob.glob(str(tmp_path / "hung" / "logs" / "*" / "world.log"))
    with open(world_log) as log:
        assert "lockstep: node /hung_controller (/m2wr/laser/scan not taken in: 0 of 1) was " \
            "still at work 3.00 s after it was sent a message; stepping on" in log.read()
    no_process_left(data)


def test_a_slow_controller_is_failed_by_the_run_timeout(tmp_path, run_evaluate,
                                                        no_process_left):
    """50 ms of CPU per scan: lockstep waits for each answer (about 1x real time), and the
    run's wall-time limit fails it, naming the controller's log."""
    status, text, data = run_evaluate(
        ["--controller", os.path.join(FIXTURES, "slow_controller.py"), "--workers", "1",
         "--run-timeout", "6"], tmp_path / "slow")
    assert status == 0, text
    [r] = data["runs"]
    assert r["success"] is False
    assert r["reason"].startswith("did not finish within 6 s of wall time"), r["reason"]
    assert r["controller_log"] in r["reason"] and os.path.exists(r["controller_log"])
    assert r["cmd_vel_messages"] >= 1
    assert r["sim_time_s"] < 20.0                # lockstep held the simulator for it
    no_process_left(data)


def test_the_next_run_finds_no_record_of_the_last_runs_node(tmp_path, run_evaluate,
                                                            no_process_left):
    """Every run's controller is a node of the same name on the worker's master. rospy never
    takes back one registration (stale_nodes.py), so unless the runner drops it, the master
    keeps the stopped node's address, and when the next run's node registers it sends
    "shutdown" there: to whatever process has taken that port since (another node of the
    run, the simulator). The fixture asks the master before it registers."""
    status, text, data = run_evaluate(
        ["--controller", os.path.join(FIXTURES, "name_reuse_controller.py"), "--workers", "1",
         "--duration", "2", "--start", "0", "8", "0", "--start", "-3", "2", "1",
         "--start", "3", "-2", "0"], tmp_path / "reuse")
    assert status == 0, text
    assert len(data["runs"]) == 3
    for r in data["runs"]:
        with open(r["controller_log"]) as log:
            lines = [line for line in log if line.startswith("master's record")]
        assert lines == ["master's record of /name_reuse_probe at start: none\n"], \
            (r["run_id"], lines)
    no_process_left(data)


def test_a_run_starts_with_no_command_where_the_controller_put_the_robot(tmp_path,
                                                                         run_evaluate):
    """A command that reached the simulator before the run started (a rospy.Rate loop's
    first turn lands or not, as the connection comes up) is forgotten, so runs start alike;
    a set_model_state of the controller's own (the series' bug 2) is kept. The fixture puts
    m2wr at (1, 7), sends 0.5 m/s once when connected, then nothing."""
    status, text, data = run_evaluate(
        ["--controller", os.path.join(FIXTURES, "early_command_controller.py"),
         "--workers", "1", "--duration", "2", "--start", "0", "8", "0"], tmp_path / "early")
    assert status == 0, text
    [r] = data["runs"]
    with open(r["controller_log"]) as log:
        assert "start-up command published" in log.read()
    assert r["cmd_vel_messages"] == 1
    t0, x0, y0 = r["path"][0]
    assert abs(x0 - 1.0) < 0.01 and abs(y0 - 7.0) < 0.01, r["path"][:3]
    assert r["distance_m"] < 0.01, r["path"]       # 0.5 m/s for 2 s had it been kept
    assert abs(r["final_x"] - 1.0) < 0.01 and abs(r["final_y"] - 7.0) < 0.01
