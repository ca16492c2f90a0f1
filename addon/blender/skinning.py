"""Skin a mesh object to an armature so that every vertex ends up weighted, and say what it took.

Every stage weights the *welded* mesh: vertices closer than ``WELD_DISTANCE`` of the mesh's size (the copies that
UV seams and flat shading split a surface into) are merged first, and the weights are carried back to the original
vertices through the exact weld map. Copies of one vertex therefore always get identical weights, so a posed mesh
cannot crack open along its seams, and bone heat sees one connected surface instead of the pieces that make its heat
system singular.

Blender's bone heat (``parent_set(type='ARMATURE_AUTO')``) returns FINISHED even when it prints "Bone Heat
Weighting: failed to find solution for one or more bones" and leaves every vertex unweighted: the heat system of a
mesh with loose parts that see no bone (another part hides them) is singular. Loose parts and inner shells can also
leave vertices unweighted with no message. In bpy 4.2 and 5.0 the message goes through Python's ``sys.stdout``
(measured: nothing reaches file descriptor 1), so it is captured with ``contextlib.redirect_stdout``; unweighted
vertices are counted directly.

:func:`skin` runs bone heat on a temporary welded copy of the mesh, then repairs only what is still unweighted:

1. bone heat on each loose part of the welded mesh alone, for the parts still unweighted;
2. ``rigger.weights.bone_weights``: the nearest few bones by distance, which always succeeds (its facing penalty
   takes area-weighted normals of the welded mesh, so a seam's copies face alike).

Then a bone that carries no vertex's largest weight (bone heat heats a bone from the vertices it is the nearest
visible bone of; between the rings of a low-poly mesh a short bone may be none's) gets a share of the vertices of
the bones it joins, blended in from the nearest bones, so that every bone moves some of the mesh.

Last, the accessories, the loose parts no bone runs through (``rigger.core.accessories``: eyes, teeth, nails,
plates), move as one piece with the other parts' surface nearest to them, so they stay with what they sit on. Bone
heat still weighs the whole mesh, accessories included, and their weights are replaced afterwards: leaving them out
changed the body's weights (on a robot built of many loose parts, bone heat on the whole then succeeded where each
part alone had done better).

Every stage uses the mesh's own vertex positions (before modifiers) in world space, as Blender's bone heat does when
parenting, except that with a Subsurf modifier Blender's bone heat takes each vertex's place on the limit surface:
the welded copies (triangulated) then get a Subsurf modifier too. Weights are normalised over the deforming bones as
they are written.
"""
import contextlib
import io
import json
import time
from dataclasses import asdict, dataclass, field
from functools import cached_property

import bpy
import bmesh
import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

from ..core.accessories import barycentric, boneless_parts, part_means, surface_entries
from ..core.arrays import column_bounds, concatenated_ranges
from ..core.graphs import loose_parts
from ..weights import bone_weights, vertex_normals
from .meshdata import mesh_arrays, world_points

