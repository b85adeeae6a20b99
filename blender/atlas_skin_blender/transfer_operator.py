"""Object > Transfer Atlas-Skin Weights from Active: the selected meshes (clothes, hair,
props) take the weights of the active skinned mesh by atlas-skin's weight transfer
(closest point matching and weight inpainting, Abdrashitov et al. 2023), get its bones'
vertex groups, an Armature modifier and its armature as parent."""
import time

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty, IntProperty

from .binding import bind_to_armature, write_groups
from .body import BodyError, read_body, rest_state
from .operator import max_influences_property, polled, reported
from .package import MissingPackage, atlas_skin
from .rig import RigError, deforming_rig


def skinned_source(context):
    """(source, armature, targets) of the selection, or a sentence saying what is missing:
    the active mesh with an Armature modifier, and the other selected meshes."""
    source = context.active_object
    if source is None or source.type != "MESH":
        return "make the skinned mesh that gives its weights the active object"
    armature = next(
        (m.object for m in source.modifiers if m.type == "ARMATURE" and m.object is not None),
        None,
    )
    if armature is None:
        return f"the active mesh '{source.name}' has no Armature modifier: it is not skinned"
    targets = [o for o in context.selected_objects if o.type == "MESH" and o is not source]
    if not targets:
        return "select the meshes to weight together with the active skinned mesh"
    return source, armature, targets


def source_weights(obj, bone_names):
    """The vertex-group weights of `obj` on `bone_names` as (V, K) indices and weights."""
    index = {g.index: bone_names.index(g.name) for g in obj.vertex_groups if g.name in bone_names}
    rows = [
        [(index[g.group], g.weight) for g in v.groups if g.group in index and g.weight > 0.0]
        for v in obj.data.vertices
    ]
    k = max((len(r) for r in rows), default=0)
    if k == 0:
        raise BodyError(f"'{obj.name}' has no weights on the bones of its armature")
    indices = np.zeros((len(rows), k), dtype=np.int64)
    weights = np.zeros((len(rows), k), dtype=np.float64)
    for v, row in enumerate(rows):
        for i, (j, w) in enumerate(row):
            indices[v, i], weights[v, i] = j, w
    return indices, weights


class OBJECT_OT_transfer_atlas_skin(bpy.types.Operator):
    """Weight the selected meshes from the active skinned mesh: copy its weights where
    they lie on it, fill in the rest smoothly (atlas-skin's weight transfer)"""

    bl_idname = "object.transfer_atlas_skin"
    bl_label = "Transfer Atlas-Skin Weights from Active"
    bl_options = {"REGISTER", "UNDO"}

    distance: FloatProperty(
        name="Distance",
        description="Largest distance from the active mesh where weights are copied, as a "
        "fraction of its bounding-box diagonal",
        default=0.05,
        min=1e-6,
        soft_max=0.5,
    )
    angle: FloatProperty(
        name="Angle",
        description="Largest angle between normals where weights are copied, in degrees",
        default=30.0,
        min=0.0,
        max=90.0,
    )
    flipped_normals: BoolProperty(
        name="Flipped Normals",
        description="Also copy where the normals point opposite ways (a single-sided garment wound the other way)",
        default=False,
    )
    smooth_iterations: IntProperty(
        name="Smoothing",
        description="Rounds of smoothing near the filled-in vertices (0: none)",
        default=10,
        min=0,
        soft_max=100,
    )
    max_influences: max_influences_property()

    @classmethod
    def poll(cls, context):
        return polled(cls, context, skinned_source)

    def execute(self, context):
        source, armature, targets = skinned_source(context)
        return reported(
            self,
            lambda: self.transfer(context, source, armature, targets),
            (MissingPackage, RigError, BodyError, ValueError),
        )

    def transfer(self, context, source, armature, targets):
        """Computes and writes the weights; returns the summary line and the warnings.
        Everything that can fail happens before the first change to the scene."""
        package = atlas_skin()
        rig = deforming_rig(armature)
        src_indices, src_weights = source_weights(source, rig.names)
        with rest_state(armature, [source, *targets]):
            depsgraph = context.evaluated_depsgraph_get()
            body = read_body(depsgraph, armature, [source])
            clothes = read_body(depsgraph, armature, targets)
            start = time.perf_counter()
            indices, weights, info = package.transfer(
                body.positions,
                body.triangles,
                src_indices,
                src_weights,
                clothes.positions,
                clothes.triangles,
                joint_count=len(rig.names),
                max_influences=self.max_influences,
                distance=self.distance,
                angle_degrees=self.angle,
                flipped_normals=self.flipped_normals,
                smooth_iterations=self.smooth_iterations,
            )
            seconds = time.perf_counter() - start
            for obj, first, end in clothes.ranges:
                write_groups(obj, rig.names, indices[first:end], weights[first:end])
                bind_to_armature(obj, armature)
        counts = info["counts"]
        warnings = body.warnings + clothes.warnings
        nearest = [p for p in info["pieces"] if p["bound_to_nearest"]]
        if nearest:
            warnings.append(
                f"{len(nearest)} piece(s) matched nowhere on '{source.name}': each bound whole "
                "to where it comes nearest"
            )
        summary = (
            f"Atlas-Skin: {len(clothes.positions)} vertices of {len(targets)} mesh(es) weighted "
            f"from '{source.name}' ({counts['matched']} copied, {counts['inpainted']} filled "
            f"in) in {seconds:.2f} s"
        )
        return summary, warnings


def draw_transfer_menu(self, _context):
    self.layout.operator(OBJECT_OT_transfer_atlas_skin.bl_idname)
