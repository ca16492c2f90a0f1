"""Skin a mesh object to an armature so that every vertex ends up weighted, and say what it took.

Blender's bone heat (``parent_set(type='ARMATURE_AUTO')``) returns FINISHED even when it prints "Bone Heat
Weighting: failed to find solution for one or more bones" and leaves every vertex unweighted: the heat system of a
mesh split along UV seams into many pieces, or made of loose parts, can be singular. Loose parts and inner shells can
also leave vertices unweighted with no message (a part that sees no bone, or whose bones another part hides). In
bpy 4.2 and 5.0 the message goes through Python's ``sys.stdout`` (measured: nothing reaches file descriptor 1), so it
is captured with ``contextlib.redirect_stdout``; unweighted vertices are counted directly.

:func:`skin` runs bone heat on the mesh, then repairs only what is still unweighted, stage by stage:

1. bone heat on a welded copy (vertices closer than ``WELD_DISTANCE`` of the mesh's size merged, as UV seams split
   them), the weights carried back to the original vertices through the exact weld map;
2. bone heat on each loose part of the welded mesh alone, for the parts still unweighted;
3. ``rigger.weights.bone_weights``: the nearest few bones by distance, which always succeeds.

The repair stages use the mesh's own vertex positions (before modifiers) in world space; bone heat on the mesh itself
sees them as Blender does, through the modifier stack. Weights are finally normalised over the deforming bones.
"""
import contextlib
import io
import json
import time
from dataclasses import asdict, dataclass, field

import bpy
import bmesh
import numpy as np

from ..core.arrays import column_bounds, concatenated_ranges
from ..core.graphs import components
from ..weights import bone_weights
from .meshdata import mesh_arrays, world_points

MODIFIER_NAME = "Rigger Armature"
GROUPS_PROPERTY = "rigger_vertex_groups"  # mesh object property: JSON list of the vertex groups Rigger wrote
FAILURE_MESSAGE = "Bone Heat Weighting: failed to find solution"
WELD_DISTANCE = 1e-5  # fraction of the mesh's largest extent under which two vertices are one (UV-seam duplicates)
TEMPORARY_NAME = "Rigger skinning"
NORMALIZED_TOLERANCE = 1e-6  # a vertex whose weights sum this close to 1 is left as it is (weights are float32)


@dataclass
class SkinStage:
    """One stage of :func:`skin`: how long it took, how many vertices it gave their first weight, what it printed."""

    name: str
    seconds: float = 0.0
    weighted: int = 0
    messages: list = field(default_factory=list)
    note: str = ""


@dataclass
class SkinReport:
    """What :func:`skin` did.

    ``stages`` lists the stages that ran, first ``"bone heat"`` (``weighted`` = the vertices it weighted), then any
    of ``"welded bone heat"``, ``"island bone heat"`` and ``"nearest bones"`` (``weighted`` = the vertices each
    fixed). ``bone_heat_result`` is the operator's return value, ``unweighted`` the vertices left without any
    deforming weight at the end (always 0), ``warnings`` human-readable sentences about anything that went wrong.
    """

    mesh: str
    armature: str
    vertices: int
    bones: int
    bone_heat_result: str = ""
    stages: list = field(default_factory=list)
    unweighted: int = 0
    seconds: float = 0.0
    warnings: list = field(default_factory=list)

    @property
    def messages(self):
        """Every line Blender printed while weighting, in order."""
        return [message for stage in self.stages for message in stage.messages]

    @property
    def level(self):
        """``"WARNING"`` when a repair ran or Blender printed something, else ``"INFO"`` (an operator report type)."""
        return "WARNING" if self.warnings else "INFO"

    def summary(self):
        """One line for the operator's report."""
        head = f"Skinned {self.mesh!r} to {self.armature!r}: {self.vertices} vertices, {self.bones} bones, " \
               f"{self.seconds:.2f} s"
        if not self.warnings:
            return f"{head}, bone heat weighted every vertex"
        parts = []
        if any(FAILURE_MESSAGE in message for message in self.messages):
            parts.append("bone heat failed")
        unweighted = self.vertices - self.stages[0].weighted
        if unweighted:
            fixes = ", ".join(f"{stage.name} {stage.weighted}" for stage in self.stages[1:] if stage.weighted)
            parts.append(f"{unweighted} vertices repaired ({fixes})")
        if self.unweighted:
            parts.append(f"{self.unweighted} STILL UNWEIGHTED")
        return f"{head}; " + "; ".join(parts)

    def as_dict(self):
        """The report as plain data, ready for JSON."""
        return asdict(self)


