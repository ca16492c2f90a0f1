"""Stage overlays: every intermediate result of a rigging method drawn in the viewport, so each step can be inspected.

Each stage of a skeleton (``rigger.core.stages``) says how it is drawn: world-space lines, points, classed triangles
or labels. This module draws those primitives, whatever the stage type, so a method's new stage types get their
overlays without a change here. Labels are points drawn as spheres, each with a text object beside it (a child of
the overlay object, standing upright to face the front view), since geometry nodes cannot give each point its own
string. A drawing's raw data is stored as a plain mesh (vertices and edges; classed
triangles also keep their faces) and a geometry-node modifier makes it visible: edges become tubes (Mesh to Curve,
Curve to Mesh with a circle profile) and points small spheres. Curve to Mesh drops the mesh's colour attributes, so
colour comes from materials, one per stage or triangle class, with a viewport ``diffuse_color`` for Workbench and a
matching Principled colour for the other engines. Sockets are found by name: node layouts differ between Blender 4.2
and 5.0.

Stages that are not drawn (a view's frame, a mirror plane) are skipped silently. A stage that is not a ``Stage``, or
whose drawing fails, is skipped with a ``RuntimeWarning`` naming it: a method's odd output must never block rigging.
"""
import math
import numbers
import warnings
from collections.abc import Mapping

import bpy
import numpy as np

from ..core.stages import ClassedFaces, Labels, Lines, Points, Stage

COLLECTION_NAME = "Rigger Overlays"
LINE_SCALE = 0.004  # default line radius, as a fraction of the largest extent of the drawn data
JOINT_SCALE = 2.5  # point sphere radius, in line radii
FACE_EDGE_SCALE = 0.5  # classed triangles' edge radius, in line radii: their edges are dense and must not hide faces
TUBE_SIDES = 8  # vertices around a tube
SPHERE_SUBDIVISIONS = 2  # ico sphere level of a point: 42 vertices
FACE_ALPHA = 0.25  # classed faces are see-through (Workbench draws material alpha as transparency)
LABEL_SCALE = 5.0  # label text height, in line radii
LABEL_POINT_SCALE = 1.5  # label sphere radius, in line radii: smaller than a joint's

TUBES_GROUP = "Rigger Tubes"
CLASS_TUBES_GROUP = "Rigger Class Tubes"  # + the class names it draws
SPHERES_GROUP = "Rigger Spheres"
MODIFIER_NAME = "Rigger Overlay"
KIND_KEY = "rigger_overlay"  # custom properties marking an overlay object: its stage name and its owner
OWNER_KEY = "rigger_overlay_owner"
MADE_KEY = "rigger_overlay_data"  # custom property marking the materials and node groups made here


