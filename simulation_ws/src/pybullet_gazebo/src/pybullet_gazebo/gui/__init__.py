"""The GUI: a window that shows the world as the simulator steps it, drawn by a viewer
process of its own (viewer.py) from what the simulator sends it (window.py). No ROS here."""
