"""The page's server: aiohttp (HTTP and WebSocket) in a thread and asyncio event loop of its
own, so the simulator's loop only hands it a frame now and then (`publish_frame`, which
never waits) and never serves a browser itself.

Routes: `/` the page (static/viewer.html), `/static/<file>` its script and style,
`/three/<file>` three.js and its loaders (Debian's libjs-three, site.THREE_FILES only),
`/mesh/<n>` the mesh files the scene names (only those), `/ws` the WebSocket.

Over the WebSocket, to the page (JSON text): on connect {"type": "hello", "scene",
"robots": {name: robot scene}, "paths": {robot: [x0, y0, x1, ...]}, "control": bool,
"frame"}; then {"type": "robot", "robot": robot scene}, {"type": "remove", "name"}, frames
(frames.py), at most `max_rate` a wall second, each page getting the latest when it is
ready for one (a slow page skips frames; nothing queues up for it), and {"type": "error",
"text"} in answer to a message it could not act on. From the page: {"op": "pause" | "play" |
"step" | "reset"}; anything else (not JSON, not an object, an unknown op, more than
MAX_MESSAGE bytes) is answered by an error and changes nothing. `control(op)` runs in a
worker thread, one call at a time per page; with `control` None the page is view-only.
"""
import asyncio
import json
import os
import threading
import time

from aiohttp import WSMsgType, web

from . import site

OPS = ("pause", "play", "step", "reset")
MAX_MESSAGE = 4096              # [bytes] the largest message a page may send
SEND_TIMEOUT = 10.0             # [s] wall: a page that takes longer for one frame is closed
HEARTBEAT = 10.0                # [s] wall: WebSocket ping; a vanished page is dropped after it


class _Page:
    """One open page: what it still has to get, sent by a task of its own."""

    def __init__(self, ws):
        self.ws = ws
        self.queue = []              # messages that must all arrive, in order (scene changes)
        self.frame = None            # the latest frame's text; older ones are dropped
        self.wake = asyncio.Event()


