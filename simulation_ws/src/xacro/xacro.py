#!/usr/bin/env python3
"""$(find xacro)/xacro.py FILE: the old name of xacro, as xacro 1.13 kept it: the same
output on stdout, then a deprecation note on stderr (roslaunch's command= reads stdout only)."""
import os
import sys

# This file's folder comes first on sys.path and holds this very file, named xacro.py: take
# it off, or `import xacro` would import this script instead of the real module.
_here = os.path.dirname(os.path.realpath(__file__))
sys.path = [entry for entry in sys.path if os.path.realpath(entry or os.curdir) != _here]

try:
    import xacro
except ImportError:
    sys.stderr.write("xacro.py: the xacro module is not importable by %s; run "
                     "scripts/setup.sh and source scripts/env.sh\n" % sys.executable)
    sys.exit(1)

if __name__ == "__main__":
    xacro.main()
    sys.stderr.write("xacro.py is deprecated; please use xacro instead\n")
