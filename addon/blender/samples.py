"""Build the sample characters of ``rigger.samples`` as Blender meshes: a Skin modifier around the known skeleton.

The skin graph has one vertex per joint (its skin radius from the data) and one edge per bone, rooted at the root
joint. The skin would end flush with an end joint, putting a bone's end on the surface; an extra skin vertex one radius
beyond every end rounds the tip over it, so every true joint lies inside the mesh.

The Skin modifier's hull is fragile: it leaves holes where a limb leaves a branch point steeply or two branch points
sit close together along a thick trunk. The characters' data avoids both (tests/test_samples.py checks every mesh is
closed). Before subdivision, the zero-length edges it leaves at some branch points are collapsed, the vertices it
sometimes leaves without a face (beside a shoulder) removed, and the faces it sometimes winds inwards (at a root with
a single child) turned outwards.
"""
import bpy  # before bmesh: Blender's own modules import only once bpy has
import bmesh
import numpy as np

from .. import samples
from .meshdata import mesh_arrays

TIP_RADIUS_SCALE = 0.7  # the rounding vertex past an end joint is this much thinner than the joint
ZERO_LENGTH = 1e-6  # metres: the Skin modifier's degenerate edges are zero up to float precision


def _skin_graph(joints):
    """Skin vertex positions, radii and edges: the joints and bones plus a rounding vertex past each end of the skin.

    An end is a joint with one neighbour: a leaf, or a root with a single child (a tree's base).
    """
    index = {joint.name: i for i, joint in enumerate(joints)}
    positions = [np.array(joint.position, dtype=np.float64) for joint in joints]
    radii = [joint.radius for joint in joints]
    edges = [(index[joint.parent], i) for i, joint in enumerate(joints) if joint.parent is not None]
    neighbours = [[] for _ in joints]
    for a, b in edges:
        neighbours[a].append(b)
        neighbours[b].append(a)
    for i, joint in enumerate(joints):
        if len(neighbours[i]) != 1:
            continue
        direction = positions[i] - positions[neighbours[i][0]]
        direction /= np.linalg.norm(direction)
        edges.append((i, len(positions)))
        positions.append(positions[i] + direction * joint.radius)
        radii.append(joint.radius * TIP_RADIUS_SCALE)
    return np.array(positions), np.array(radii), edges


def build_character(name, subdivisions=2, collection=None):
    """A new mesh object for sample character ``name`` (modifiers applied), linked into ``collection``.

    ``subdivisions`` Catmull-Clark levels smooth the Skin modifier's boxy hull; ``collection`` defaults to the
    scene's master collection.
    """
    joints = samples.character_joints(name)
    if not isinstance(subdivisions, int) or not 0 <= subdivisions <= 4:
        raise ValueError(f"subdivisions must be an integer from 0 to 4, got {subdivisions!r}")
    positions, radii, edges = _skin_graph(joints)
    skeleton_mesh = bpy.data.meshes.new(f"{name}_skeleton")
    skeleton_mesh.from_pydata(positions.tolist(), edges, [])
    obj = bpy.data.objects.new(name, skeleton_mesh)
    (bpy.context.scene.collection if collection is None else collection).objects.link(obj)

    skin = obj.modifiers.new("Skin", 'SKIN')
    skin.use_smooth_shade = True
    skin_vertices = skeleton_mesh.skin_vertices[0].data
    skin_vertices.foreach_set("radius", np.repeat(radii, 2).astype(np.float32))
    is_root = [joint.parent is None for joint in joints] + [False] * (len(radii) - len(joints))
    skin_vertices.foreach_set("use_root", is_root)
    obj.data = _applied_modifiers(obj)
    bpy.data.meshes.remove(skeleton_mesh)
    _tidy_hull(obj.data)
    if subdivisions:
        smooth = obj.modifiers.new("Subdivision", 'SUBSURF')
        smooth.levels = smooth.render_levels = subdivisions
        hull_mesh = obj.data
        obj.data = _applied_modifiers(obj)
        bpy.data.meshes.remove(hull_mesh)
    obj.data.name = name
    return obj


def _applied_modifiers(obj):
    """A new mesh of ``obj`` as evaluated, its modifiers removed from the object."""
    mesh = bpy.data.meshes.new_from_object(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()))
    obj.modifiers.clear()
    return mesh


def _tidy_hull(mesh):
    """Collapse the Skin modifier's zero-length edges, drop its loose vertices and make its faces wind consistently
    outwards, in place."""
    hull = bmesh.new()
    hull.from_mesh(mesh)
    bmesh.ops.dissolve_degenerate(hull, edges=hull.edges[:], dist=ZERO_LENGTH)
    bmesh.ops.delete(hull, geom=[vertex for vertex in hull.verts if not vertex.link_faces], context='VERTS')
    bmesh.ops.recalc_face_normals(hull, faces=hull.faces[:])
    hull.to_mesh(mesh)
    hull.free()


def character_arrays(name, subdivisions=2):
    """Vertices (N, 3) float64 and triangles (M, 3) int32 of sample character ``name``; leaves no data behind."""
    obj = build_character(name, subdivisions)
    mesh = obj.data
    try:
        return mesh_arrays(mesh)  # the object sits at the origin, unrotated: its mesh space is world space
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)
