"""m2wr_tools' layout: every module imports, and the index in m2wr_tools/__init__.py (and each
sub-package's own) names every module and sub-package there is."""
import importlib
import os
import pkgutil
import re

import pytest

import m2wr_tools

ROOT = os.path.dirname(m2wr_tools.__file__)
MODULES = sorted(m.name for m in pkgutil.walk_packages(m2wr_tools.__path__, "m2wr_tools."))
SUB_PACKAGES = sorted(m.name for m in pkgutil.iter_modules([ROOT]) if m.ispkg)


@pytest.mark.parametrize("name", MODULES)
def test_every_module_imports(name):
    importlib.import_module(name)


def indexed(package):
    """The names a package's docstring lists, one a line: `  name   what it is`."""
    return {m.group(1).rstrip("/") for m in
            re.finditer(r"^ {2,4}([a-z_]+/?) ", package.__doc__ or "", flags=re.MULTILINE)}


def present(folder):
    return {m.name for m in pkgutil.iter_modules([folder])}


def test_the_index_names_every_sub_package_and_top_module():
    missing = present(ROOT) - indexed(m2wr_tools)
    assert not missing, "m2wr_tools/__init__.py does not list %s" % sorted(missing)


@pytest.mark.parametrize("sub", SUB_PACKAGES)
def test_each_sub_package_lists_its_modules(sub):
    package = importlib.import_module("m2wr_tools." + sub)
    missing = present(os.path.join(ROOT, sub)) - indexed(package)
    assert not missing, "m2wr_tools/%s/__init__.py does not list %s" % (sub, sorted(missing))


@pytest.mark.parametrize("sub", SUB_PACKAGES)
def test_the_index_names_every_module_of_each_sub_package(sub):
    missing = present(os.path.join(ROOT, sub)) - indexed(m2wr_tools)
    assert not missing, "m2wr_tools/__init__.py does not list %s/%s" % (sub, sorted(missing))
