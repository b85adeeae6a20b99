"""The operator's text options, read against the rig's bone names."""
import math


class OptionError(Exception):
    """An option that names no deforming bone or is not a number (the message says which)."""


def bone_list(text, bone_names, option):
    """`"Head, Neck"` -> ["Head", "Neck"]: comma-separated names of deforming bones."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    for name in names:
        check_bone(name, bone_names, option)
    return names


def bone_factors(text, bone_names, option):
    """`"Head=0.2, Spine=1"` -> {"Head": 0.2, "Spine": 1.0}: per-bone numbers, as the
    command line's repeated `--overlap-joint NAME=F`."""
    factors = {}
    for item in (part.strip() for part in text.split(",")):
        if not item:
            continue
        name, equals, value = item.rpartition("=")
        name = name.strip()
        if not equals or not name:
            raise OptionError(f"{option}: '{item}' is not BONE=NUMBER")
        try:
            factor = float(value)
        except ValueError:
            raise OptionError(f"{option}: '{value.strip()}' (for {name}) is not a number") from None
        if not (math.isfinite(factor) and factor > 0.0):
            raise OptionError(f"{option}: {name}={value.strip()} must be a positive number")
        check_bone(name, bone_names, option)
        factors[name] = factor
    return factors


def check_bone(name, bone_names, option):
    if name not in bone_names:
        raise OptionError(f"{option}: '{name}' is not a deforming bone of the armature")
