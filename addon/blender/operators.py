"""The operators ``rigger.rig``, ``rigger.skin``, ``rigger.rig_skin``, ``rigger.clear_overlays`` and
``rigger.direction_from_view``.

They read their settings from ``scene.rigger``, act on the active object (a mesh, or the armature Rigger made for
one), report problems through ``self.report`` rather than tracebacks, and show progress on the window manager.
"""
import traceback

import bpy
from mathutils import Vector

from ..api import method_registry
from . import overlays
from .pipeline import character_meshes, rig_object, skin_meshes, skin_summary
from .properties import (ARMATURE_POINTER, NO_METHOD, SETTINGS_ATTRIBUTE, note_overlays, overlay_visibility,
                         param_values)


def rig_targets(context):
    """The meshes to rig together: the active mesh and the other selected meshes, or the meshes of the active
    Rigger armature (rigging again); else ([], why not)."""
    obj = context.active_object
    if obj is None:
        selected = any(other.type == 'MESH' for other in context.selected_objects)
        return [], "Make one of the selected meshes active (click it)" if selected else "Select a mesh object"
    if obj.type == 'MESH':
        return [obj, *(other for other in context.selected_objects if other.type == 'MESH' and other != obj)], None
    if obj.type == 'ARMATURE':
        meshes = [mesh for mesh in context.scene.objects if getattr(mesh, ARMATURE_POINTER, None) == obj]
        if meshes:
            return meshes, None
    return [], f"{obj.name} is not a mesh; select a mesh object"


def skin_targets(context):
    """(meshes, armature) to skin: the rig targets and the first one's Rigger armature (or a selected armature);
    else ([], None, why not).

    A Rigger armature the user deleted is no armature: deleting it takes it out of the scene, but the mesh's pointer
    keeps it alive in the file, where skinning to it would bind the mesh to something nobody can see.
    """
    meshes, why = rig_targets(context)
    if not meshes:
        return [], None, why
    armature = getattr(meshes[0], ARMATURE_POINTER, None)
    deleted = armature is not None and context.scene.objects.get(armature.name) != armature
    if armature is None or deleted:
        armature = next((obj for obj in context.selected_objects if obj.type == 'ARMATURE'), None)
    if armature is None and deleted:
        return [], None, (f"{meshes[0].name}'s armature was deleted, but still holds the mesh: Rig makes a new one "
                          f"and lets go of the old")
    if armature is None:
        return [], None, f"{meshes[0].name} has no armature yet: rig it first (or select an armature with it)"
    return meshes, armature, None


class _RiggerOperator:
    """Shared behaviour: Object Mode only, errors become reports, progress on the window manager."""

    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        why = "Switch to Object Mode first" if context.mode != 'OBJECT' else cls.why_not(context)
        if why:
            cls.poll_message_set(why)
        return not why

    def execute(self, context):
        window_manager = context.window_manager
        window_manager.progress_begin(0, 100)
        try:
            return self.run(context, lambda fraction: window_manager.progress_update(int(100 * fraction)))
        except ValueError as error:  # bad mesh, method or parameters: the user can fix these
            self.report({'ERROR'}, str(error))
        except Exception as error:  # a bug: say so in one line; the console keeps the details for a bug report
            traceback.print_exc()
            self.report({'ERROR'}, f"Rigger failed: {type(error).__name__}: {error} (details in the console)")
        finally:
            window_manager.progress_end()
        return {'CANCELLED'}

    def rig(self, context, progress):
        settings, method = chosen_method(context)
        params = param_values(method, getattr(settings.methods, method.name))
        meshes, left_out = character_meshes(rig_targets(context)[0])
        result = rig_object(meshes[0], method.name, params, target=settings.target, parts=meshes[1:],
                            show_overlays=overlay_visibility(settings), progress=progress)
        note_overlays(settings, result.skeleton.stages, result.overlays)
        seconds = sum(result.timings.values())
        names = ", ".join(mesh.name for mesh in meshes)
        replaced = "" if not result.replaced else " (replaced the previous rig)" if result.motion is None else \
            f" (replaced the previous rig; {result.motion})"
        plan = result.skeleton.body_plan
        left = [f"left out {mesh.name} ({why})" for mesh, why in left_out]
        notes = [*left, *result.warnings, *([] if plan is None else [plan.warning or plan.summary()])]
        warned = left or result.warnings or plan is not None and plan.warning
        self.report({'WARNING'} if warned else {'INFO'},
                    f"Rigged {names} with {method.label or method.name} as {result.target.label}: "
                    f"{len(result.bones)} bones in {seconds:.2f} s{replaced}" + "".join(f"; {n}" for n in notes))
        return meshes, result.armature

    def skin(self, meshes, armature, progress):
        outcomes, warnings = skin_meshes(meshes, armature, progress)
        warned = warnings or any(outcome.level == "WARNING" for outcome in outcomes.values())
        self.report({'WARNING'} if warned else {'INFO'}, "; ".join([*warnings, skin_summary(outcomes)]))