def skin(mesh_obj, armature_obj):
    """Parent ``mesh_obj`` to ``armature_obj`` with an Armature modifier and a weighted vertex group per deforming
    bone, every vertex weighted; returns a :class:`SkinReport`.

    The mesh keeps its world transform (its previous parent, if any, is replaced by the armature). The modifier,
    named ``MODIFIER_NAME``, goes last in the stack. Skinning again replaces Rigger's previous modifier and vertex
    groups, and any groups named after the armature's deforming bones. Selection and the active object are left as
    they were. ValueError when ``mesh_obj`` is not a mesh object with vertices or ``armature_obj`` is not an
    armature object with deforming bones.
    """
    started = time.perf_counter()
    bone_names = _check_inputs(mesh_obj, armature_obj)
    report = SkinReport(mesh_obj.name, armature_obj.name, len(mesh_obj.data.vertices), len(bone_names))
    if bpy.context.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    _remove_previous_skin(mesh_obj, armature_obj, bone_names)

    stage = SkinStage("bone heat")
    result, stage.messages = _bone_heat(mesh_obj, armature_obj)
    report.bone_heat_result = ",".join(sorted(result))
    _bind(mesh_obj, armature_obj, bone_names)
    entries = _weight_entries(mesh_obj, bone_names)
    weighted = np.zeros(report.vertices, dtype=bool)
    weighted[entries[0]] = True
    stage.weighted = int(weighted.sum())
    stage.seconds = time.perf_counter() - started
    report.stages.append(stage)
    for message in stage.messages:
        report.warnings.append(f"Bone heat printed: {message}")
    if not weighted.all():
        report.warnings.append(f"Bone heat left {report.vertices - stage.weighted} of {report.vertices} vertices "
                               f"unweighted")
        _repair(mesh_obj, armature_obj, bone_names, weighted, report)
        entries = _weight_entries(mesh_obj, bone_names)  # the repairs wrote weights

    report.unweighted = int((~_normalize(mesh_obj, bone_names, entries)).sum())
    if report.unweighted:
        report.warnings.append(f"{report.unweighted} vertices are still unweighted")
    report.seconds = time.perf_counter() - started
    return report


def _check_inputs(mesh_obj, armature_obj):
    """The names of the armature's deforming bones; ValueError for anything skin() cannot work with."""
    if not isinstance(mesh_obj, bpy.types.Object) or mesh_obj.type != 'MESH':
        raise ValueError(f"expected a mesh object to skin, got {_describe(mesh_obj)}")
    if not len(mesh_obj.data.vertices):
        raise ValueError(f"mesh {mesh_obj.name!r} has no vertices to skin")
    if not isinstance(armature_obj, bpy.types.Object) or armature_obj.type != 'ARMATURE':
        raise ValueError(f"expected an armature object to skin to, got {_describe(armature_obj)}")
    if not len(armature_obj.data.bones):
        raise ValueError(f"armature {armature_obj.name!r} has no bones")
    names = [bone.name for bone in armature_obj.data.bones if bone.use_deform]
    if not names:
        raise ValueError(f"armature {armature_obj.name!r} has no deforming bones")
    return names


def _describe(value):
    if isinstance(value, bpy.types.Object):
        return f"{value.type.lower()} object {value.name!r}"
    return type(value).__name__


def unbind(mesh_obj, armature_obj):
    """Undo :func:`skin`: remove Rigger's modifier (and any Armature modifier on ``armature_obj``), the vertex groups
    Rigger wrote or named after the armature's bones, and the parenting; the mesh stays where it is."""
    _remove_previous_skin(mesh_obj, armature_obj, [bone.name for bone in armature_obj.data.bones])
    mesh_obj.pop(GROUPS_PROPERTY, None)
    if mesh_obj.parent == armature_obj:
        world = mesh_obj.matrix_world.copy()
        mesh_obj.parent = None
        mesh_obj.matrix_world = world


