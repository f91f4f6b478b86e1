"""Meshes on the live page, in Debian's chromium (Playwright): the page's server alone (no
simulator) serves a scene naming an STL, an OBJ and a Collada file, and one mesh whose file
is gone. The three load through three.js's own loaders and are drawn; the page names the
one it could not draw, and nothing else goes wrong."""
import os
import socket

import pytest
import trimesh

from pybullet_gazebo.web.server import WebServer

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--headless", "--use-gl=angle", "--use-angle=swiftshader",
         "--enable-unsafe-swiftshader", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run"]


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_the_page_draws_stl_obj_and_dae_meshes_and_names_the_one_it_could_not(tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api")
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    files = {}
    for ext in ("stl", "obj", "dae"):
        files[ext] = str(tmp_path / ("box." + ext))
        box.export(files[ext])
    server = WebServer("127.0.0.1", _free_port())

    def shape(uri, url, x):
        return {"kind": "mesh", "uri": uri, "url": url, "scale": [1, 1, 1],
                "pose": [x, 0, 0.5, 0, 0, 0, 1], "colour": [0.2, 0.6, 0.2, 1]}
    shapes = [shape("model://m/%s" % os.path.basename(p), server.mesh_url(p), 2.0 * k)
              for k, p in enumerate(files.values())]
    shapes.append(shape("model://m/gone.stl", server.mesh_url(str(tmp_path / "gone.stl")), 8))
    server.scene = {"world": "meshes", "problems": [], "models": [
        {"name": "m", "static": True, "ground": False,
         "links": [{"name": "link", "pose": [0, 0, 0, 0, 0, 0, 1], "shapes": shapes}]}]}
    server.start()
    errors = []
    try:
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
            try:
                page = browser.new_page()
                page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.goto("http://127.0.0.1:%d/" % server.port)
                page.wait_for_function(
                    "() => document.getElementById('problems').textContent.length > 0",
                    timeout=20000)
                page.wait_for_timeout(1000)          # the other loaders have answered too
                problems = page.inner_text("#problems")
                loaded = page.evaluate("() => window.m2wrStats.meshesLoaded")
            finally:
                browser.close()
    finally:
        server.close()
    assert loaded == 3
    assert problems == "m::link: mesh model://m/gone.stl could not be loaded: not drawn"
    # the one console error: the browser's own line about the missing file's 404
    assert len(errors) == 1 and "404" in errors[0], errors
