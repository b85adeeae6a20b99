"""Tests the legacy install of the Blender add-on (Preferences > Add-ons > Install legacy
add-on, for Blender 4.2 to 5.0 without the extension system): the legacy zip installed
into a fresh user folder, enabled, its `atlas_skin` found in the zip's `_vendor/`, and the
operator weighting the demo character as `atlas-skin skin` does.

Usage: python legacy_addon.py LEGACY.zip ATLAS_SKIN OUT_DIR
"""
import os
import subprocess
import sys

from fresh_user import USER  # first: Blender reads the user folder when bpy is imported

import bpy
from skinned import (
    check_groups,
    check_matches_cli,
    cli_weights,
    deforming_names,
    import_character,
    run_operator,
    strip_weights,
)

LEGACY_ZIP, ATLAS_SKIN, OUT = sys.argv[1:4]


def main():
    os.makedirs(OUT, exist_ok=True)
    assert bpy.ops.preferences.addon_install(filepath=LEGACY_ZIP) == {"FINISHED"}
    assert bpy.ops.preferences.addon_enable(module="atlas_skin_blender") == {"FINISHED"}
    subprocess.run([ATLAS_SKIN, "demo", "-o", OUT], check=True, capture_output=True)
    demo = os.path.join(OUT, "demo.glb")
    cli_names, cli = cli_weights(ATLAS_SKIN, demo, os.path.join(OUT, "legacy-cli.glb"))
    armature, meshes = import_character(demo)
    strip_weights(meshes)
    assert run_operator(armature, meshes, use_tails=False) == {"FINISHED"}
    import atlas_skin

    where = os.path.realpath(atlas_skin.__file__)
    vendor = os.path.realpath(os.path.join(USER, "scripts/addons/atlas_skin_blender/_vendor"))
    assert where.startswith(vendor), f"atlas_skin imported from {where}, not from {vendor}"
    names = deforming_names(armature)
    check_groups("demo (legacy add-on)", meshes, names)
    worst = check_matches_cli("demo (legacy add-on)", meshes, names, cli_names, cli)
    print(f"legacy add-on: installed, atlas_skin from its _vendor, demo as atlas-skin skin "
          f"(largest difference {worst:.1e}): ok")


main()