def _remove_previous_skin(mesh_obj, armature_obj, bone_names):
    """Drop Rigger's earlier modifier and groups, any Armature modifier on this armature, and groups named after its
    deforming bones, so that bone heat starts from nothing and no stale weight counts as a result."""
    for modifier in list(mesh_obj.modifiers):
        if modifier.type == 'ARMATURE' and (modifier.name.startswith(MODIFIER_NAME)
                                            or modifier.object == armature_obj):
            mesh_obj.modifiers.remove(modifier)
    stale = set(bone_names) | set(json.loads(mesh_obj.get(GROUPS_PROPERTY, "[]")))
    for group in list(mesh_obj.vertex_groups):
        if group.name in stale:
            mesh_obj.vertex_groups.remove(group)


def _bone_heat(obj, armature_obj):
    """Run Blender's bone heat parenting on ``obj``: (the operator's result set, the lines it printed). An operator
    error is one more printed line: the repair stages take over as they do when bone heat weights nothing."""
    printed = io.StringIO()
    objects = [obj, armature_obj]
    with bpy.context.temp_override(active_object=armature_obj, object=armature_obj, selected_objects=objects,
                                   selected_editable_objects=objects), contextlib.redirect_stdout(printed):
        try:
            result = bpy.ops.object.parent_set(type='ARMATURE_AUTO', keep_transform=True)
        except RuntimeError as error:
            result = {'CANCELLED'}
            print(f"Bone heat parenting raised: {error}")
    return result, [line.strip() for line in printed.getvalue().splitlines() if line.strip()]


def _bind(mesh_obj, armature_obj, bone_names):
    """Make sure the mesh is parented to the armature (world transform kept), deformed by one Armature modifier
    named ``MODIFIER_NAME`` at the end of the stack, and has a group per deforming bone, whatever bone heat did."""
    if mesh_obj.parent != armature_obj:
        world = mesh_obj.matrix_world.copy()
        mesh_obj.parent = armature_obj
        mesh_obj.parent_type = 'OBJECT'
        mesh_obj.matrix_world = world
    modifier = next((m for m in mesh_obj.modifiers if m.type == 'ARMATURE' and m.object == armature_obj), None)
    if modifier is None:
        modifier = mesh_obj.modifiers.new(MODIFIER_NAME, 'ARMATURE')
        modifier.object = armature_obj
    modifier.name = MODIFIER_NAME
    modifier.use_vertex_groups = True
    modifier.use_bone_envelopes = False
    mesh_obj.modifiers.move(list(mesh_obj.modifiers).index(modifier), len(mesh_obj.modifiers) - 1)
    for name in bone_names:
        if mesh_obj.vertex_groups.get(name) is None:
            mesh_obj.vertex_groups.new(name=name)
    mesh_obj[GROUPS_PROPERTY] = json.dumps(bone_names)


def _weight_entries(obj, bone_names):
    """Every positive deforming weight of ``obj`` as (vertex, bone index into ``bone_names``, weight) arrays."""
    column = {}
    for index, name in enumerate(bone_names):
        group = obj.vertex_groups.get(name)
        if group is not None:
            column[group.index] = index
    vertices, bones, weights = [], [], []
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            bone = column.get(element.group)
            if bone is not None and element.weight > 0:
                vertices.append(vertex.index)
                bones.append(bone)
                weights.append(element.weight)
    return np.array(vertices, dtype=np.int64), np.array(bones, dtype=np.int64), np.array(weights)


def _repair(mesh_obj, armature_obj, bone_names, weighted, report):
    """Run the repair ladder for the vertices ``weighted`` says are not; updates ``weighted`` and ``report``."""
    started = time.perf_counter()
    local_positions, triangles = mesh_arrays(mesh_obj.data)
    positions = world_points(local_positions, mesh_obj.matrix_world)
    weld_map, kept, welded_triangles = _welded(mesh_obj.data, local_positions, triangles)
    welded = (weld_map, positions[kept], welded_triangles)
    if len(kept) < len(positions):
        _repair_welded(mesh_obj, armature_obj, bone_names, weighted, welded, report, started)
    if not weighted.all():
        _repair_islands(mesh_obj, armature_obj, bone_names, weighted, welded, report)
    if not weighted.all():
        _repair_nearest(mesh_obj, armature_obj, bone_names, weighted, positions, report)


