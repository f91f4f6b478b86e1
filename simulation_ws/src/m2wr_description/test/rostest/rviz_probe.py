#!/usr/bin/env python3
"""Runs rviz's own main window (librviz's VisualizationFrame, what the `rviz` program shows,
through Debian's python3-rviz) with a config file, and prints what its Displays panel says.

  rviz_probe.py CONFIG --seconds 20 [--settle 3] [--screenshot out.png]

Loads CONFIG as `rviz -d CONFIG` does, runs Qt's event loop until every display reports no
error and no warning (or --seconds pass), keeps running --settle seconds more (rviz must
stay up and stay OK), saves the window to --screenshot, and prints one JSON line:
{"ok": bool, "seconds": s, "displays": [{"name", "class", "enabled", "level", "items":
{item: text}}]}, where level is what rviz shows beside the display's Status (Ok, Warn,
Error). Needs a display (DISPLAY; the rostest starts an Xvfb) and a ROS master."""
import argparse
import json
import signal
import sys
import time


def status_of(display):
    """(level word, {item: text}) of a display's Status entry in the Displays panel."""
    for index in range(display.numChildren()):
        child = display.childAt(index)
        label = child.getName()                 # "Status: Ok", "Status: Warn", "Status: Error"
        if label.startswith("Status: "):
            items = {child.childAt(i).getName(): str(child.childAt(i).getValue())
                     for i in range(child.numChildren())}
            return label[len("Status: "):], items
    return "none", {}                   # no status yet: rviz has not updated the display


def displays_of(manager):
    group = manager.getRootDisplayGroup()
    found = []
    for index in range(group.numDisplays()):
        display = group.getDisplayAt(index)
        level, items = status_of(display)
        found.append({"name": display.getName(), "class": display.getClassId(),
                      "enabled": bool(display.isEnabled()), "level": level, "items": items})
    return found


def all_ok(displays):
    return bool(displays) and all(d["level"] == "Ok" for d in displays if d["enabled"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("config")
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--settle", type=float, default=3.0)
    parser.add_argument("--screenshot", default="")
    args = parser.parse_args()

    import rospy
    from python_qt_binding.QtCore import QTimer
    from python_qt_binding.QtWidgets import QApplication
    from rviz import bindings as rviz

    rospy.init_node("rviz_probe", anonymous=True, disable_signals=True)
    app = QApplication(sys.argv[:1])
    signal.signal(signal.SIGINT, lambda *_: app.quit())
    frame = rviz.VisualizationFrame()
    frame.setSplashPath("")
    frame.initialize()
    config = rviz.Config()
    rviz.YamlConfigReader().readFile(config, args.config)
    frame.load(config)
    frame.resize(1024, 700)
    frame.show()
    manager = frame.getManager()

    started = time.monotonic()
    state = {"ok_since": None, "displays": [], "result": None}

    def poll():
        now = time.monotonic()
        displays = displays_of(manager)
        state["displays"] = displays
        if all_ok(displays):
            state["ok_since"] = state["ok_since"] or now
        else:
            state["ok_since"] = None             # it must stay OK through the settle time
        settled = state["ok_since"] is not None and now - state["ok_since"] >= args.settle
        if settled or now - started >= args.seconds + args.settle:
            state["result"] = settled
            if args.screenshot:          # from the X server: the 3D view is OpenGL, which
                app.primaryScreen().grabWindow(frame.winId()).save(args.screenshot)  # grab() misses
            app.quit()

    timer = QTimer()
    timer.timeout.connect(poll)
    timer.start(250)
    app.exec_()
    print(json.dumps({"ok": bool(state["result"]), "seconds": time.monotonic() - started,
                      "displays": state["displays"]}), flush=True)
    return 0 if state["result"] else 1


if __name__ == "__main__":
    sys.exit(main())
