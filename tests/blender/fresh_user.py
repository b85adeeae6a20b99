"""Imported before `bpy` by the add-on's test scripts: Blender reads its user folder
(BLENDER_USER_RESOURCES) when bpy is imported; a fresh one means add-ons and extensions
are installed there and nowhere else (removed at exit)."""
import atexit
import os
import shutil
import tempfile

USER = tempfile.mkdtemp(prefix="atlas-skin-blender-")
os.environ["BLENDER_USER_RESOURCES"] = USER
atexit.register(shutil.rmtree, USER, ignore_errors=True)