def _repair_welded(mesh_obj, armature_obj, bone_names, weighted, welded, report, started):
    """Stage 1: bone heat on the welded copy, weights carried back through the weld map."""
    weld_map, welded_positions, welded_triangles = welded
    merged = len(weld_map) - len(welded_positions)
    stage = SkinStage("welded bone heat", note=f"{merged} duplicate vertices merged")
    entries, stage.messages = _bone_heat_weights(welded_positions, welded_triangles, armature_obj, bone_names)
    targets = np.flatnonzero(~weighted)
    stage.weighted = _transfer(mesh_obj, bone_names, entries, targets, weld_map[targets], weighted)
    _finish_stage(stage, started, report, f"Bone heat on a welded copy ({merged} duplicate vertices merged) "
                                          f"weighted {stage.weighted} of them")


def _repair_islands(mesh_obj, armature_obj, bone_names, weighted, welded, report):
    """Stage 2: bone heat on each loose part of the welded mesh that still holds unweighted vertices, alone (no
    other part hides its bones, no other part makes its heat system singular)."""
    started = time.perf_counter()
    weld_map, welded_positions, welded_triangles = welded
    edges = np.concatenate([welded_triangles[:, [0, 1]], welded_triangles[:, [1, 2]]])
    island_of = components(len(welded_positions), edges)
    parts = int(island_of.max()) + 1
    if parts == 1:  # the whole mesh was tried already
        return
    stage = SkinStage("island bone heat")
    vertices_by_island = _grouped(island_of, parts)
    triangles_by_island = _grouped(island_of[welded_triangles[:, 0]], parts)
    local_index = np.empty(len(welded_positions), dtype=np.int64)
    for members in vertices_by_island:
        local_index[members] = np.arange(len(members))
    targets = np.flatnonzero(~weighted)
    tried = 0
    for island, island_targets in enumerate(_grouped(island_of[weld_map[targets]], parts)):
        faces = welded_triangles[triangles_by_island[island]]
        if not len(island_targets) or not len(faces):
            continue
        tried += 1
        entries, messages = _bone_heat_weights(welded_positions[vertices_by_island[island]], local_index[faces],
                                               armature_obj, bone_names)
        stage.messages += messages
        vertices = targets[island_targets]
        stage.weighted += _transfer(mesh_obj, bone_names, entries, vertices, local_index[weld_map[vertices]],
                                    weighted)
    stage.note = f"{tried} of {parts} loose parts tried"
    _finish_stage(stage, started, report,
                  f"Bone heat per loose part ({stage.note}) weighted {stage.weighted} more vertices")


def _repair_nearest(mesh_obj, armature_obj, bone_names, weighted, positions, report):
    """Stage 3: every vertex still unweighted gets its nearest bones (``rigger.weights``), which always succeeds."""
    started = time.perf_counter()
    stage = SkinStage("nearest bones")
    targets = np.flatnonzero(~weighted)
    heads, tails = _world_bones(armature_obj, bone_names)
    result = bone_weights(positions[targets], heads, tails, _world_normals(mesh_obj)[targets])
    rows, slots = np.nonzero(result.bones >= 0)
    _write_weights(mesh_obj, bone_names, targets[rows], result.bones[rows, slots], result.weights[rows, slots])
    weighted[targets] = True
    stage.weighted = len(targets)
    _finish_stage(stage, started, report,
                  f"The remaining {len(targets)} vertices were weighted by their nearest bones (distance fallback)")


def _finish_stage(stage, started, report, sentence):
    stage.seconds = time.perf_counter() - started
    report.stages.append(stage)
    report.warnings.extend(f"Bone heat printed: {message}" for message in stage.messages)
    report.warnings.append(sentence)


def _world_normals(obj):
    """Unit vertex normals (N, 3) in world space (zero where a vertex has none)."""
    mesh = obj.data
    normals = np.empty(len(mesh.vertices) * 3)
    mesh.vertex_normals.foreach_get("vector", normals)
    linear = np.array(obj.matrix_world)[:3, :3]
    normals = normals.reshape(-1, 3) @ np.linalg.inv(linear)  # normals map by the inverse transpose
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)


def _world_bones(armature_obj, bone_names):
    """Heads and tails (B, 3) of the named bones in world space, rest pose."""
    bones = [armature_obj.data.bones[name] for name in bone_names]
    ends = world_points(np.array([(bone.head_local, bone.tail_local) for bone in bones], dtype=np.float64),
                        armature_obj.matrix_world)
    return ends[:, 0], ends[:, 1]


