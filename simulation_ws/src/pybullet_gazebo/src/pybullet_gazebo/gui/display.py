"""Whether an X display can be opened, asked before any window is: pybullet ends the whole
process when it cannot open one, so the simulator asks first and runs headless instead."""
import ctypes
import ctypes.util
import os


def display_problem(name=None):
    """None when the X display `name` (default: $DISPLAY) can be opened; otherwise a
    sentence saying why not."""
    name = os.environ.get("DISPLAY", "") if name is None else name
    if not name:
        return "there is no display (DISPLAY is unset)"
    library = ctypes.util.find_library("X11")
    if library is None:
        return "libX11 is not installed, so no window can be opened on DISPLAY=%s" % name
    try:
        x11 = ctypes.CDLL(library)
    except OSError as err:
        return "libX11 could not be loaded (%s)" % err
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    handle = x11.XOpenDisplay(name.encode())
    if not handle:
        return "the display DISPLAY=%s cannot be opened" % name
    x11.XCloseDisplay(handle)
    return None
