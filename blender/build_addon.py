"""Packs the Blender add-on `atlas_skin_blender` with `atlas_skin` wheels.

Writes into OUT_DIR:
- `atlas_skin_blender-VERSION-PLATFORM.zip`, one per platform of the wheels: the extension
  (Blender 4.2 and later; Preferences > Get Extensions > Install from Disk), the wheels
  listed in its manifest, packed and then checked by Blender's own `extension build` and
  `extension validate` (blender_ext.py, from the `bpy` package this Python has, or given
  with --blender-ext);
- `atlas_skin_blender-VERSION-PLATFORM-legacy.zip`, one per wheel: the same add-on (its
  Python files, no manifest) for Preferences > Add-ons > Install legacy add-on, the wheel
  unpacked in its `_vendor/`.

Usage: python build_addon.py [--blender-ext PATH] OUT_DIR WHEEL...
"""
import argparse
import importlib.util
import pathlib
import shutil
import subprocess
import sys
import tomllib
import zipfile

SOURCE = pathlib.Path(__file__).resolve().parent / "atlas_skin_blender"
ADDON_FILES = sorted(SOURCE.glob("*.py")) + [SOURCE / "blender_manifest.toml"]


def bundled_blender_ext():
    """blender_ext.py of the `bpy` package installed in this Python (not imported)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or spec.origin is None:
        sys.exit("error: no `bpy` package in this Python; give --blender-ext PATH")
    package = pathlib.Path(spec.origin).parent
    found = sorted(package.glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not found:
        sys.exit(f"error: no blender_ext.py under {package}")
    return found[-1]


def load_module(path):
    spec = importlib.util.spec_from_file_location("blender_ext", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def wheel_platforms(blender_ext, wheel):
    """Blender's platform names for a wheel (`...-manylinux_2_34_x86_64.whl` -> linux-x64)."""
    return blender_ext.blender_platforms_from_wheel_platform(wheel.stem.split("-")[-1])


def build_extension(blender_ext_path, blender_ext, out, wheels):
    stage = out / "stage"
    shutil.rmtree(stage, ignore_errors=True)
    (stage / "wheels").mkdir(parents=True)
    for path in ADDON_FILES:
        shutil.copy(path, stage)
    for wheel in wheels:
        shutil.copy(wheel, stage / "wheels")
    platforms = sorted({p for wheel in wheels for p in wheel_platforms(blender_ext, wheel)})
    with open(stage / "blender_manifest.toml", "a") as manifest:
        manifest.write(f"\nwheels = {[f'./wheels/{w.name}' for w in wheels]}\n")
        manifest.write(f"platforms = {platforms}\n")
    run(blender_ext_path, "build", "--source-dir", stage, "--output-dir", out, "--split-platforms")
    shutil.rmtree(stage)
    version = manifest_version()
    built = [out / f"atlas_skin_blender-{version}-{p.replace('-', '_')}.zip" for p in platforms]
    for path in built:
        run(blender_ext_path, "validate", path)
    return built


def build_legacy(blender_ext, out, wheel):
    version = manifest_version()
    platforms = "_".join(p.replace("-", "_") for p in wheel_platforms(blender_ext, wheel))
    path = out / f"atlas_skin_blender-{version}-{platforms}-legacy.zip"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for source in ADDON_FILES:
            if source.suffix != ".py":
                continue  # a manifest would make Blender take the folder for an extension
            archive.write(source, f"atlas_skin_blender/{source.name}")
        with zipfile.ZipFile(wheel) as packed:
            for item in packed.infolist():
                if not item.is_dir():
                    name = f"atlas_skin_blender/_vendor/{item.filename}"
                    archive.writestr(name, packed.read(item))
    return path


def manifest_version():
    with open(SOURCE / "blender_manifest.toml", "rb") as f:
        return tomllib.load(f)["version"]


def run(*command):
    subprocess.run([sys.executable, *map(str, command)], check=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blender-ext", type=pathlib.Path, help="Blender's blender_ext.py")
    parser.add_argument("out", type=pathlib.Path)
    parser.add_argument("wheels", type=pathlib.Path, nargs="+")
    args = parser.parse_args()
    blender_ext_path = args.blender_ext or bundled_blender_ext()
    blender_ext = load_module(blender_ext_path)
    args.out.mkdir(parents=True, exist_ok=True)
    for path in build_extension(blender_ext_path, blender_ext, args.out, args.wheels):
        print(f"wrote {path} (extension)")
    for wheel in args.wheels:
        print(f"wrote {build_legacy(blender_ext, args.out, wheel)} (legacy add-on)")


main()