MODIFIER_NAME = "Rigger Armature"
GROUPS_PROPERTY = "rigger_vertex_groups"  # mesh object property: JSON list of the vertex groups Rigger wrote
FAILURE_MESSAGE = "Bone Heat Weighting: failed to find solution"
WELD_DISTANCE = 1e-5  # fraction of the mesh's largest extent under which two vertices are one (UV-seam duplicates)
TEMPORARY_NAME = "Rigger skinning"
SURFACE_STAGE = "surface weights"  # the accessories' stage (core.accessories)
IDLE_STAGE = "idle bones"  # the stage giving bones that carry no vertex's largest weight a share


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

    ``stages`` lists the stages that ran, first ``"bone heat"`` on the welded mesh (``weighted`` = the vertices it
    weighted), then any of ``"island bone heat"`` and ``"nearest bones"`` (``weighted`` = the vertices each fixed),
    ``"idle bones"`` when a bone carried no vertex's largest weight (``weighted`` = the vertices reweighted, ``note``
    = those bones), and last ``"surface weights"`` when the mesh has accessories (``weighted`` = their vertices).
    ``welded`` counts the vertices merged into another at the same place before weighting (they share its weights),
    ``bone_heat_result`` is the operator's return value, ``unweighted`` the vertices left without any deforming
    weight at the end (always 0), ``warnings`` human-readable sentences about anything that went wrong.
    """

    mesh: str
    armature: str
    vertices: int
    bones: int
    welded: int = 0
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
        if self.welded:
            head += f", {self.welded} seam vertices welded"
        idle = next((stage for stage in self.stages if stage.name == IDLE_STAGE), None)
        if idle is not None:
            head += f", bones that moved no vertex given a share of {idle.weighted} vertices ({idle.note})"
        surface = next((stage for stage in self.stages if stage.name == SURFACE_STAGE), None)
        if surface is not None:
            head += f", {surface.weighted} vertices of {surface.note} moved with the surface they sit on"
        if not self.warnings:
            return f"{head}, bone heat weighted every vertex"
        parts = []
        if any(FAILURE_MESSAGE in message for message in self.messages):
            parts.append("bone heat failed")
        repairs = [stage for stage in self.stages[1:] if stage is not surface and stage is not idle]
        unweighted = self.vertices - self.stages[0].weighted
        if unweighted:
            fixes = ", ".join(f"{stage.name} {stage.weighted}" for stage in repairs if stage.weighted)
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
    _bind(mesh_obj, armature_obj, bone_names)

    weld = _welded(mesh_obj)
    report.welded = report.vertices - len(weld.positions)
    stage = SkinStage("bone heat", note=f"{report.welded} seam vertices welded" if report.welded else "")
    result, entries, stage.messages = _bone_heat_weights(weld.positions, weld.triangles, armature_obj, bone_names,
                                                         weld.subsurf)
    report.bone_heat_result = ",".join(sorted(result))
    weighted = np.zeros(report.vertices, dtype=bool)
    stage.weighted = _transfer(mesh_obj, bone_names, entries, np.arange(report.vertices), weld.map, weighted)
    stage.seconds = time.perf_counter() - started
    report.stages.append(stage)
    for message in stage.messages:
        report.warnings.append(f"Bone heat printed: {message}")
    if not weighted.all():
        report.warnings.append(f"Bone heat left {report.vertices - stage.weighted} of {report.vertices} vertices "
                               f"unweighted")
        _repair_islands(mesh_obj, armature_obj, bone_names, weighted, weld, report)
        if not weighted.all():
            _repair_nearest(mesh_obj, armature_obj, bone_names, weighted, weld, report)
    bones = _world_bones(armature_obj, bone_names)
    _weigh_idle_bones(mesh_obj, armature_obj, bone_names, bones, weld, report)
    accessories = _Accessories.of(weld, *bones)
    if accessories.parts:
        _weigh_accessories(mesh_obj, bone_names, weld, accessories, report)

    report.unweighted = int((~weighted).sum())
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


def weight_entries(obj, bone_names, vertices=None):
    """Every positive deforming weight of ``obj`` (of its ``vertices`` only, given indices) as (vertex, bone index
    into ``bone_names``, weight) arrays."""
    column = {}
    for index, name in enumerate(bone_names):
        group = obj.vertex_groups.get(name)
        if group is not None:
            column[group.index] = index
    chosen = obj.data.vertices if vertices is None else [obj.data.vertices[i] for i in vertices]
    vertices, bones, weights = [], [], []
    for vertex in chosen:
        for element in vertex.groups:
            bone = column.get(element.group)
            if bone is not None and element.weight > 0:
                vertices.append(vertex.index)
                bones.append(bone)
                weights.append(element.weight)
    return np.array(vertices, dtype=np.int64), np.array(bones, dtype=np.int64), np.array(weights)


def _repair_islands(mesh_obj, armature_obj, bone_names, weighted, weld, report):
    """Repair 1: bone heat on each loose part of the welded mesh that still holds unweighted vertices, alone (no
    other part hides its bones, no other part makes its heat system singular)."""
    started = time.perf_counter()
    weld_map, welded_positions, welded_triangles = weld.map, weld.positions, weld.triangles
    island_of = weld.parts
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
        _, entries, messages = _bone_heat_weights(welded_positions[vertices_by_island[island]],
                                                  local_index[faces], armature_obj, bone_names, weld.subsurf)
        stage.messages += messages
        vertices = targets[island_targets]
        stage.weighted += _transfer(mesh_obj, bone_names, entries, vertices, local_index[weld_map[vertices]],
                                    weighted)
    stage.note = f"{tried} of {parts} loose parts tried"
    _finish_stage(stage, started, report,
                  f"Bone heat per loose part ({stage.note}) weighted {stage.weighted} more vertices")


def _repair_nearest(mesh_obj, armature_obj, bone_names, weighted, weld, report):
    """Repair 2: every vertex still unweighted gets the nearest bones (``rigger.weights``) of its welded vertex, which
    always succeeds. The facing penalty takes the welded mesh's area-weighted normals: a seam's copies, each with the
    normal of its own side's faces, would otherwise face apart and get different bones."""
    started = time.perf_counter()
    stage = SkinStage("nearest bones")
    targets = np.flatnonzero(~weighted)
    sources = np.unique(weld.map[targets])
    heads, tails = _world_bones(armature_obj, bone_names)
    normals = vertex_normals(weld.positions, weld.triangles)[sources]
    result = bone_weights(weld.positions[sources], heads, tails, normals)
    rows, slots = np.nonzero(result.bones >= 0)
    entries = (sources[rows], result.bones[rows, slots], result.weights[rows, slots])
    _transfer(mesh_obj, bone_names, entries, targets, weld.map[targets], weighted)
    stage.weighted = len(targets)
    _finish_stage(stage, started, report,
                  f"The remaining {len(targets)} vertices were weighted by their nearest bones (distance fallback)")


