"""Finding the `atlas_skin` Python package (the Rust method, compiled).

Installed as an extension, Blender installs the wheel bundled in the extension's zip
before enabling the add-on. The legacy zip carries the unpacked wheel in `_vendor/`,
which is searched last, so an `atlas_skin` installed in Blender's Python comes first.
"""
import importlib
import os
import sys

VENDOR = os.path.join(os.path.dirname(__file__), "_vendor")


class MissingPackage(Exception):
    """The `atlas_skin` package cannot be imported (the message says how to install it)."""


def atlas_skin():
    """The `atlas_skin` module."""
    if os.path.isdir(VENDOR) and VENDOR not in sys.path:
        sys.path.append(VENDOR)
    try:
        return importlib.import_module("atlas_skin")
    except ImportError as error:
        raise MissingPackage(
            f"the atlas_skin Python package cannot be imported ({error}); install the "
            "add-on from its extension zip, which bundles it, or `pip install` its wheel "
            "into Blender's Python"
        ) from error