class RIGGER_OT_rig(_RiggerOperator, bpy.types.Operator):
    """Build an armature for the active mesh with the chosen method (the armature stays editable before skinning)"""

    bl_idname = "rigger.rig"
    bl_label = "Rig"

    @staticmethod
    def why_not(context):
        """Why the operator cannot run here (a message for the disabled button), or None."""
        if getattr(context.scene, SETTINGS_ATTRIBUTE).method == NO_METHOD:
            return "No rigging method could be loaded (see the Rigger panel)"
        return rig_targets(context)[1]

    def run(self, context, progress):
        self.rig(context, progress)
        return {'FINISHED'}


class RIGGER_OT_skin(_RiggerOperator, bpy.types.Operator):
    """Bind the active mesh to its armature; every vertex gets weights (bone heat, repaired where it fails)"""

    bl_idname = "rigger.skin"
    bl_label = "Skin"

    @staticmethod
    def why_not(context):
        return skin_targets(context)[2]

    def run(self, context, progress):
        meshes, armature, _ = skin_targets(context)
        self.skin(meshes, armature, progress)
        return {'FINISHED'}


class RIGGER_OT_rig_skin(_RiggerOperator, bpy.types.Operator):
    """Rig the active mesh, then skin it to the new armature"""

    bl_idname = "rigger.rig_skin"
    bl_label = "Rig & Skin"

    why_not = staticmethod(RIGGER_OT_rig.why_not)

    def run(self, context, progress):
        meshes, armature = self.rig(context, lambda fraction: progress(0.5 * fraction))
        self.skin(meshes, armature, lambda fraction: progress(0.5 + 0.5 * fraction))
        return {'FINISHED'}


class RIGGER_OT_clear_overlays(bpy.types.Operator):
    """Remove every Rigger overlay object with its node groups and materials"""

    bl_idname = "rigger.clear_overlays"
    bl_label = "Clear Overlays"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        if overlays.COLLECTION_NAME not in bpy.data.collections:
            cls.poll_message_set("There are no overlays to clear")
            return False
        return True

    def execute(self, context):
        overlays.clear_overlays()
        getattr(context.scene, SETTINGS_ATTRIBUTE).overlays.clear()
        self.report({'INFO'}, "Cleared the Rigger overlays")
        return {'FINISHED'}


class RIGGER_OT_direction_from_view(bpy.types.Operator):
    """Set a direction parameter of the chosen method to the direction the 3D view looks along"""

    bl_idname = "rigger.direction_from_view"
    bl_label = "From View"
    bl_options = {'REGISTER', 'UNDO'}

    param: bpy.props.StringProperty(name="Parameter", description="The method's vector parameter to set",
                                    options={'HIDDEN', 'SKIP_SAVE'})

    @classmethod
    def poll(cls, context):
        if view_of(context) is None:
            cls.poll_message_set("Only from a 3D view")
            return False
        return True

    def execute(self, context):
        try:
            settings, method = chosen_method(context)
        except ValueError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        if not any(p.name == self.param and p.type == "vector" for p in method.params):
            self.report({'ERROR'}, f"{settings.method} has no direction parameter {self.param!r}")
            return {'CANCELLED'}
        setattr(getattr(settings.methods, method.name), self.param, looking_along(view_of(context).view_rotation))
        return {'FINISHED'}


def chosen_method(context):
    """(the scene's Rigger settings, the method class they choose); a ValueError when no such method is loaded."""
    settings = getattr(context.scene, SETTINGS_ATTRIBUTE)
    return settings, method_registry().lookup(settings.method)


def view_of(context):
    """The RegionView3D of the 3D view ``context`` belongs to (the quadrant under the mouse in quad view; from its
    sidebar, the main one), else None."""
    space = context.space_data
    if space is None or space.type != 'VIEW_3D':
        return None
    return getattr(context, "region_data", None) or space.region_3d


def looking_along(view_rotation):
    """The unit direction a 3D view with this rotation (a quaternion) looks along: its camera's -Z."""
    return tuple(view_rotation @ Vector((0.0, 0.0, -1.0)))


CLASSES = (RIGGER_OT_rig, RIGGER_OT_skin, RIGGER_OT_rig_skin, RIGGER_OT_clear_overlays, RIGGER_OT_direction_from_view)
