"""The browser view: the running world live (web:=true), and recorded runs replayed, in a
three.js page. No ROS here (the adapter hands in the Gazebo service calls), as gui/.

- `scene.py`: what to draw, as JSON-able data: the world's models from its WorldSpec, each
  robot from its URDF's visuals (colours as engine.appearance gives them).
- `frames.py`: where things are now, read from a World: robots' link frames (so wheels
  turn), moving models, the laser's hits, sim time and real-time factor.
- `live.py`: `WebView`, the simulator loop's observer: a frame at most `fps` times per wall
  second while a page is open, nothing while none is; the path so far; Step.
- `server.py`: `WebServer`, aiohttp's HTTP and WebSocket server in a thread and event loop
  of its own: the page, three.js, meshes, frames to every page, buttons from them.
- `site.py`: the static files (the page, viewer.js, three.js from Debian's libjs-three) and
  replays written as a folder that opens from file:// with no network.
- `static/`: the page and viewer.js, shared by the live view and replays.
"""
