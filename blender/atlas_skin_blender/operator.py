"""Object > Parent > With Atlas-Skin Weights: the selected meshes, as one body, weighted
to the selected armature by atlas-skin."""
import time

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from .binding import bind_to_armature, write_groups
from .body import BodyError, read_body, rest_state
from .options import OptionError, bone_factors, bone_list
from .package import MissingPackage, atlas_skin
from .rig import RigError, deforming_rig

# The quality gate's conditions of `atlas_skin.compute_weights(fail_on=...)` that a mesh in
# Blender can meet (a Blender mesh has no file reader's warnings): the option's items.
FAIL_ON = (
    ("WARNINGS", "Any Warning", "Any warning of the method"),
    ("MESH", "Mesh", "A warning about the mesh: duplicate faces, pieces wound inside out, a "
     "surface joining the sides of cuts, loose vertices"),
    ("PLACEMENT", "Placement", "A warning about where the bones sit in the mesh: beside it or "
     "outside its surface, at one point, zero-length, no boundary at all"),
    ("SKELETON", "Skeleton", "A warning about what the method made of the bones: a hierarchy "
     "inferred, leaf extensions capped, bones named as helpers"),
    ("WEIGHTS", "Weights", "A warning about the weights: soft bones without weight"),
    ("FALLBACK", "Fallback", "A vertex weighted by a fallback (a loose vertex: its nearest bone)"),
    ("SOFT_JOINTS", "Soft Bones Without Weight",
     "A bone whose soft boundary found no cross-section and that carries no weight"),
    ("UNWEIGHTED_JOINTS", "Bones Without Weight",
     "A bone given a boundary that carries no weight"),
)


class Rejected(Exception):
    """The quality gate (the Fail On option) refused the weights (the message says why)."""


def polled(cls, context, find):
    """An operator's poll: Object Mode and a selection `find(context)` accepts (else the
    sentence it returns is shown as the reason)."""
    if context.mode != "OBJECT":
        cls.poll_message_set("works in Object Mode")
        return False
    found = find(context)
    if isinstance(found, str):
        cls.poll_message_set(found)
        return False
    return True


def max_influences_property():
    """The Max Influences option of the add-on's operators."""
    return IntProperty(
        name="Max Influences",
        description="Bones kept per vertex (the largest weights, renormalised)",
        default=4,
        min=1,
        max=32,
    )


def reported(operator, compute, errors):
    """Runs an operator's work, `compute()` → (summary line, warnings), and shows its
    outcome: an error of the types `errors` reported and the operator cancelled, else each
    warning and then the summary."""
    try:
        summary, warnings = compute()
    except errors as error:
        operator.report({"ERROR"}, str(error))
        return {"CANCELLED"}
    for warning in warnings:
        operator.report({"WARNING"}, warning)
    operator.report({"INFO"}, summary)
    return {"FINISHED"}


def selection(context):
    """(armature, meshes) of the selection, or a sentence saying what is missing."""
    selected = context.selected_objects
    armatures = [o for o in selected if o.type == "ARMATURE"]
    meshes = [o for o in selected if o.type == "MESH"]
    if len(armatures) != 1:
        return f"select one armature ({len(armatures)} selected) and the meshes to weight"
    if not meshes:
        return "select the meshes to weight together with the armature"
    return armatures[0], meshes


