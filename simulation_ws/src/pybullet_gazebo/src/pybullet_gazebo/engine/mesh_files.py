"""Mesh files named by a world's `<mesh><uri>`: where they are and their triangles.

URIs resolved (the first existing file wins):
  model://NAME/rest    NAME/rest in each directory of the model path, in order
  file:///abs/path     the path itself; file://rel/path relative to the referring file's folder
  package://PKG/rest   PKG's folder (rospkg, when installed; the engine does not need ROS)
  a plain path         absolute, or relative to the referring file's folder
Formats read (with trimesh; Collada through pycollada): .obj, .stl, .dae. The triangles come
back scaled by the `<scale>` and in the mesh's own frame (the collision's frame).
"""
import os

import numpy as np

FORMATS = (".obj", ".stl", ".dae")


class MeshFileError(Exception):
    """A mesh file that exists but cannot be read as triangles; the message says why."""


def resolve(uri, model_path, base_dir):
    """The absolute path of the file `uri` names, or None when no such file exists."""
    uri = (uri or "").strip()
    candidates = []
    if uri.startswith("model://"):
        rest = uri[len("model://"):]
        candidates = [os.path.join(directory, rest) for directory in model_path]
    elif uri.startswith("file://"):
        rest = uri[len("file://"):]
        candidates = [rest if os.path.isabs(rest) else os.path.join(base_dir, rest)]
    elif uri.startswith("package://"):
        package, _, rest = uri[len("package://"):].partition("/")
        folder = _package_folder(package)
        candidates = [os.path.join(folder, rest)] if folder else []
    elif uri and "://" not in uri:
        candidates = [uri if os.path.isabs(uri) else os.path.join(base_dir, uri)]
    for candidate in candidates:
        if os.path.isfile(candidate):
            return os.path.abspath(candidate)
    return None


def model_name(uri):
    """NAME of a model://NAME/... URI, else None."""
    if not (uri or "").startswith("model://"):
        return None
    return uri[len("model://"):].split("/", 1)[0] or None


def readable(path):
    return os.path.splitext(path)[1].lower() in FORMATS


def load_triangles(path, scale=(1.0, 1.0, 1.0)):
    """(vertices (n, 3) [m], faces (m, 3) vertex indices) of the mesh file at path, the
    vertices multiplied by scale. Raises MeshFileError for a file trimesh cannot read or that
    holds no triangles."""
    import trimesh             # imported here: only worlds with mesh files pay for it
    try:
        mesh = trimesh.load(path, force="mesh", process=False)
    except Exception as error:             # trimesh raises many kinds; all mean "unreadable"
        raise MeshFileError("cannot read mesh %s (%s: %s)" % (path, type(error).__name__, error))
    vertices = np.asarray(getattr(mesh, "vertices", ()), dtype=float).reshape(-1, 3)
    faces = np.asarray(getattr(mesh, "faces", ()), dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        raise MeshFileError("mesh %s holds no triangles" % path)
    return vertices * np.asarray(scale, dtype=float), faces


def write_obj(path, vertices, faces):
    """A Wavefront OBJ of the triangles (how Bullet is given a mesh shape)."""
    with open(path, "w") as out:
        out.write("".join("v %.9g %.9g %.9g\n" % tuple(v) for v in vertices))
        out.write("".join("f %d %d %d\n" % tuple(f + 1) for f in faces))


def _package_folder(package):
    try:
        import rospkg
        return rospkg.RosPack().get_path(package)
    except Exception:                      # rospkg missing or the package unknown
        return None