def _welded(mesh, positions, triangles):
    """Merge vertices closer than ``WELD_DISTANCE`` of the mesh's size (``positions``: its object-space vertices):
    (weld map (N,) original -> welded index, the original index of each welded vertex, welded triangles without
    the ones welding collapsed)."""
    bounds = column_bounds(positions)
    size = float((bounds[1] - bounds[0]).max())
    work = bmesh.new()
    try:
        work.from_mesh(mesh)
        work.verts.ensure_lookup_table()
        doubles = bmesh.ops.find_doubles(work, verts=work.verts[:], dist=WELD_DISTANCE * size)["targetmap"]
        target = np.arange(len(positions))
        for vertex, keep in doubles.items():
            target[vertex.index] = keep.index
    finally:
        work.free()
    while not np.array_equal(target[target], target):  # follow chains to the vertex that stays
        target = target[target]
    kept, weld_map = np.unique(target, return_inverse=True)
    welded = weld_map[triangles]
    distinct = (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & (welded[:, 2] != welded[:, 0])
    return weld_map, kept, welded[distinct]


def _bone_heat_weights(positions, triangles, armature_obj, bone_names):
    """Bone heat on a temporary world-space mesh: ((vertex, bone, weight) arrays, printed lines); leaves nothing."""
    mesh = bpy.data.meshes.new(TEMPORARY_NAME)
    obj = bpy.data.objects.new(TEMPORARY_NAME, mesh)
    try:
        mesh.vertices.add(len(positions))
        mesh.vertices.foreach_set("co", positions.astype(np.float32).ravel())
        mesh.loops.add(3 * len(triangles))
        mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
        mesh.polygons.add(len(triangles))
        mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(triangles), 3, dtype=np.int32))
        mesh.update()
        bpy.context.scene.collection.objects.link(obj)
        _, messages = _bone_heat(obj, armature_obj)
        return _weight_entries(obj, bone_names), messages
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)


def _grouped(labels, count):
    """Indices of ``labels`` grouped by label 0 .. count - 1: a list of ``count`` index arrays."""
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(count + 1))
    return [order[bounds[label]:bounds[label + 1]] for label in range(count)]


def _transfer(mesh_obj, bone_names, entries, targets, sources, weighted):
    """Give the original vertices ``targets`` the weights of copy vertices ``sources`` (the copy's (vertex, bone,
    weight) ``entries``), where the copy has any; marks them in ``weighted`` and returns how many it weighted."""
    copy_vertices, bones, weights = entries
    order = np.argsort(copy_vertices, kind="stable")
    copy_vertices, bones, weights = copy_vertices[order], bones[order], weights[order]
    first = np.searchsorted(copy_vertices, sources, side="left")
    last = np.searchsorted(copy_vertices, sources, side="right")
    found = last > first
    counts = (last - first)[found]
    rows = concatenated_ranges(first[found], counts)
    _write_weights(mesh_obj, bone_names, np.repeat(targets[found], counts), bones[rows], weights[rows])
    weighted[targets[found]] = True
    return int(found.sum())


def _normalize(mesh_obj, bone_names, entries):
    """Scale each vertex's deforming weights (``_weight_entries``) to sum to 1 (bone heat leaves sums of 0.9 to 1),
    in Python rather than with Blender's operator, whose poll refuses hidden objects. Returns the (N,) mask of
    weighted vertices."""
    vertices, bones, weights = entries
    sums = np.bincount(vertices, weights, minlength=len(mesh_obj.data.vertices))
    scaled = weights / sums[vertices]
    off = np.abs(sums[vertices] - 1.0) > NORMALIZED_TOLERANCE
    _write_weights(mesh_obj, bone_names, vertices[off], bones[off], scaled[off])
    return sums > 0


def _write_weights(mesh_obj, bone_names, vertices, bones, weights):
    """Set weight ``weights[k]`` of vertex ``vertices[k]`` in the group of bone ``bones[k]`` (an index into
    ``bone_names``)."""
    groups = [mesh_obj.vertex_groups[name] for name in bone_names]
    for vertex, bone, weight in zip(vertices.tolist(), bones.tolist(), weights.tolist()):
        groups[bone].add([vertex], weight, 'REPLACE')
