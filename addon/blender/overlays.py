"""Stage overlays: every intermediate result of a rigging method drawn in the viewport, so each step can be inspected.

A stage's raw data is stored as a plain mesh (vertices and edges; the triangulation also keeps its faces) and a
geometry-node modifier makes it visible: edges become tubes (Mesh to Curve, Curve to Mesh with a circle profile) and
joints small spheres. Curve to Mesh drops the mesh's colour attributes, so colour comes from materials, one per kind
or triangle class, with a viewport ``diffuse_color`` for Workbench and a matching Principled colour for the other
engines. Sockets are found by name: node layouts differ between Blender 4.2 and 5.0.

Absent stages are skipped silently (a method may provide only some). Malformed stage data is skipped with a
``RuntimeWarning`` naming the stage and the problem: a method's odd debug output must never block rigging.
"""
import math
import numbers
import warnings
from collections.abc import Mapping

import bpy
import numpy as np

from ..skeletonize.chordal import ISOLATED, JUNCTION, SLEEVE, TERMINAL

COLLECTION_NAME = "Rigger Overlays"
OVERLAY_KINDS = (
    ("silhouette", "Silhouette", "Outline of the mesh seen along the view axis, on its plane"),
    ("triangulation", "Triangulation",
     "Constrained Delaunay triangles of the silhouette, coloured terminal / sleeve / junction / isolated"),
    ("axis", "Chordal Axis", "Chordal axis graph of the triangulation, on the silhouette plane"),
    ("pruned", "Pruned Branches", "Axis branches removed as outline noise"),
    ("chains", "Chains", "Axis chains placed in depth inside the mesh"),
    ("joints", "Joints", "Joint positions"),
)
STAGE_OF_KIND = {"silhouette": "silhouette", "triangulation": "cdt", "axis": "axis", "pruned": "pruned",
                 "chains": "chains", "joints": "joints"}

LINE_SCALE = 0.004  # default line radius, as a fraction of the largest extent of the drawn data
JOINT_SCALE = 2.5  # joint sphere radius, in line radii
CDT_EDGE_SCALE = 0.5  # triangulation edge radius, in line radii: its edges are dense and must not hide its faces
TUBE_SIDES = 8  # vertices around a tube
SPHERE_SUBDIVISIONS = 2  # ico sphere level of a joint: 42 vertices
FACE_ALPHA = 0.25  # triangulation faces are see-through (Workbench draws material alpha as transparency)

KIND_COLOURS = {"silhouette": (1.0, 0.85, 0.1), "axis": (0.1, 0.8, 1.0), "pruned": (1.0, 0.15, 0.15),
                "chains": (0.2, 0.9, 0.3), "joints": (0.95, 0.95, 0.95)}
CLASS_NAMES = {TERMINAL: "terminal", SLEEVE: "sleeve", JUNCTION: "junction", ISOLATED: "isolated"}
CLASS_COLOURS = {TERMINAL: (0.95, 0.4, 0.05), SLEEVE: (0.25, 0.45, 1.0), JUNCTION: (0.85, 0.1, 0.75),
                 ISOLATED: (0.55, 0.55, 0.55)}
CLASS_ORDER = (TERMINAL, SLEEVE, JUNCTION, ISOLATED)  # material slots of the triangulation's faces
EDGE_PRIORITY = (SLEEVE, ISOLATED, TERMINAL, JUNCTION)  # an edge between classes is drawn in the later one's colour

TUBES_GROUP = "Rigger Tubes"
CLASS_TUBES_GROUP = "Rigger Class Tubes"
SPHERES_GROUP = "Rigger Spheres"
MODIFIER_NAME = "Rigger Overlay"
KIND_KEY = "rigger_overlay"  # custom properties marking an overlay object: its kind and its owner
OWNER_KEY = "rigger_overlay_owner"