def _weigh_idle_bones(mesh_obj, armature_obj, bone_names, bones, weld, report):
    """Stage: the bones that carry no vertex's largest weight (idle) get a share of the vertices around them. Each
    welded vertex whose largest weight is on an idle bone's parent or child blends its weights towards its nearest
    bones' (``rigger.weights``, the deforming ``bones``' heads and tails), those it already has and that idle bone,
    by the weight they give the idle bone: the weights stay continuous (a seam's copies alike) and take nothing from
    other parts near by (the other foot). Only those vertices are weighed again, row by row."""
    started = time.perf_counter()
    count = len(bone_names)
    first = np.full(len(weld.positions), -1)
    first[weld.map[::-1]] = np.arange(len(weld.map))[::-1]  # one original vertex of each welded one
    vertices, columns, weights = weight_entries(mesh_obj, bone_names, first.tolist())
    welded = weld.map[vertices]
    order = np.lexsort((-columns, weights, welded))  # by vertex, then weight, the lower bone last among equals
    largest = order[np.r_[welded[order][1:] != welded[order][:-1], True]]
    dominant = np.full(len(weld.positions), -1)
    dominant[welded[largest]] = columns[largest]
    idle = np.setdiff1d(np.arange(count), dominant)
    if not len(idle):
        return
    index = {name: k for k, name in enumerate(bone_names)}
    joined = {bone: _joined(armature_obj, bone_names, index, bone) for bone in idle.tolist()}
    near = np.flatnonzero(np.isin(dominant, np.concatenate(list(joined.values()))))  # welded vertices to weigh
    joins = np.zeros((len(near), count), dtype=bool)  # the idle bones joined to each one's dominant bone (or it)
    for bone, others in joined.items():
        joins[np.isin(dominant[near], others), bone] = True
    row = np.full(len(weld.positions), -1)
    row[near] = np.arange(len(near))
    current = np.zeros((len(near), count))
    mine = row[welded] >= 0
    current[row[welded[mine]], columns[mine]] = weights[mine]
    normals = vertex_normals(weld.positions, weld.triangles)[near]
    nearest = bone_weights(weld.positions[near], *bones, normals).dense(count)
    share = np.minimum((nearest * joins).sum(axis=1), 1.0)
    changed = np.flatnonzero(share > 0)
    own = nearest[changed] * ((current[changed] > 0) | joins[changed])  # no weight from other parts near by
    own /= own.sum(axis=1, keepdims=True)
    blended = (1.0 - share[changed, None]) * current[changed] + share[changed, None] * own
    rows, blended_columns = np.nonzero(blended > 0)
    targets = np.flatnonzero(np.isin(weld.map, near[changed]))
    for name in bone_names:
        mesh_obj.vertex_groups[name].remove(targets.tolist())
    stage = SkinStage(IDLE_STAGE, note=", ".join(bone_names[bone] for bone in idle))
    _transfer(mesh_obj, bone_names, (near[changed][rows], blended_columns, blended[rows, blended_columns]), targets,
              weld.map[targets], np.zeros(report.vertices, dtype=bool))
    stage.weighted = len(targets)
    stage.seconds = time.perf_counter() - started
    report.stages.append(stage)


