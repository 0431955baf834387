import os
import sys

# The build lays the add-on out (with the native module) in build/addons.
ADDON_DIR = os.environ.get(
    "MICROPOLY_ADDON_DIR",
    os.path.join(os.path.dirname(__file__), "..", "..", "build", "addons"),
)
sys.path.insert(0, os.path.abspath(ADDON_DIR))
