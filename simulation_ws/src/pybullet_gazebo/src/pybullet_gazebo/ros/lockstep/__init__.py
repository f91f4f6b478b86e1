"""Lockstep: the simulator runs as fast as the machine allows, and each controller still sees
what it would see at real time (docs/lockstep.md).

Controller side: tracker.py (is this process done, what has it taken in and written out),
rospy_hooks.py (rospy fed to the tracker, the reports sent), tick_hold.py (a tick sent with the
readings sets the time only once they are taken in), autoload.py (loads the hooks in
every Python process of the project's environment that imports rospy).
Simulator side: board.py (the latest report of each controller, and whether they are all done
with what the simulator sent them), tick_word.py (a lone loop's ticks sent with the counts
they follow), gate.py (the loop steps on only once they are), inbox.py
(the loop's own thread reads the reports and commands it waits for), and the
fallback for a controller that cannot report: idle_threads.py (its threads' states in /proc),
own_receivers.py (the simulator's own reading threads) and node_processes.py (which process
is which node).
"""
REPORT_TOPIC = "/lockstep/report"
CLOCK_TOPIC = "/clock"
EXPECT_TOPIC = "/lockstep/expect"      # a lone loop's ticks, with the counts they follow