class OBJECT_OT_parent_atlas_skin(bpy.types.Operator):
    """Parent the selected meshes to the selected armature with weights computed by
    atlas-skin: one vertex group per deforming bone, an Armature modifier"""

    bl_idname = "object.parent_atlas_skin"
    bl_label = "With Atlas-Skin Weights"
    bl_options = {"REGISTER", "UNDO"}

    overlap: FloatProperty(
        name="Overlap",
        description="Half-width of the blend between neighbouring parts, as a multiple of "
        "each boundary's diameter (the paper's 0.5)",
        default=0.5,
        min=0.001,
        soft_max=2.0,
    )
    bone_overlap: StringProperty(
        name="Per-Bone Overlap",
        description="Overlap of single bones, as BONE=FACTOR, comma-separated: from "
        "quasi-rigid (small) to soft (large)",
    )
    max_influences: max_influences_property()
    blend: EnumProperty(
        name="Blend",
        description="How overlapping parts are blended",
        items=(
            ("POU", "Partition of Unity", "Normalised partition of unity: continuous everywhere"),
            ("PAPER", "Paper (Eq. 1)", "The blending of Lu et al. 2008, Eq. 1"),
        ),
        default="POU",
    )
    binding: EnumProperty(
        name="Binding",
        description="Blended weights, or one bone per vertex for a character bound rigidly",
        items=(
            ("SMOOTH", "Smooth", "Blended weights: a vertex may follow several bones"),
            (
                "RIGID",
                "Rigid",
                "One bone per vertex, weight 1: the same parts, each vertex moving with the "
                "deepest bone whose branch holds more than half of its blended weights",
            ),
        ),
        default="SMOOTH",
    )
    force: StringProperty(
        name="Force Boundaries",
        description="Bones that get a boundary where the rules would give none "
        "(comma-separated)",
    )
    forbid: StringProperty(
        name="Forbid Boundaries",
        description="Bones that get no boundary: their part moves with their parent's "
        "(comma-separated)",
    )
    fail_on: EnumProperty(
        name="Fail On",
        description="Refuse to weight, leaving the meshes unchanged, when the result has one of "
        "these (atlas-skin's quality gate, --fail-on)",
        items=FAIL_ON,
        options={"ENUM_FLAG"},
        default=set(),
    )
    use_tails: BoolProperty(
        name="Bone Tails",
        description="Leaf bones end at their tails; off, "
        "bones are their heads only, as in a glTF file, whose tails Blender's importer guesses",
        default=True,
    )

    @classmethod
    def poll(cls, context):
        return polled(cls, context, selection)

    def execute(self, context):
        armature, meshes = selection(context)
        manager = context.window_manager
        manager.progress_begin(0, 2 * len(meshes) + 1)
        steps = iter(range(1, 2 * len(meshes) + 2))
        try:
            return reported(
                self,
                lambda: self.parent_with_weights(
                    context, armature, meshes, lambda: manager.progress_update(next(steps))
                ),
                (MissingPackage, RigError, BodyError, OptionError, Rejected, ValueError),
            )
        finally:
            manager.progress_end()

    def parent_with_weights(self, context, armature, meshes, progress):
        """Computes and writes the weights; returns the summary line and the warnings.
        Everything that can fail happens before the first change to the scene."""
        package = atlas_skin()
        rig = deforming_rig(armature)
        options = self.method_options(rig.names)
        with rest_state(armature, meshes):
            body = read_body(context.evaluated_depsgraph_get(), armature, meshes, progress)
            start = time.perf_counter()
            try:
                indices, weights, report = package.compute_weights(
                    body.positions,
                    body.triangles,
                    rig.heads,
                    rig.parents,
                    tails=rig.tails if self.use_tails else None,
                    inverse_bind=rig.inverse_bind,
                    **options,
                )
            except package.QualityGateError as error:
                raise Rejected("Fail On: " + "; ".join(error.reasons)) from None
            seconds = time.perf_counter() - start
            progress()
            for obj, first, end in body.ranges:
                write_groups(obj, rig.names, indices[first:end], weights[first:end])
                bind_to_armature(obj, armature)
                progress()
        summary = (
            f"Atlas-Skin: {len(body.positions)} vertices of {len(meshes)} mesh(es) weighted "
            f"to {len(rig.names)} bones of '{armature.name}' in {seconds:.2f} s"
        )
        return summary, body.warnings + list(report.get("warnings", []))

    def method_options(self, bone_names):
        """The keyword options of `atlas_skin.compute_weights`."""
        return {
            "names": bone_names,
            "overlap": self.overlap,
            "overlap_joints": bone_factors(self.bone_overlap, bone_names, "Per-Bone Overlap"),
            "max_influences": self.max_influences,
            "blend": self.blend.lower(),
            "binding": self.binding.lower(),
            "force": bone_list(self.force, bone_names, "Force Boundaries"),
            "forbid": bone_list(self.forbid, bone_names, "Forbid Boundaries"),
            "fail_on": sorted(c.lower().replace("_", "-") for c in self.fail_on),
        }


def draw_parent_menu(self, _context):
    self.layout.operator(OBJECT_OT_parent_atlas_skin.bl_idname)
    self.layout.separator()


def draw_context_menu(self, context):
    if context.active_object is not None and context.active_object.type == "ARMATURE":
        self.layout.separator()
        self.layout.operator(
            OBJECT_OT_parent_atlas_skin.bl_idname, text="Parent with Atlas-Skin Weights"
        )
