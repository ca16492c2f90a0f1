"""The panel Rigger registers instead of its real UI when it cannot run (see ``rigger.compat.compiled_problem``).

It sits where the real panel would (View3D > Sidebar > Rigger) and says what is wrong and which zip to install, so
enabling a mismatched zip shows an explanation rather than a traceback.
"""
import sys
import textwrap

import bpy

CHARACTER_WIDTH = 7  # pixels per character of the default UI font at scale 1, to wrap the message to the sidebar


class SidebarPanel:
    """Where Rigger's panel sits (View3D > Sidebar > Rigger): the real one and this stand-in alike."""

    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Rigger"
    bl_label = "Rigger"


class RIGGER_PT_problem(SidebarPanel, bpy.types.Panel):
    """Rigger cannot run here: the reason and the fix."""

    message = ""

    def draw(self, context):
        column = self.layout.column(align=True)
        column.label(text="Rigger cannot run", icon='ERROR')
        scale = context.preferences.system.ui_scale or 1.0
        width = max(20, int(context.region.width / (CHARACTER_WIDTH * scale)))
        for line in textwrap.wrap(self.message, width):
            column.label(text=line)


def register(message):
    """Show ``message`` in the sidebar (and once on the console) in place of Rigger's UI."""
    RIGGER_PT_problem.message = message
    if not RIGGER_PT_problem.is_registered:  # registering again (the add-on enabled twice) just updates the text
        bpy.utils.register_class(RIGGER_PT_problem)
    print(f"Rigger: {message}", file=sys.stderr)


def unregister():
    """Remove the panel; True if it was registered (so the real UI was not), False otherwise."""
    if not RIGGER_PT_problem.is_registered:
        return False
    bpy.utils.unregister_class(RIGGER_PT_problem)
    return True
