"""The Rigger panel in View3D > Sidebar > Rigger: method, its parameters, the output target, the actions and the
overlay toggles."""
import bpy

from ..api import method_registry
from .operators import RIGGER_OT_clear_overlays, RIGGER_OT_rig, RIGGER_OT_rig_skin, RIGGER_OT_skin
from .problem import SidebarPanel
from .properties import NO_METHOD, SETTINGS_ATTRIBUTE


class RIGGER_PT_main(SidebarPanel, bpy.types.Panel):
    bl_idname = "RIGGER_PT_main"

    def draw(self, context):
        layout = self.layout
        settings = getattr(context.scene, SETTINGS_ATTRIBUTE)
        layout.prop(settings, "method")
        registry = method_registry()
        if settings.method != NO_METHOD and settings.method in registry.methods:
            draw_method(layout.box(), registry.methods[settings.method], getattr(settings.methods, settings.method))
        if registry.failures:
            draw_failures(layout.box(), registry.failures)

        layout.prop(settings, "target")
        column = layout.column(align=True)
        column.operator(RIGGER_OT_rig.bl_idname, icon='ARMATURE_DATA')
        column.operator(RIGGER_OT_skin.bl_idname, icon='MOD_ARMATURE')
        column.operator(RIGGER_OT_rig_skin.bl_idname, icon='OUTLINER_OB_ARMATURE')

        box = layout.box()
        box.label(text="Overlays", icon='OVERLAY')
        if settings.overlays:
            grid = box.grid_flow(columns=2, align=True)
            for item in settings.overlays:
                grid.prop(item, "shown", text=item.label, toggle=True)
        else:
            box.label(text="Rig a mesh to see its stages")
        box.operator(RIGGER_OT_clear_overlays.bl_idname, icon='TRASH')


def draw_method(layout, method, props):
    """The generated widgets of ``method``'s parameters, then the method's own ``draw`` hook; a hook that raises is
    reported in the panel instead of breaking it."""
    if method.description:
        layout.label(text=method.description)
    for param in method.params:
        layout.prop(props, param.name)
    try:
        method().draw(layout, props)
    except Exception as error:
        layout.label(text=f"{method.name}.draw failed: {type(error).__name__}: {error}", icon='ERROR')


def draw_failures(layout, failures):
    layout.label(text="Methods that failed to load:", icon='ERROR')
    for where, error in failures.items():
        layout.label(text=f"{where}: {error}")


CLASSES = (RIGGER_PT_main,)
