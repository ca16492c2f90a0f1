"""Blender properties generated from the methods' parameter declarations, and the add-on's settings on
``scene.rigger``.

Every discovered method gets a PropertyGroup with one property per :class:`~rigger.core.params.Param`, reachable as
``scene.rigger.methods.<method name>.<param name>``; ``scene.rigger.method`` picks the method,
``scene.rigger.target`` the output target (``core.targets``), and ``scene.rigger.overlays`` holds a toggle per
stage the rigs drew (``scene.rigger.overlays["cdt"].shown``), added as overlays of new stages are built. The
classes are built at register time from the registry discovered then, so a method added to ``methods/`` appears
after the add-on is enabled again.
"""
import bpy
import numpy as np

from ..core.targets import TARGETS
from . import overlays

SETTINGS_ATTRIBUTE = "rigger"  # scene.rigger
ARMATURE_POINTER = "rigger_armature"  # Object.rigger_armature: the armature Rigger made for this mesh
NO_METHOD = "NONE"  # the dropdown's only item when every method failed to load


def method_items(registry):
    """EnumProperty items for the method dropdown, in the registry's sorted order."""
    return [(name, method.label or name, method.description) for name, method in registry.methods.items()]


def param_values(method, group):
    """The parameter values held by ``method``'s generated ``group``, as plain Python values for ``rig_mesh``.

    Blender stores floats in single precision; each is returned as the shortest decimal that rounds to the stored
    value (0.01, not 0.009999999776), so a bound typed in the UI never reads as just outside the declared range.
    """
    values = {}
    for param in method.params:
        value = getattr(group, param.name)
        if param.type == "float":
            value = _shortest(value)
        elif param.type == "vector":
            value = tuple(_shortest(component) for component in value)
        values[param.name] = value
    return values


def _shortest(value):
    return float(str(np.float32(value)))


def _property(param):
    """The bpy property declaring ``param``: same name, label, description, default and bounds."""
    common = {"name": param.label, "description": param.description}
    bounds = {key: value for key, value in (("min", param.min), ("max", param.max)) if value is not None}
    if param.type == "float":
        return bpy.props.FloatProperty(default=param.default, precision=4, **bounds, **common)
    if param.type == "int":
        return bpy.props.IntProperty(default=param.default, **bounds, **common)
    if param.type == "bool":
        return bpy.props.BoolProperty(default=param.default, **common)
    if param.type == "enum":
        items = [(item, item.replace("_", " ").title(), "") for item in param.items]
        return bpy.props.EnumProperty(items=items, default=param.default, **common)
    return bpy.props.FloatVectorProperty(size=3, default=param.default, **bounds, **common)


def _show_overlay(item, context):
    overlays.set_overlay_visible(item.name, item.shown)


class RIGGER_PG_overlay(bpy.types.PropertyGroup):
    """One overlay toggle: the stage it shows (``name``), its label, and whether it is shown"""

    label: bpy.props.StringProperty(name="Label")
    shown: bpy.props.BoolProperty(name="Shown", description="Show this stage's overlay", default=True,
                                  update=_show_overlay)


def make_classes(registry):
    """The PropertyGroup classes for ``registry``, in registration order (method groups first, settings last)."""
    method_groups = {}
    for name, method in registry.methods.items():
        annotations = {param.name: _property(param) for param in method.params}
        method_groups[name] = type(f"RIGGER_PG_method_{name}", (bpy.types.PropertyGroup,),
                                   {"__annotations__": annotations, "__doc__": method.description})
    methods_group = type("RIGGER_PG_methods", (bpy.types.PropertyGroup,), {
        "__annotations__": {name: bpy.props.PointerProperty(type=group) for name, group in method_groups.items()},
        "__doc__": "Parameters of every rigging method",
    })
    items = method_items(registry) or [(NO_METHOD, "No methods", "No rigging method could be loaded")]
    settings_annotations = {
        "method": bpy.props.EnumProperty(name="Method", description="Rigging method", items=items),
        "methods": bpy.props.PointerProperty(type=methods_group),
        "target": bpy.props.EnumProperty(name="Target", description="What the armature becomes (a body plan that "
                                         "cannot fill the target falls back, with a warning)",
                                         items=[(name, target.label, target.description)
                                                for name, target in TARGETS.items()]),
        "overlays": bpy.props.CollectionProperty(type=RIGGER_PG_overlay, name="Overlays"),
    }
    settings = type("RIGGER_PG_settings", (bpy.types.PropertyGroup,), {
        "__annotations__": settings_annotations, "__doc__": "Rigger settings of a scene"})
    return [*method_groups.values(), methods_group, RIGGER_PG_overlay, settings]


def attach(settings_class):
    """Add ``scene.rigger`` and ``Object.rigger_armature`` (after the classes are registered)."""
    setattr(bpy.types.Scene, SETTINGS_ATTRIBUTE, bpy.props.PointerProperty(type=settings_class))
    setattr(bpy.types.Object, ARMATURE_POINTER, bpy.props.PointerProperty(
        type=bpy.types.Object, name="Rigger Armature", description="The armature Rigger made for this mesh",
        poll=lambda _, obj: obj.type == 'ARMATURE'))


def detach():
    for owner, attribute in ((bpy.types.Scene, SETTINGS_ATTRIBUTE), (bpy.types.Object, ARMATURE_POINTER)):
        if hasattr(owner, attribute):
            delattr(owner, attribute)


def overlay_visibility(settings):
    """{stage name: shown?} from the scene settings' overlay toggles."""
    return {item.name: item.shown for item in settings.overlays}


def note_overlays(settings, stages, drawn):
    """Add a toggle to the scene settings for each stage name in ``drawn`` that has none yet, shown as the overlay
    was built (existing toggles keep their state); each is labelled after its stage (``stages[name]``), a toggle a
    script added without a label too."""
    for name, obj in drawn.items():
        item = settings.overlays.get(name)
        if item is None:
            item = settings.overlays.add()
            item.name = name
            item["shown"] = not obj.hide_viewport  # set without the update: the overlay is already so
        item.label = item.label or stages[name].label or name
