"""Registering the Blender UI: discover the methods, generate their properties, register operators and panel."""
import bpy

from ..api import method_registry
from . import operators, panel, properties

_registered = []


def register():
    """Register everything for the methods found now (so a method file added since the last enable appears).

    A method that fails to load is printed to the console and listed in the panel; the others work. Registering
    again (a script calling ``rigger.register()`` while the add-on is enabled) replaces the earlier registration
    rather than failing half way. If registering fails part way, what was registered is unregistered again before
    the error propagates.
    """
    if _registered:
        unregister()
    registry = method_registry(refresh=True)
    for where, error in registry.failures.items():
        print(f"Rigger: skipped method {where}: {error}")
    property_classes = properties.make_classes(registry)
    try:
        for cls in (*property_classes, *operators.CLASSES, *panel.CLASSES):
            bpy.utils.register_class(cls)
            _registered.append(cls)
        properties.attach(property_classes[-1])
    except Exception:
        unregister()
        raise


def unregister():
    properties.detach()
    while _registered:
        cls = _registered.pop()
        if cls.is_registered:  # another copy of the add-on may have replaced a class of the same name
            bpy.utils.unregister_class(cls)
