"""The page's files, and replays written as a static folder.

The page (static/viewer.html + viewer.js + viewer.css) is the same for the live view and for
replays; it runs three.js r111 from Debian's libjs-three (scripts/setup.sh installs it) as
classic scripts, which load from file:// as well as over HTTP (ES modules do not load from
file://). A replay folder:

  <folder>/web/            the page's files and three.js, copied once (write_assets)
  <folder>/<name>.js       the replay's data: M2WR_REPLAY = {...}
  <folder>/<name>.html     a page showing it (opens from disk or any web server)

A replay: {"scene": world scene, "robots": {name: robot scene}, "title": text, "frames":
[frame, ...]} (scene.py, frames.py), frames in sim-time order.
"""
import json
import os
import shutil

STATIC_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "static")
STATIC_FILES = ("viewer.html", "viewer.js", "viewer.css")
THREE_DIR = "/usr/share/javascript/three"
THREE_FILES = {              # served or copied name -> path in libjs-three (r111)
    "three.min.js": "build/three.min.js",
    "OrbitControls.js": "examples/js/controls/OrbitControls.js",
    "STLLoader.js": "examples/js/loaders/STLLoader.js",
    "OBJLoader.js": "examples/js/loaders/OBJLoader.js",
    "ColladaLoader.js": "examples/js/loaders/ColladaLoader.js",
}
ASSETS = "web"              # the folder a replay's page takes its files from


class MissingThreeJs(RuntimeError):
    pass


def check_three():
    """MissingThreeJs naming the package when libjs-three is not installed."""
    missing = [name for name, path in THREE_FILES.items()
               if not os.path.isfile(os.path.join(THREE_DIR, path))]
    if missing:
        raise MissingThreeJs("three.js not found in %s (%s): apt-get install libjs-three "
                             "(scripts/setup.sh does)" % (THREE_DIR, ", ".join(missing)))


def write_assets(folder):
    """Copies the page's files and three.js into <folder>/web (once; again when newer)."""
    check_three()
    target = os.path.join(folder, ASSETS)
    os.makedirs(target, exist_ok=True)
    sources = [(os.path.join(STATIC_DIR, n), n) for n in STATIC_FILES if n != "viewer.html"]
    sources += [(os.path.join(THREE_DIR, p), n) for n, p in THREE_FILES.items()]
    for source, name in sources:
        path = os.path.join(target, name)
        if not os.path.exists(path) or os.path.getmtime(path) < os.path.getmtime(source):
            shutil.copyfile(source, path)
    return target


def replay_page(data_file, title, assets=ASSETS):
    """The HTML of a replay page: viewer.html with its files from `assets` and the data."""
    with open(os.path.join(STATIC_DIR, "viewer.html")) as source:
        html = source.read()
    html = html.replace('src="three/', 'src="%s/' % assets) \
        .replace('src="static/', 'src="%s/' % assets) \
        .replace('href="static/', 'href="%s/' % assets)
    html = html.replace("<title>m2wr world</title>", "<title>%s</title>" % _escape(title))
    return html.replace("<!-- replay data -->",
                        '<script src="%s"></script>' % _escape(data_file))


def write_replay(folder, name, replay):
    """Writes <folder>/<name>.js and <folder>/<name>.html (and the assets); returns the
    page's path."""
    return _write_replay(folder, name, json.dumps(replay, separators=(",", ":")),
                         replay.get("title", name))


def write_replay_file(folder, name, path):
    """write_replay for a replay kept as JSON in the file `path` (the batch runner's
    runs/<run_id>.replay.json): its text goes into the page's data as it is, unparsed (a
    class's report holds a replay of megabytes for every run: parsed and written again,
    they were most of the report's time)."""
    with open(path, encoding="utf-8") as source:
        text = source.read()
    return _write_replay(folder, name, text, _title(text) or name)


def _title(text):
    """The replay's "title" from its JSON text: read from the text's start when the object
    begins with it (as replays.build makes it), else from the whole object."""
    head = '{"title":'
    if text.startswith(head):
        try:
            title, _ = json.JSONDecoder().raw_decode(text, len(head))
            if isinstance(title, str):
                return title
        except ValueError:
            pass
    return json.loads(text).get("title")


def _write_replay(folder, name, data, title):
    write_assets(folder)
    data_file = name + ".js"
    with open(os.path.join(folder, data_file), "w", encoding="utf-8") as out:
        out.write("var M2WR_REPLAY = ")
        out.write(data)
        out.write(";\n")
    page = os.path.join(folder, name + ".html")
    with open(page, "w", encoding="utf-8") as out:
        out.write(replay_page(data_file, title))
    return page


def _escape(text):
    return (str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;"))
