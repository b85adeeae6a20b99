"""Parent with Atlas-Skin weights: a Blender add-on (an extension of Blender 4.2 and
later, also installable the legacy way) that weights meshes to an armature with atlas-skin
(automatic character skinning by atlas decomposition; Lu et al. 2008).

Object > Parent > With Atlas-Skin Weights, or the object context menu with an armature
active: the selected meshes, as one body, get one vertex group per deforming bone of the
selected armature, an Armature modifier and the armature as parent.

Object > Transfer Atlas-Skin Weights from Active: the selected meshes (clothes, hair,
props) take the weights of the active skinned mesh (weight transfer with inpainting).
"""

# Read by Blender only for a legacy install; an extension is described by
# blender_manifest.toml.
bl_info = {
    "name": "Atlas-Skin Weights",
    "author": "atlas-skin developers",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "View3D > Object > Parent > With Atlas-Skin Weights",
    "description": "Parent meshes to an armature with Atlas-Skin automatic weights",
    "category": "Rigging",
}

import bpy

from .operator import OBJECT_OT_parent_atlas_skin, draw_context_menu, draw_parent_menu
from .transfer_operator import OBJECT_OT_transfer_atlas_skin, draw_transfer_menu


def register():
    bpy.utils.register_class(OBJECT_OT_parent_atlas_skin)
    bpy.types.VIEW3D_MT_object_parent.prepend(draw_parent_menu)
    bpy.types.VIEW3D_MT_object_context_menu.append(draw_context_menu)
    bpy.utils.register_class(OBJECT_OT_transfer_atlas_skin)
    bpy.types.VIEW3D_MT_object.append(draw_transfer_menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(draw_transfer_menu)
    bpy.utils.unregister_class(OBJECT_OT_transfer_atlas_skin)
    bpy.types.VIEW3D_MT_object_context_menu.remove(draw_context_menu)
    bpy.types.VIEW3D_MT_object_parent.remove(draw_parent_menu)
    bpy.utils.unregister_class(OBJECT_OT_parent_atlas_skin)