def _joined(armature_obj, bone_names, index, bone):
    """Indices (into ``bone_names``, the deforming bones; ``index`` maps their names to them) of ``bone`` and of the
    deforming bones it joins: its parent and its children."""
    data = armature_obj.data.bones[bone_names[bone]]
    return [bone] + [index[other.name] for other in [data.parent, *data.children]
                     if other is not None and other.name in index]


def _weigh_accessories(mesh_obj, bone_names, weld, accessories, report):
    """Last stage: each accessory takes the mean of the weights at its vertices' nearest points on the body's
    surface (``core.accessories.part_means``), each blended from its triangle's corners as the stages before
    weighted them."""
    started = time.perf_counter()
    body = accessories.body
    tree = BVHTree.FromPolygons(body.positions.tolist(), body.triangles.tolist(), all_triangles=True)
    nearest = [tree.find_nearest(Vector(point)) for point in weld.positions[accessories.welded].tolist()]
    corners = body.triangles[[hit[2] for hit in nearest]]
    coordinates = barycentric(np.array([hit[0] for hit in nearest]),
                              *(body.positions[corners[:, k]] for k in range(3)))
    originals = np.flatnonzero(body.map >= 0)
    first_copy = np.empty(len(body.positions), dtype=np.int64)
    first_copy[body.map[originals[::-1]]] = originals[::-1]
    vertices, bones, weights = weight_entries(mesh_obj, bone_names, first_copy[np.unique(corners)].tolist())
    entries = part_means(accessories.part_of, weld.positions[accessories.welded], [hit[3] for hit in nearest],
                         surface_entries(corners, coordinates, (body.map[vertices], bones, weights)))
    part = np.full(len(weld.positions), -1)
    part[accessories.welded] = accessories.part_of
    targets = np.flatnonzero(accessories.on_original)
    for name in bone_names:  # the weights the stages before gave them
        mesh_obj.vertex_groups[name].remove(targets.tolist())
    stage = SkinStage(SURFACE_STAGE, note=f"{accessories.parts} loose parts no bone runs through")
    stage.weighted = _transfer(mesh_obj, bone_names, entries, targets, part[weld.map[targets]],
                               np.zeros(report.vertices, dtype=bool))
    stage.seconds = time.perf_counter() - started
    report.stages.append(stage)


def _finish_stage(stage, started, report, sentence):
    stage.seconds = time.perf_counter() - started
    report.stages.append(stage)
    report.warnings.extend(f"Bone heat printed: {message}" for message in stage.messages)
    report.warnings.append(sentence)


def _world_bones(armature_obj, bone_names):
    """Heads and tails (B, 3) of the named bones in world space, rest pose."""
    bones = [armature_obj.data.bones[name] for name in bone_names]
    ends = world_points(np.array([(bone.head_local, bone.tail_local) for bone in bones], dtype=np.float64),
                        armature_obj.matrix_world)
    return ends[:, 0], ends[:, 1]


@dataclass
class Weld:
    """A mesh with its seams welded: ``map`` (N,) original vertex -> welded vertex, ``positions`` the welded
    vertices (each the position of the first original vertex merged into it) in world space, ``triangles`` the
    welded triangles, those welding collapsed dropped; ``subsurf``: the mesh has a Subsurf modifier, so bone heat
    takes the limit surface."""

    map: np.ndarray
    positions: np.ndarray
    triangles: np.ndarray
    subsurf: bool

    @cached_property
    def parts(self):
        """(welded vertices,) the loose part of each welded vertex (``core.graphs.loose_parts``)."""
        return loose_parts(len(self.positions), self.triangles)


