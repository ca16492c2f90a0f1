"""Blender mesh objects as the arrays the bpy-free core takes: the evaluated mesh (modifiers applied) in world space."""
import bpy
import numpy as np


def evaluated_arrays(obj, depsgraph=None):
    """Vertices (N, 3) float64 in world space and triangles (M, 3) int32 of ``obj`` as the viewport shows it.

    Modifiers and shape keys are applied and the object's world matrix (parents included) maps the vertices, so the
    skeleton lands where the user sees the mesh. ValueError for anything that is not a mesh object with faces.
    """
    vertices, triangles = _evaluated(obj, depsgraph, mesh_arrays)
    if not len(triangles):
        raise ValueError(f"mesh {obj.name!r} has no faces to rig")
    return vertices, triangles


def evaluated_vertices(obj, depsgraph=None):
    """The world-space vertices (N, 3) float64 of ``evaluated_arrays``, without triangulating (cheap)."""
    return _evaluated(obj, depsgraph, lambda mesh: (mesh_vertices(mesh), None))[0]


def _evaluated(obj, depsgraph, read):
    """(world vertices, what else ``read`` gives) of mesh object ``obj`` as evaluated: ``read(mesh)`` gives
    (vertices in the mesh's space, anything)."""
    if not isinstance(obj, bpy.types.Object):
        raise ValueError(f"expected a mesh object, got {type(obj).__name__}")
    if obj.type != 'MESH':
        raise ValueError(f"{obj.name!r} is a {obj.type.lower()} object, not a mesh")
    depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    try:
        vertices, other = read(evaluated.to_mesh())
    finally:
        evaluated.to_mesh_clear()
    return world_points(vertices, evaluated.matrix_world), other


def mesh_vertices(mesh):
    """Vertices (N, 3) float64 of mesh data ``mesh`` in its own space (no triangulation: cheap)."""
    vertices = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
    mesh.vertices.foreach_get("co", vertices)
    return vertices.reshape(-1, 3)


def mesh_arrays(mesh):
    """Vertices (N, 3) float64 in the mesh's own space and triangles (M, 3) int32 of mesh data ``mesh``."""
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return mesh_vertices(mesh), triangles.reshape(-1, 3)


def world_points(points, matrix_world):
    """(..., 3) ``points`` mapped by an object's 4x4 ``matrix_world`` (a mathutils Matrix or an array)."""
    world = np.array(matrix_world, dtype=np.float64)
    return points @ world[:3, :3].T + world[:3, 3]


def combined_arrays(objects, depsgraph=None):
    """The evaluated world-space meshes of several objects as one vertex/triangle array pair (a character made of
    parts is rigged as a whole)."""
    if not objects:
        raise ValueError("no mesh objects to rig")
    depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
    parts = [evaluated_arrays(obj, depsgraph) for obj in objects]
    offsets = np.cumsum([0] + [len(vertices) for vertices, _ in parts[:-1]])
    vertices = np.concatenate([vertices for vertices, _ in parts])
    triangles = np.concatenate([triangles + offset for (_, triangles), offset in zip(parts, offsets)])
    return vertices, triangles.astype(np.int32)