def build_overlays(stages, owner, *, scale=None, visible=None):
    """Helper objects drawing ``stages`` (a skeleton's ``stages``) for rig ``owner``; returns them by kind.

    Objects are named "Rigger <kind>: <owner>" in the "Rigger Overlays" collection and replace any earlier overlays
    of the same owner. ``scale`` is the line radius (None: ``LINE_SCALE`` times the largest extent of the data);
    ``visible`` maps kinds to whether they start shown (None or a missing kind: shown).
    """
    if not isinstance(stages, Mapping):
        raise ValueError(f"stages must be a dict of stage data, got {type(stages).__name__}")
    if not isinstance(owner, str) or not owner:
        raise ValueError(f"owner must be a non-empty string, got {owner!r}")
    visible = {} if visible is None else dict(visible)
    unknown = set(visible) - set(STAGE_OF_KIND)
    if unknown:
        raise ValueError(f"unknown overlay kinds {sorted(unknown)}; kinds are {list(STAGE_OF_KIND)}")
    if scale is not None and not (isinstance(scale, numbers.Real) and not isinstance(scale, bool)
                                  and math.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a positive finite line radius, got {scale!r}")

    drawings = _drawings(stages)
    _remove_objects(lambda obj: obj.get(OWNER_KEY) == owner)
    if not drawings:
        return {}
    radius = float(scale) if scale is not None else _line_radius(drawings.values())
    collection = _collection()
    objects = {}
    for kind, drawing in drawings.items():
        obj = _overlay_object(kind, owner, drawing, radius, collection)
        _show(obj, bool(visible.get(kind, True)))
        objects[kind] = obj
    return objects


def set_overlay_visible(kind, visible):
    """Show or hide every overlay object of ``kind`` (all owners), in viewports and in the current view layer."""
    if kind not in STAGE_OF_KIND:
        raise ValueError(f"unknown overlay kind {kind!r}; kinds are {list(STAGE_OF_KIND)}")
    for obj in bpy.data.objects:
        if obj.get(KIND_KEY) == kind:
            _show(obj, bool(visible))


def clear_overlays():
    """Remove every overlay object and its mesh, the collection, and the node groups and materials made here."""
    _remove_objects(lambda obj: True)
    collection = bpy.data.collections.get(COLLECTION_NAME)
    if collection is not None:
        bpy.data.collections.remove(collection)
    for name in (CLASS_TUBES_GROUP, TUBES_GROUP, SPHERES_GROUP):
        group = bpy.data.node_groups.get(name)
        if group is not None:
            bpy.data.node_groups.remove(group)
    for name in _material_names():
        material = bpy.data.materials.get(name)
        if material is not None:
            bpy.data.materials.remove(material)


# Reading stage data: each reader gets its stage (present) and all stages, and returns a drawing, None when the
# stage is empty, or raises ValueError.

def _drawings(stages):
    """Drawings by kind in drawing order; malformed stages are left out with a warning."""
    readers = {"silhouette": _silhouette, "triangulation": _triangulation, "axis": _axis, "pruned": _pruned,
               "chains": _chains, "joints": _joints}
    drawings = {}
    for kind, _, _ in OVERLAY_KINDS:
        name = STAGE_OF_KIND[kind]
        stage = stages.get(name)
        if stage is None:
            continue
        try:
            drawing = readers[kind](stage, stages)
        except ValueError as error:
            warnings.warn(f"Rigger overlay {kind!r} skipped: stage {name!r} {error}", RuntimeWarning, stacklevel=3)
            continue
        if drawing is not None:
            drawings[kind] = drawing
    return drawings


def _silhouette(stage, stages):
    lift = _plane(stages)
    loops = _field(stage, "loops")
    if not isinstance(loops, (list, tuple)):
        raise ValueError(f"has 'loops' of type {type(loops).__name__}, not a list of (K, 2) arrays")
    points, edges, offset = [], [], 0
    for loop in loops:
        loop = _coordinates(loop, 2, "a loop", minimum=3)
        ring = np.arange(len(loop))
        points.append(lift(loop))
        edges.append(offset + np.stack([ring, np.roll(ring, -1)], axis=1))
        offset += len(loop)
    return _Lines(np.concatenate(points), np.concatenate(edges)) if points else None


def _triangulation(stage, stages):
    lift = _plane(stages)
    vertices = _coordinates(_field(stage, "vertices"), 2, "'vertices'")
    triangles = _indices(_field(stage, "triangles"), 3, len(vertices), "'triangles'")
    classes = np.asarray(_field(stage, "classes"))
    if classes.shape != (len(triangles),) or not np.isin(classes, CLASS_ORDER).all():
        raise ValueError(f"has 'classes' of shape {classes.shape}, not one of {sorted(CLASS_NAMES)} per triangle")
    corners = np.sort(triangles, axis=1)
    if (corners[:, 1:] == corners[:, :-1]).any():
        raise ValueError("has a triangle with a repeated vertex")
    if not len(triangles):
        return None
    used, compact = np.unique(triangles, return_inverse=True)
    return _Triangles(lift(vertices[used]), compact.reshape(-1, 3), classes.astype(np.int64))


def _axis(stage, stages):
    lift = _plane(stages)
    points = _coordinates(_field(stage, "points"), 2, "'points'")
    return _lines(lift(points), _indices(_field(stage, "links"), 2, len(points), "'links'"))


def _pruned(stage, stages):
    lift = _plane(stages)
    axis = stages.get("axis")
    if not isinstance(axis, Mapping):
        raise ValueError("indexes the points of the 'axis' stage, which is missing")
    points = _coordinates(_field(axis, "points"), 2, "the axis 'points'")
    return _lines(lift(points), _indices(_field(stage, "links"), 2, len(points), "'links'"))


def _chains(chains, stages):
    if not isinstance(chains, (list, tuple)):
        raise ValueError(f"is a {type(chains).__name__}, not a list of (K, 3) polylines")
    points, edges, offset = [], [], 0
    for chain in chains:
        chain = _coordinates(chain, 3, "a chain", minimum=2)
        step = np.arange(len(chain) - 1)
        points.append(chain)
        edges.append(offset + np.stack([step, step + 1], axis=1))
        offset += len(chain)
    return _Lines(np.concatenate(points), np.concatenate(edges)) if points else None


def _joints(joints, stages):
    points = _coordinates(joints, 3, "points")
    return _Points(points) if len(points) else None


def _plane(stages):
    """Map (K, 2) silhouette-plane points to 3D, from the frame every 2D stage shares with the silhouette."""
    frame = stages.get("silhouette")
    if not isinstance(frame, Mapping):
        raise ValueError("is 2D and needs the 'silhouette' stage's plane (origin, u, v, direction, depth)")
    try:
        origin, u, v, direction = (_coordinates(_field(frame, key), 3, repr(key), single=True)
                                   for key in ("origin", "u", "v", "direction"))
        depth = _field(frame, "depth")
        if not (isinstance(depth, numbers.Real) and math.isfinite(depth)):
            raise ValueError(f"has a 'depth' of {depth!r}, not a finite number")
    except ValueError as error:
        raise ValueError(f"lies on the silhouette plane, but stage 'silhouette' {error}") from None
    base = origin + depth * direction
    return lambda points: base + points[:, :1] * u + points[:, 1:] * v


def _field(stage, key):
    if not isinstance(stage, Mapping):
        raise ValueError(f"is a {type(stage).__name__}, not a dict with {key!r}")
    if key not in stage:
        raise ValueError(f"has no {key!r}")
    return stage[key]


def _coordinates(value, width, what, *, minimum=0, single=False):
    """``value`` as a finite float64 (K, width) array with K >= minimum, or a (width,) vector when ``single``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"has {what}: not a regular array of numbers") from None
    if array.size == 0 and not single:
        array = array.reshape(0, width)
    shape = (width,) if single else (len(array) if array.ndim else 0, width)
    if array.shape != shape or len(array) < minimum:
        wanted = f"({width},)" if single else f"(K, {width}) with K >= {minimum}"
        raise ValueError(f"has {what} of shape {array.shape}, not {wanted}")
    if not np.isfinite(array).all():
        raise ValueError(f"has {what} with non-finite values")
    return array


def _indices(value, width, count, what):
    """``value`` as an int64 (K, width) array of indices below ``count``."""
    array = np.asarray(value)
    if array.size == 0:
        return np.zeros((0, width), dtype=np.int64)
    if array.ndim != 2 or array.shape[1] != width or not np.issubdtype(array.dtype, np.integer):
        raise ValueError(f"has {what} of shape {array.shape} and type {array.dtype}, not (K, {width}) integers")
    if array.min() < 0 or array.max() >= count:
        raise ValueError(f"has {what} outside 0..{count - 1}")
    return array.astype(np.int64)


def _lines(points, links):
    """Tubes along ``links`` (each once, self-links dropped), keeping only the points they use."""
    links = np.unique(np.sort(links, axis=1), axis=0)
    links = links[links[:, 0] != links[:, 1]]
    if not len(links):
        return None
    used, compact = np.unique(links, return_inverse=True)
    return _Lines(points[used], compact.reshape(-1, 2))


def _line_radius(drawings):
    """``LINE_SCALE`` times the largest extent of all drawn points (as if a metre across when they all coincide)."""
    points = np.concatenate([drawing.points for drawing in drawings])
    extent = float(np.max(points.max(axis=0) - points.min(axis=0)))
    return LINE_SCALE * (extent if extent > 0 else 1.0)


# Drawings: what a stage's mesh holds and which node group, with which inputs, draws it.

class _Lines:
    """Polylines and graphs: vertices and edges, drawn as tubes in the kind's colour."""

    def __init__(self, points, edges):
        self.points, self.edges = points, edges

    def fill(self, mesh):
        mesh.from_pydata(self.points.tolist(), self.edges.tolist(), [])

    def modifier_inputs(self, kind, radius):
        return _tubes_group(), {"Radius": radius, "Material": _kind_material(kind)}


class _Points:
    """Joints: loose vertices, drawn as spheres."""

    def __init__(self, points):
        self.points = points

    def fill(self, mesh):
        mesh.from_pydata(self.points.tolist(), [], [])

    def modifier_inputs(self, kind, radius):
        return _spheres_group(), {"Radius": JOINT_SCALE * radius,
                                  "Material": _kind_material(kind)}


class _Triangles:
    """The triangulation: see-through faces in their class's colour, and every edge a tube in the colour of the
    class that owns it (``EDGE_PRIORITY``), marked by one boolean edge attribute "rigger_<class>" per class."""

    def __init__(self, points, triangles, classes):
        self.points, self.triangles, self.classes = points, triangles, classes

    def fill(self, mesh):
        mesh.from_pydata(self.points.tolist(), [], self.triangles.tolist())
        for code in CLASS_ORDER:
            mesh.materials.append(_class_material(code, faces=True))
        slot = np.empty(max(CLASS_ORDER) + 1, dtype=np.int32)
        slot[list(CLASS_ORDER)] = np.arange(len(CLASS_ORDER))
        mesh.polygons.foreach_set("material_index", slot[self.classes])
        edges = np.empty(2 * len(mesh.edges), dtype=np.int32)
        mesh.edges.foreach_get("vertices", edges)
        owners = self._edge_owners(edges.reshape(-1, 2))
        for code in CLASS_ORDER:
            attribute = mesh.attributes.new(f"rigger_{CLASS_NAMES[code]}", 'BOOLEAN', 'EDGE')
            attribute.data.foreach_set("value", owners == code)

    def _edge_owners(self, edges):
        """Class drawing each edge: of the triangles along it, the one latest in ``EDGE_PRIORITY``."""
        rank = np.empty(max(EDGE_PRIORITY) + 1, dtype=np.int64)
        rank[list(EDGE_PRIORITY)] = np.arange(len(EDGE_PRIORITY))
        sides = np.sort(self.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        count = len(self.points)
        keys, inverse = np.unique(sides[:, 0] * count + sides[:, 1], return_inverse=True)
        best = np.zeros(len(keys), dtype=np.int64)
        np.maximum.at(best, inverse, np.repeat(rank[self.classes], 3))
        edges = np.sort(edges, axis=1)
        return np.array(EDGE_PRIORITY)[best[np.searchsorted(keys, edges[:, 0] * count + edges[:, 1])]]

    def modifier_inputs(self, kind, radius):
        inputs = {CLASS_NAMES[code].title(): _class_material(code) for code in CLASS_ORDER}
        return _class_tubes_group(), {"Radius": CDT_EDGE_SCALE * radius, **inputs}


# Blender data: objects, the collection, materials and node groups.

def _overlay_object(kind, owner, drawing, radius, collection):
    name = f"Rigger {kind}: {owner}"
    mesh = bpy.data.meshes.new(name)
    drawing.fill(mesh)
    obj = bpy.data.objects.new(name, mesh)
    obj[KIND_KEY] = kind
    obj[OWNER_KEY] = owner
    obj.hide_select = True
    obj.hide_render = True
    obj.show_in_front = True
    collection.objects.link(obj)
    group, values = drawing.modifier_inputs(kind, radius)
    modifier = obj.modifiers.new(MODIFIER_NAME, 'NODES')
    modifier.node_group = group
    for item in group.interface.items_tree:
        if item.item_type == 'SOCKET' and item.in_out == 'INPUT' and item.name in values:
            modifier[item.identifier] = values[item.name]
    obj.update_tag()
    return obj


def _show(obj, visible):
    obj.hide_viewport = not visible
    try:
        obj.hide_set(not visible)
    except RuntimeError:
        pass  # not in the current view layer (its collection is excluded there): nothing to hide


def _remove_objects(chosen):
    """Remove the overlay objects ``chosen`` accepts, and their meshes unless something else uses them."""
    for obj in [obj for obj in bpy.data.objects if KIND_KEY in obj and chosen(obj)]:
        mesh = obj.data
        bpy.data.objects.remove(obj)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)


def _collection():
    """The overlays' collection, made and linked to the current scene when missing."""
    collection = bpy.data.collections.get(COLLECTION_NAME)
    if collection is None:
        collection = bpy.data.collections.new(COLLECTION_NAME)
    scene = bpy.context.scene
    if collection not in scene.collection.children_recursive:
        scene.collection.children.link(collection)
    return collection


def _material_name(label, faces=False):
    return f"Rigger {label}" + (" faces" if faces else "")


def _material_names():
    names = [_material_name(kind) for kind in KIND_COLOURS]
    for code in CLASS_ORDER:
        names += [_material_name(CLASS_NAMES[code]), _material_name(CLASS_NAMES[code], faces=True)]
    return names


def _kind_material(kind):
    return _material(_material_name(kind), KIND_COLOURS[kind])


def _class_material(code, faces=False):
    return _material(_material_name(CLASS_NAMES[code], faces), CLASS_COLOURS[code], FACE_ALPHA if faces else 1.0)


def _material(name, colour, alpha=1.0):
    """The shared material ``name``, made once: Workbench's ``diffuse_color`` and a Principled colour to match."""
    material = bpy.data.materials.get(name)
    if material is not None:
        return material
    material = bpy.data.materials.new(name)
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


def _class_tubes_group():
    """Geometry, Radius, one material per class → the faces as they are, joined with each class's edges (marked
    by its "rigger_<class>" edge attribute) as tubes of that class's material."""
    group = bpy.data.node_groups.get(CLASS_TUBES_GROUP)
    if group is not None:
        return group
    tubes = _tubes_group()
    labels = [CLASS_NAMES[code] for code in CLASS_ORDER]
    group, nodes, start, end = _new_group(CLASS_TUBES_GROUP, [("Radius", 'NodeSocketFloat', 0.01)] + [
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