@dataclass
class _Accessories:
    """The welded mesh split into its accessories (``core.accessories``) and the body they sit on: ``body`` a
    :class:`Weld` of the other parts, whose map sends each original vertex to its body vertex (-1 on an accessory);
    ``on_original`` (N,) which original vertices lie on an accessory, ``welded`` the accessories' welded vertices,
    ``part_of`` the accessory (0 .. ``parts`` - 1) of each of them. A mesh whose body would have no faces has no
    accessories: nothing to sit on."""

    body: Weld
    on_original: np.ndarray
    welded: np.ndarray
    part_of: np.ndarray
    parts: int

    @classmethod
    def of(cls, weld, heads, tails):
        part_of = weld.parts
        boneless = boneless_parts(part_of, weld.positions, heads, tails)
        if boneless[part_of[weld.triangles[:, 0]]].all():
            boneless[:] = False
        accessory = boneless[part_of]
        kept = np.flatnonzero(~accessory)
        local = np.full(len(weld.positions), -1)
        local[kept] = np.arange(len(kept))
        body = Weld(local[weld.map], weld.positions[kept], local[weld.triangles[~accessory[weld.triangles[:, 0]]]],
                    weld.subsurf)
        welded = np.flatnonzero(accessory)
        _, part = np.unique(part_of[welded], return_inverse=True)
        return cls(body, accessory[weld.map], welded, part.ravel(), int(boneless.sum()))


def _welded(mesh_obj):
    """Mesh object ``mesh_obj`` with its vertices closer than ``WELD_DISTANCE`` of its size merged: a :class:`Weld`.
    Vertices in a chain of such neighbours all merge into one."""
    mesh = mesh_obj.data
    positions, triangles = mesh_arrays(mesh)
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
    return Weld(weld_map, world_points(positions[kept], mesh_obj.matrix_world), welded[distinct],
                any(modifier.type == 'SUBSURF' for modifier in mesh_obj.modifiers))


def _bone_heat_weights(positions, triangles, armature_obj, bone_names, subsurf=False):
    """Bone heat on a temporary world-space mesh (with a Subsurf modifier when ``subsurf``, so that bone heat takes
    its limit surface): (the operator's result, (vertex, bone, weight) arrays, printed lines); leaves nothing."""
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
        if subsurf:
            obj.modifiers.new(TEMPORARY_NAME, 'SUBSURF')
        result, messages = _bone_heat(obj, armature_obj)
        return result, weight_entries(obj, bone_names), messages
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
    weight) ``entries``), where the copy has any; marks them in ``weighted`` and returns how many it weighted.

    The weights are normalised over the deforming bones as they are written (bone heat leaves sums of 0.9 to 1),
    in Python rather than with Blender's operator, whose poll refuses hidden objects. Each distinct (bone, weight)
    is written once, to every target that carries it (a seam's copies, and the many vertices on one bone alone)."""
    copy_vertices, bones, weights = entries
    if not len(copy_vertices):
        return 0
    weights = (weights / np.bincount(copy_vertices, weights)[copy_vertices]).astype(np.float32)  # Blender's floats
    found = np.isin(sources, copy_vertices)
    targets, sources = targets[found], sources[found]
    by_source = np.argsort(sources, kind="stable")
    starts = np.searchsorted(sources[by_source], copy_vertices, side="left")
    counts = np.searchsorted(sources[by_source], copy_vertices, side="right") - starts
    order = np.lexsort((weights, bones))
    bones, weights, starts, counts = bones[order], weights[order], starts[order], counts[order]
    members = targets[by_source[concatenated_ranges(starts, counts)]]  # each entry's targets, entry after entry
    firsts = np.flatnonzero(np.r_[True, (bones[1:] != bones[:-1]) | (weights[1:] != weights[:-1])])
    bounds = np.r_[0, np.cumsum(counts)][np.r_[firsts, len(bones)]]
    groups = [mesh_obj.vertex_groups[name] for name in bone_names]
    for bone, weight, begin, end in zip(bones[firsts].tolist(), weights[firsts].tolist(), bounds[:-1].tolist(),
                                        bounds[1:].tolist()):
        if end > begin:
            groups[bone].add(members[begin:end].tolist(), weight, 'REPLACE')
    weighted[targets] = True
    return len(targets)