def build_overlays(stages, owner, *, scale=None, visible=None):
    """Helper objects drawing ``stages`` (a skeleton's stages: name to ``Stage``) for rig ``owner``; returns them
    by stage name.

    Objects are named "Rigger <stage>: <owner>" in the "Rigger Overlays" collection and replace any earlier overlays
    of the same owner. ``scale`` is the line radius (None: ``LINE_SCALE`` times the largest extent of the data);
    ``visible`` maps stage names to whether they start shown (a missing name: its stage type's ``shown``).
    """
    if not isinstance(stages, Mapping):
        raise ValueError(f"stages must be a dict of stage name to stage, got {type(stages).__name__}")
    if not isinstance(owner, str) or not owner:
        raise ValueError(f"owner must be a non-empty string, got {owner!r}")
    visible = {} if visible is None else dict(visible)
    if scale is not None and not (isinstance(scale, numbers.Real) and not isinstance(scale, bool)
                                  and math.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a positive finite line radius, got {scale!r}")

    drawings = _drawings(stages)
    remove_overlays(owner)
    if not drawings:
        return {}
    radius = float(scale) if scale is not None else _line_radius([drawing for _, drawing in drawings.values()])
    collection = _collection()
    objects = {}
    for name, (stage, drawing) in drawings.items():
        obj = _overlay_object(name, owner, stage, drawing, radius, collection)
        _show(obj, bool(visible.get(name, stage.shown)))
        objects[name] = obj
    return objects


def set_overlay_visible(name, visible):
    """Show or hide every overlay object of stage ``name`` (all owners), in viewports and in the current view layer;
    returns how many there were."""
    objects = [obj for obj in bpy.data.objects if obj.get(KIND_KEY) == name]
    for obj in objects:
        _show(obj, bool(visible))
    return len(objects)


def remove_overlays(owner):
    """Remove the overlay objects of rig ``owner`` (the name ``build_overlays`` got)."""
    _remove_objects(lambda obj: obj.get(OWNER_KEY) == owner)


def clear_overlays():
    """Remove every overlay object and its mesh, the collection, and the node groups and materials made here."""
    _remove_objects(lambda obj: True)
    collection = bpy.data.collections.get(COLLECTION_NAME)
    if collection is not None:
        bpy.data.collections.remove(collection)
    for group in [group for group in bpy.data.node_groups if MADE_KEY in group]:
        bpy.data.node_groups.remove(group)
    for material in [material for material in bpy.data.materials if MADE_KEY in material]:
        bpy.data.materials.remove(material)


def _drawings(stages):
    """(stage, drawing) by stage name, in the stages' order; stages without a drawing are left out, and those that
    are not stages or fail to draw with a warning."""
    drawings = {}
    for name, stage in stages.items():
        if not isinstance(stage, Stage):
            warnings.warn(f"Rigger overlay {name!r} skipped: a {type(stage).__name__}, not a rigger.core.stages.Stage",
                          RuntimeWarning, stacklevel=3)
            continue
        try:
            drawing = stage.drawing()
        except Exception as error:  # a method's own stage type must never block rigging
            warnings.warn(f"Rigger overlay {name!r} skipped: drawing its {type(stage).__name__} failed: "
                          f"{type(error).__name__}: {error}", RuntimeWarning, stacklevel=3)
            continue
        if drawing is not None and not isinstance(drawing, (Lines, Points, ClassedFaces, Labels)):
            warnings.warn(f"Rigger overlay {name!r} skipped: its drawing is a {type(drawing).__name__}, not Lines, "
                          f"Points, ClassedFaces or Labels", RuntimeWarning, stacklevel=3)
        elif drawing is not None:
            drawings[name] = stage, drawing
    return drawings


def _line_radius(drawings):
    """``LINE_SCALE`` times the largest extent of all drawn points (as if a metre across when they all coincide)."""
    points = np.concatenate([drawing.points for drawing in drawings])
    extent = float(np.max(points.max(axis=0) - points.min(axis=0)))
    return LINE_SCALE * (extent if extent > 0 else 1.0)


# Filling an overlay's mesh and choosing the node group, with its inputs, that draws each primitive.

def _fill(mesh, drawing):
    if isinstance(drawing, Lines):
        mesh.from_pydata(drawing.points.tolist(), drawing.edges.tolist(), [])
    elif isinstance(drawing, (Points, Labels)):
        mesh.from_pydata(drawing.points.tolist(), [], [])
    else:
        _fill_classed(mesh, drawing)


def _modifier_inputs(name, stage, drawing, radius):
    if isinstance(drawing, Lines):
        return _tubes_group(), {"Radius": radius, "Material": _material(f"Rigger {name}", stage.colour)}
    if isinstance(drawing, (Points, Labels)):
        scale = LABEL_POINT_SCALE if isinstance(drawing, Labels) else JOINT_SCALE
        return _spheres_group(), {"Radius": scale * radius, "Material": _material(f"Rigger {name}", stage.colour)}
    labels = [label for _, label, _ in drawing.palette]
    inputs = {label.title(): _material(f"Rigger {label}", colour) for _, label, colour in drawing.palette}
    return _class_tubes_group(labels), {"Radius": FACE_EDGE_SCALE * radius, **inputs}


def _fill_classed(mesh, drawing):
    """See-through faces in their class's colour, and every edge marked by one boolean edge attribute
    "rigger_<class>" for the class that draws it: of the triangles along it, the one latest in the palette."""
    mesh.from_pydata(drawing.points.tolist(), [], drawing.triangles.tolist())
    codes = [code for code, _, _ in drawing.palette]
    for _, label, colour in drawing.palette:
        mesh.materials.append(_material(f"Rigger {label} faces", colour, FACE_ALPHA))
    slot = np.zeros(max(codes) + 1, dtype=np.int32)
    slot[codes] = np.arange(len(codes))
    mesh.polygons.foreach_set("material_index", slot[drawing.classes])
    edges = np.empty(2 * len(mesh.edges), dtype=np.int32)
    mesh.edges.foreach_get("vertices", edges)
    owners = _edge_owners(drawing, edges.reshape(-1, 2))
    for code, label, _ in drawing.palette:
        attribute = mesh.attributes.new(f"rigger_{label}", 'BOOLEAN', 'EDGE')
        attribute.data.foreach_set("value", owners == code)


def _edge_owners(drawing, edges):
    """Class drawing each edge: of the triangles along it, the one latest in the palette."""
    codes = [code for code, _, _ in drawing.palette]
    rank = np.zeros(max(codes) + 1, dtype=np.int64)
    rank[codes] = np.arange(len(codes))
    sides = np.sort(drawing.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    count = len(drawing.points)
    keys, inverse = np.unique(sides[:, 0] * count + sides[:, 1], return_inverse=True)
    best = np.zeros(len(keys), dtype=np.int64)
    np.maximum.at(best, inverse, np.repeat(rank[drawing.classes], 3))
    edges = np.sort(edges, axis=1)
    return np.array(codes)[best[np.searchsorted(keys, edges[:, 0] * count + edges[:, 1])]]


# Blender data: objects, the collection, materials and node groups.

def _overlay_object(name, owner, stage, drawing, radius, collection):
    label = f"Rigger {name}: {owner}"
    mesh = bpy.data.meshes.new(label)
    _fill(mesh, drawing)
    obj = _helper_object(label, mesh, name, owner, collection)
    if isinstance(drawing, Labels):
        _texts(obj, name, owner, stage, drawing, radius, collection)
    group, values = _modifier_inputs(name, stage, drawing, radius)
    modifier = obj.modifiers.new(MODIFIER_NAME, 'NODES')
    modifier.node_group = group
    for item in group.interface.items_tree:
        if item.item_type == 'SOCKET' and item.in_out == 'INPUT' and item.name in values:
            modifier[item.identifier] = values[item.name]
    obj.update_tag()
    return obj


def _helper_object(label, data, name, owner, collection):
    """An overlay object of stage ``name`` for ``owner``: marked, not selectable, not rendered, drawn in front."""
    obj = bpy.data.objects.new(label, data)
    obj[KIND_KEY] = name
    obj[OWNER_KEY] = owner
    obj.hide_select = True
    obj.hide_render = True
    obj.show_in_front = True
    collection.objects.link(obj)
    return obj


def _texts(parent, name, owner, stage, drawing, radius, collection):
    """A text object per label beside its point, children of ``parent``: upright (readable from the front, -Y),
    ``LABEL_SCALE`` line radii high, in the stage's colour."""
    material = _material(f"Rigger {name}", stage.colour)
    for index, (point, text) in enumerate(zip(drawing.points, drawing.texts)):
        curve = bpy.data.curves.new(f"{parent.name} {index:03d}", 'FONT')
        curve.body = text
        curve.size = LABEL_SCALE * radius
        curve.materials.append(material)
        curve[MADE_KEY] = True
        label = _helper_object(curve.name, curve, name, owner, collection)
        label.parent = parent
        label.location = (point[0] + 2 * LABEL_POINT_SCALE * radius, point[1], point[2])
        label.rotation_euler = (math.pi / 2, 0.0, 0.0)


def _show(obj, visible):
    obj.hide_viewport = not visible
    try:
        obj.hide_set(not visible)
    except RuntimeError:
        pass  # not in the current view layer (its collection is excluded there): nothing to hide


def _remove_objects(chosen):
    """Remove the overlay objects ``chosen`` accepts, and their meshes and texts unless something else uses them."""
    for obj in [obj for obj in bpy.data.objects if KIND_KEY in obj and chosen(obj)]:
        data = obj.data
        bpy.data.objects.remove(obj)
        if data is not None and data.users == 0:
            (bpy.data.meshes if isinstance(data, bpy.types.Mesh) else bpy.data.curves).remove(data)


def _collection():
    """The overlays' collection, made and linked to the current scene when missing."""
    collection = bpy.data.collections.get(COLLECTION_NAME)
    if collection is None:
        collection = bpy.data.collections.new(COLLECTION_NAME)
    scene = bpy.context.scene
    if collection not in scene.collection.children_recursive:
        scene.collection.children.link(collection)
    return collection


def _material(name, colour, alpha=1.0):
    """The shared material ``name``, made once: Workbench's ``diffuse_color`` and a Principled colour to match."""
    material = bpy.data.materials.get(name)
    if material is not None:
        return material
    material = bpy.data.materials.new(name)
    material[MADE_KEY] = True
    material.diffuse_color = (*colour, alpha)
    if material.node_tree is None:  # Blender 4.2 makes the node tree on request; 5.0 always has one
        material.use_nodes = True
    for node in material.node_tree.nodes:
        if node.type == 'BSDF_PRINCIPLED':
            node.inputs["Base Color"].default_value = (*colour, 1.0)
            node.inputs["Alpha"].default_value = alpha
    return material


def _tubes_group():
    """Geometry, Selection, Radius, Material → the selected edges as tubes of that radius and material."""
    group = bpy.data.node_groups.get(TUBES_GROUP)
    if group is not None:
        return group
    group, nodes, start, end = _new_group(TUBES_GROUP, [("Selection", 'NodeSocketBool', True),
                                                        ("Radius", 'NodeSocketFloat', 0.01),
                                                        ("Material", 'NodeSocketMaterial', None)])
    to_curve = nodes.new("GeometryNodeMeshToCurve")
    profile = nodes.new("GeometryNodeCurvePrimitiveCircle")
    _socket(profile.inputs, "Resolution").default_value = TUBE_SIDES
    to_mesh = nodes.new("GeometryNodeCurveToMesh")
    paint = nodes.new("GeometryNodeSetMaterial")
    _link(group, start, "Geometry", to_curve, "Mesh")
    _link(group, start, "Selection", to_curve, "Selection")
    _link(group, start, "Radius", profile, "Radius")
    _link(group, to_curve, "Curve", to_mesh, "Curve")
    _link(group, profile, "Curve", to_mesh, "Profile Curve")
    _link(group, to_mesh, "Mesh", paint, "Geometry")
    _link(group, start, "Material", paint, "Material")
    _link(group, paint, "Geometry", end, "Geometry")
    return group


def _spheres_group():
    """Geometry, Radius, Material → an ico sphere of that radius and material on every vertex."""
    group = bpy.data.node_groups.get(SPHERES_GROUP)
    if group is not None:
        return group
    group, nodes, start, end = _new_group(SPHERES_GROUP, [("Radius", 'NodeSocketFloat', 0.01),
                                                          ("Material", 'NodeSocketMaterial', None)])
    sphere = nodes.new("GeometryNodeMeshIcoSphere")
    _socket(sphere.inputs, "Subdivisions").default_value = SPHERE_SUBDIVISIONS
    place = nodes.new("GeometryNodeInstanceOnPoints")
    realize = nodes.new("GeometryNodeRealizeInstances")
    paint = nodes.new("GeometryNodeSetMaterial")
    _link(group, start, "Radius", sphere, "Radius")
    _link(group, start, "Geometry", place, "Points")
    _link(group, sphere, "Mesh", place, "Instance")
    _link(group, place, "Instances", realize, "Geometry")
    _link(group, realize, "Geometry", paint, "Geometry")
    _link(group, start, "Material", paint, "Material")
    _link(group, paint, "Geometry", end, "Geometry")
    return group


def _class_tubes_group(labels):
    """Geometry, Radius, one material per class (named by ``labels``, title case) → the faces as they are, joined
    with each class's edges (marked by its "rigger_<class>" edge attribute) as tubes of that class's material."""
    name = f"{CLASS_TUBES_GROUP}: {' '.join(labels)}"
    group = bpy.data.node_groups.get(name)
    if group is not None:
        return group
    tubes = _tubes_group()
    group, nodes, start, end = _new_group(name, [("Radius", 'NodeSocketFloat', 0.01)] + [
        (label.title(), 'NodeSocketMaterial', None) for label in labels])
    join = nodes.new("GeometryNodeJoinGeometry")
    _link(group, start, "Geometry", join, "Geometry")
    for label in labels:
        owned = nodes.new("GeometryNodeInputNamedAttribute")
        owned.data_type = 'BOOLEAN'
        _socket(owned.inputs, "Name").default_value = f"rigger_{label}"
        draw = nodes.new("GeometryNodeGroup")
        draw.node_tree = tubes
        _link(group, start, "Geometry", draw, "Geometry")
        _link(group, owned, "Attribute", draw, "Selection")
        _link(group, start, "Radius", draw, "Radius")
        _link(group, start, label.title(), draw, "Material")
        _link(group, draw, "Geometry", join, "Geometry")
    _link(group, join, "Geometry", end, "Geometry")
    return group


def _new_group(name, inputs):
    """A geometry node group with a Geometry input, ``inputs`` (name, socket type, default) and a Geometry output;
    returns it, its nodes, and its input and output nodes."""
    group = bpy.data.node_groups.new(name, "GeometryNodeTree")
    group[MADE_KEY] = True
    group.is_modifier = True
    group.interface.new_socket("Geometry", in_out='INPUT', socket_type='NodeSocketGeometry')
    for socket_name, socket_type, default in inputs:
        socket = group.interface.new_socket(socket_name, in_out='INPUT', socket_type=socket_type)
        if socket_type == 'NodeSocketFloat':
            socket.default_value = default
            socket.min_value = 0.0
        elif socket_type == 'NodeSocketBool':
            socket.default_value = default
            socket.hide_value = True
    group.interface.new_socket("Geometry", in_out='OUTPUT', socket_type='NodeSocketGeometry')
    nodes = group.nodes
    return group, nodes, nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")


def _link(group, from_node, output, to_node, input_name):
    group.links.new(_socket(from_node.outputs, output), _socket(to_node.inputs, input_name))


def _socket(sockets, name):
    """The enabled socket called ``name`` (a node may hold several of that name, one per data type)."""
    for socket in sockets:
        if socket.name == name and socket.enabled:
            return socket
    raise LookupError(f"no enabled socket {name!r} among {[socket.name for socket in sockets]}")