class WebServer:
    def __init__(self, host, port, control=None, info=print, warn=print, max_rate=30.0):
        self.host, self.port = host, port
        self.control = control
        self.info, self.warn = info, warn
        self.period = 1.0 / max_rate if max_rate > 0 else 0.0     # [s] wall between frames
        self.scene = {}
        self.robots = {}                 # name -> robot scene
        self.paths = {}                  # name -> [x, y, ...] (a list the view appends to)
        self.meshes = []                 # mesh file paths; /mesh/<index>
        self.last_frame = None
        self._pages = set()
        self._loop = None
        self._runner = None
        self._thread = None
        self._last_sent = 0.0

    # --- from the simulator's threads -----------------------------------------------------
    @property
    def watchers(self):
        """Pages open now (read without a lock: a set's len is atomic)."""
        return len(self._pages)

    def mesh_url(self, path):
        """The URL a page loads the mesh file `path` from (registered here)."""
        if path not in self.meshes:
            self.meshes.append(path)
        return "mesh/%d/%s" % (self.meshes.index(path), os.path.basename(path))

    def start(self):
        """Binds and serves; OSError when the address cannot be bound."""
        started = threading.Event()
        failure = []

        def serve():
            loop = asyncio.new_event_loop()
            asyncio.set_event_loop(loop)
            self._loop = loop
            try:
                self._runner = web.AppRunner(self._app(), handle_signals=False,
                                             access_log=None)
                loop.run_until_complete(self._runner.setup())
                loop.run_until_complete(web.TCPSite(self._runner, self.host, self.port,
                                                    reuse_address=True).start())
            except OSError as err:
                failure.append(err)
                started.set()
                loop.close()
                return
            started.set()
            try:
                loop.run_forever()
            finally:
                loop.run_until_complete(self._close_pages())
                loop.run_until_complete(self._runner.cleanup())
                loop.close()
        self._thread = threading.Thread(target=serve, name="web-server", daemon=True)
        self._thread.start()
        started.wait()
        if failure:
            raise failure[0]

    def send(self, message):
        """A message every page must get (a robot added or removed), in order."""
        self._call(self._queue_all, json.dumps(message))

    def publish_frame(self, frame):
        """The latest frame, for every page; never waits."""
        self.last_frame = frame
        if self._pages:
            self._call(self._offer_frame, frame)

    def close(self):
        loop = self._loop
        if loop is not None and self._thread is not None and self._thread.is_alive():
            try:
                loop.call_soon_threadsafe(loop.stop)
            except RuntimeError:
                pass
            self._thread.join(5.0)

    def _call(self, function, *args):
        loop = self._loop
        if loop is None:
            return
        try:
            loop.call_soon_threadsafe(function, *args)
        except RuntimeError:            # the loop has ended (shutting down)
            pass

    # --- in the server's event loop ---------------------------------------------------------
    def _app(self):
        app = web.Application()
        app.router.add_get("/", self._index)
        app.router.add_get("/ws", self._websocket)
        app.router.add_get("/static/{name}", self._static)
        app.router.add_get("/three/{name:.+}", self._three)
        app.router.add_get("/mesh/{index:\\d+}/{name}", self._mesh)
        return app

    async def _index(self, _request):
        return web.FileResponse(os.path.join(site.STATIC_DIR, "viewer.html"))

    async def _static(self, request):
        name = request.match_info["name"]
        if name not in site.STATIC_FILES:
            raise web.HTTPNotFound(text="no such file: %s" % name)
        return web.FileResponse(os.path.join(site.STATIC_DIR, name))

    async def _three(self, request):
        name = request.match_info["name"]
        if name not in site.THREE_FILES:
            raise web.HTTPNotFound(text="no such file: %s" % name)
        return web.FileResponse(os.path.join(site.THREE_DIR, site.THREE_FILES[name]))

    async def _mesh(self, request):
        index = int(request.match_info["index"])
        if index >= len(self.meshes) or not os.path.isfile(self.meshes[index]):
            raise web.HTTPNotFound(text="no such mesh")
        return web.FileResponse(self.meshes[index])

    async def _websocket(self, request):
        ws = web.WebSocketResponse(heartbeat=HEARTBEAT, max_msg_size=MAX_MESSAGE)
        await ws.prepare(request)
        page = _Page(ws)
        page.queue.append(json.dumps({
            "type": "hello", "scene": self.scene, "robots": self.robots,
            "paths": {name: list(path) for name, path in self.paths.items()},
            "control": self.control is not None, "frame": self.last_frame}))
        page.wake.set()
        self._pages.add(page)
        writer = asyncio.ensure_future(self._write(page))
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    await self._on_message(page, msg.data)
                elif msg.type == WSMsgType.BINARY:
                    self._answer(page, "binary messages are not understood")
        finally:
            self._pages.discard(page)
            writer.cancel()
        return ws

    async def _on_message(self, page, text):
        try:
            message = json.loads(text)
        except ValueError:
            return self._answer(page, "not JSON: %.60s" % text)
        if not isinstance(message, dict) or message.get("op") not in OPS:
            return self._answer(page, "unknown message %.80s; the operations are %s"
                                % (text, ", ".join(OPS)))
        if self.control is None:
            return self._answer(page, "this page is view-only (web_control:=false)")
        try:
            await asyncio.get_event_loop().run_in_executor(None, self.control, message["op"])
        except Exception as err:            # the service call failed: the page says why
            self._answer(page, "%s failed: %s" % (message["op"], err))

    def _answer(self, page, text):
        page.queue.append(json.dumps({"type": "error", "text": text}))
        page.wake.set()

    def _queue_all(self, text):
        for page in self._pages:
            page.queue.append(text)
            page.wake.set()

    def _offer_frame(self, frame):
        now = time.monotonic()
        if now - self._last_sent < self.period or not self._pages:
            return
        self._last_sent = now
        text = json.dumps(frame)
        for page in self._pages:
            page.frame = text
            page.wake.set()

    async def _write(self, page):
        ws = page.ws
        try:
            while not ws.closed:
                await page.wake.wait()
                page.wake.clear()
                batch, page.queue = page.queue, []
                if page.frame is not None:
                    batch.append(page.frame)
                    page.frame = None
                for text in batch:
                    await asyncio.wait_for(ws.send_str(text), SEND_TIMEOUT)
        except (asyncio.TimeoutError, ConnectionError, RuntimeError):
            await ws.close()

    async def _close_pages(self):
        for page in list(self._pages):
            await page.ws.close()
