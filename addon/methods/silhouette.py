"""The silhouette rigging method (Pan et al. 2009, "Automatic rigging for animation characters with 3D silhouette").

Pipeline: project the mesh along the axis that shows it widest (or a chosen axis or direction), trace its silhouette,
triangulate it (CDT), take the chordal axis of the triangles, merge round blobs and prune outline-noise spurs, root
the tree at its most central branch point and cut the loops holes make, put every axis point inside the mesh in depth
(splitting chains that run through several stacked parts, and asking the perpendicular view where the primary one is
occluded), then cut the chains into bones at sharp turns and at a maximum length. Islands of the silhouette each get
their own bones, parented to the nearest bone of the largest island. Last, limbs the primary view hides behind the
body (a bird's legs under its spread wings, a fox's ears seen from the side) are taken from the trees of the two
perpendicular views (the side view, then the end-on one: along the longest extent when the view is AUTO) and hung
from the nearest bone they reach without leaving the mesh's depth span in the primary view and their own, through a
bone across the gap when that bone is far.
"""

from typing import NamedTuple

import numpy as np

from .. import cdt, silhouette
from ..core.arrays import concatenated_ranges
from ..core.graphs import components
from ..core.params import Param
from ..core.registry import RigMethod
from ..core.skeleton import Skeleton
from ..core.timing import StageClock
from ..skeletonize.bones import (bone_names, chain_joints, mirror_completed, mirror_in_depth, mirror_plane,
                                reflection_in_view, symmetric_joints)
from ..skeletonize.chordal import chordal_axis, triangle_classes
from ..skeletonize.depth import SideAxis, place_chains
from ..skeletonize.polyline import nearest_on_segments
from ..skeletonize.second_view import Cover, uncovered_limbs
from ..skeletonize.tree import chains_of, merge_discs, prune_spurs, rooted_chains

AXES = np.eye(3)
SPECK = 0.25  # islands whose axis is shorter than this many bone lengths get no bones of their own
SPREAD_SAMPLES = 100_000  # triangles sampled to choose the view
KEEP_REACH = 0.25  # branches sticking out this share of the mesh's size are kept, however wide (a cow's neck and head)
AXIS_NAMES = ("X", "Y", "Z")
MIRROR_TOLERANCE = 0.05  # chains whose ends mirror each other this close (in mesh sizes) are a left/right pair
HIDDEN_REACH = 0.6  # perpendicular-view limb tips this many bone lengths off the skeleton (seen that way) are missing
PAIRED_PRUNE = 0.55  # mirror twins sticking out more than this fraction of ``prune`` times their width are limbs
HIDDEN_PRUNE = 2 / 3  # the perpendicular views prune at this fraction of ``prune``: a limb they add must also be off
# the primary skeleton and hidden in the primary view, so they can trust stubbier branches (a fox's ears)
END_RESOLUTION = 1 / 3  # the end-on view (the remaining axis of larger spread: along the longest extent when the view
# is AUTO) only looks for limbs, at this fraction of the resolution: limbs are coarse features, and its trace costs less
MIN_VIEW_RESOLUTION = 64  # the coarsest grid any view gets
MAX_PATH_SAMPLES = 256  # points tested along a path from a hidden limb to a bone it may hang from (one per cell)
PATH_CANDIDATES = 32  # ... to each of the nearest bones, nearest first, at most this many (a path test is costly)
PATH_SLACK = 0.15  # ... and that path may leave the mesh for this many bone lengths in all (grazing its surface)
BRIDGE = 1.0  # a hidden limb starting farther than this many bone lengths from that bone is extended back to it
AXIS_SNAP = 1e-6  # view_direction components this small beside its largest are zero


class Blob(NamedTuple):
    """An island whose pruned axis is a single node (a round speck): that node's point (2D) and disc radius."""
    point: np.ndarray
    radius: float


class PlacedIsland(NamedTuple):
    """An island's chains placed in 3D (``depth.place_chains``): the root's point and (polyline, parent, widths)s."""
    root_point: np.ndarray
    chains: list


class SilhouetteMethod(RigMethod):
    """Skeleton from the chordal axis of the mesh's silhouette, centred in depth."""

    name = "silhouette"
    label = "Silhouette (Pan 2009)"
    description = "Chordal axis of the 3D silhouette, centred inside the mesh in depth"
    params = (
        Param("view", "enum", "AUTO", items=("AUTO", "X", "Y", "Z", "DIRECTION"),
              description="Projection axis; AUTO picks the axis that shows the mesh widest, DIRECTION looks "
                          "along the view direction (a model tilted off the axes, seen from its front)"),
        Param("view_direction", "vector", (0.0, 1.0, 0.0),
              description="The direction to look along when the view is DIRECTION (its length does not matter)"),
        Param("resolution", "int", 384, min=MIN_VIEW_RESOLUTION, max=8192,
              description="Silhouette grid cells along the longest side; higher keeps thinner gaps apart"),
        Param("outline_spacing", "float", 0.01, min=0.001, max=0.1,
              description="Longest outline edge fed to the triangulation, as a fraction of the silhouette size"),
        Param("min_hole", "float", 0.01, min=0.0, max=0.5,
              description="Holes in the silhouette smaller than this fraction of its area are filled "
                          "(gaps between parts), larger ones (an arm on the hip) are kept"),
        Param("merge", "float", 1.0, min=0.0, max=3.0,
              description="Blob merging: nodes within this many disc radii of a branch point join it"),
        Param("prune", "float", 1.35, min=0.0, max=5.0,
              description="Branches sticking out of their base by less than this many times their width are "
                          "dropped as bumps (unless they reach a quarter of the mesh's size); lower keeps stubbier "
                          "branches"),
        Param("min_branch", "float", 0.5, min=0.0, max=10.0,
              description="Branches sticking out less than this many bone lengths are dropped, however thin "
                          "(unless they reach a quarter of the mesh's size); raise it to leave short spikes, claws "
                          "and toes without bones"),
        Param("bone_angle", "float", 40.0, min=1.0, max=180.0,
              description="Start a new bone where a chain turns by more than this many degrees"),
        Param("bone_length", "float", 0.1, min=0.01, max=1.0,
              description="Typical bone length, as a fraction of the mesh's largest extent"),
        Param("max_chain_bones", "int", 5, min=0, max=100,
              description="Most bones per chain between branch points (0: no limit)"),
        Param("split_layers", "bool", True,
              description="Split chains whose view rays cross the mesh in separate parts (stacked legs)"),
        Param("side_view", "bool", True,
              description="Use the perpendicular silhouettes: for depth where the primary view is occluded, "
                          "and for the limbs it hides"),
    )

    def draw(self, layout, props):
        """Looking along a direction: a button takes it from the 3D view."""
        if props.view == "DIRECTION":
            layout.operator("rigger.direction_from_view", icon='VIEW_CAMERA').param = "view_direction"

    def rig(self, mesh, *, view, view_direction, resolution, outline_spacing, min_hole, merge, prune, min_branch,
            bone_angle, bone_length, max_chain_bones, split_layers, side_view):
        clock = StageClock()
        frame = None
        if view == "DIRECTION":
            frame, axis = view_frame(view_direction)
            view = AXIS_NAMES[axis]
        # rig at unit size (a power of two away: exact), in the frame where the view is an axis; then map back
        factor = mesh.unit_factor
        mesh = mesh.at_unit_size(frame)
        vertices, triangles, flat = mesh.vertices, mesh.triangles, mesh.flat_normal
        try:
            axis, (sil, tri, graph) = _primary_view(mesh, view, resolution, outline_spacing, min_hole)
        except silhouette.NoSilhouette as error:
            if frame is None:
                raise
            raise type(error)(f"along view_direction {tuple(view_direction)}: {error}") from None
        clock.lap("silhouette_cdt_axis")

        unit = bone_length * mesh.scale  # the bone length in mesh units
        reaches = (min_branch * unit, KEEP_REACH * mesh.scale)  # prune_spurs' min_reach and max_reach
        plane = mirror_plane(mesh.used_vertices, mesh.bbox, 0.01 * mesh.scale)
        tolerance = MIRROR_TOLERANCE * mesh.scale  # chains whose ends mirror this close are a pair
        graph, alive, merged, kept = _pruned_tree(graph, merge, (prune, PAIRED_PRUNE * prune), reaches,
                                                  reflection_in_view(sil, plane), local_pairs=plane is None)
        clock.lap("merge_prune")

        side, other_views = None, []  # other_views: (silhouette, chordal axis) of the perpendicular views
        if side_view and flat is None:  # a flat mesh has nothing to hide in depth
            side_axis, end_axis = sorted((a for a in range(3) if a != axis), key=lambda a: mesh.spread[a])
            side_of = _other_view(vertices, triangles, side_axis, resolution, outline_spacing, min_hole)
            end_resolution = max(MIN_VIEW_RESOLUTION, round(END_RESOLUTION * resolution))
            end_on = _other_view(vertices, triangles, end_axis, end_resolution, outline_spacing, min_hole)
            if side_of is not None:
                side_sil, side_graph = side_of
                side = SideAxis(side_sil, side_graph.points, side_graph.radius, sil)
            other_views = [found for found in (side_of, end_on) if found is not None]
        clock.lap("other_views")

        builder = _BoneBuilder(np.radians(bone_angle), unit, max_chain_bones, plane, tolerance)
        for placed in _placed_islands(sil, graph, alive, kept, SPECK * unit, side, split_layers,
                                      mirror_in_depth(sil, plane, tolerance)):
            if isinstance(placed, Blob):
                builder.add_blob(sil, placed.point, placed.radius)
            else:
                builder.add_island(placed.root_point, placed.chains)
        for view_sil, view_graph in other_views:
            limbs = _hidden_limbs(sil, view_sil, view_graph, builder.lines, merge,
                                  (HIDDEN_PRUNE * prune, PAIRED_PRUNE * prune), reaches, unit, split_layers,
                                  reflection_in_view(view_sil, plane), plane is None)
            builder.add_limbs(limbs, (sil, view_sil))
        clock.lap("depth_bones")

        heads, tails, parents = builder.arrays()
        names = builder.names()
        clock.lap("names")

        stages = {
            "silhouette": {"loops": sil.loops, "origin": sil.origin, "u": sil.u, "v": sil.v,
                           "direction": sil.direction, "depth": float((mesh.centroid - sil.origin) @ sil.direction)},
            "cdt": {"vertices": tri.vertices, "triangles": tri.triangles, "classes": triangle_classes(tri)},
            "axis": {"points": graph.points, "radius": graph.radius, "links": graph.links},
            "merged": {"links": merged},
            "pruned": {"links": _removed(merged, kept)},
            "chains": builder.lines,
            "mirror_plane": plane,
            "frame": np.eye(3) if frame is None else frame,
            "timings": clock.laps,
        }
        heads, tails = _to_world(stages, frame, factor, heads, tails)
        stages["joints"] = np.unique(np.concatenate([heads, tails]), axis=0)
        return Skeleton(names, heads, tails, parents, stages=stages)


def view_frame(direction):
    """(frame, axis) to rig along ``direction``: ``frame`` rows are orthonormal axes in world coordinates, number
    ``axis`` being the direction (signed to point along that world axis, the nearest one to it) and the others as
    near their world axes as that allows; None for the world frame when the direction is a world axis."""
    vector = np.asarray(direction, dtype=np.float64)
    axis = int(np.argmax(np.abs(vector)))
    if vector[axis] == 0:
        raise ValueError("view_direction must not be zero when the view is DIRECTION")
    vector = vector / vector[axis]  # along the nearest axis's positive end, its largest component 1 (no overflow)
    vector[np.abs(vector) < AXIS_SNAP] = 0.0  # single-precision noise (a 3D view's front): the axis itself
    frame = np.eye(3)
    frame[axis] = vector / np.linalg.norm(vector)
    for other in (a for a in range(3) if a != axis):  # Gram-Schmidt from the view direction on: right-handed
        row = np.eye(3)[other]
        for done in [axis] + [a for a in range(other) if a != axis]:
            row = row - (row @ frame[done]) * frame[done]
        frame[other] = row / np.linalg.norm(row)
    return (None if np.array_equal(frame, np.eye(3)) else frame), axis


def _to_world(stages, frame, factor, *points):
    """Map the stage data of a rig at ``factor`` times the mesh's size, in ``frame`` (rows: its axes in world
    coordinates; None for the world's), back to the world (adding ``view``, the world view direction), and return
    ``points`` (arrays of 3D points) mapped so; ``mirror_plane`` stays in the frame, whose axis it names."""
    def turned(array):
        return array if frame is None else array @ frame

    def place(array):
        return turned(array / factor)

    silhouette_stage = stages["silhouette"]
    silhouette_stage["origin"] = place(silhouette_stage["origin"])
    for key in ("u", "v", "direction"):
        silhouette_stage[key] = turned(silhouette_stage[key])
    silhouette_stage["loops"] = [loop / factor for loop in silhouette_stage["loops"]]
    silhouette_stage["depth"] /= factor
    stages["view"] = silhouette_stage["direction"]
    stages["cdt"]["vertices"] = stages["cdt"]["vertices"] / factor
    stages["axis"]["points"] = stages["axis"]["points"] / factor
    stages["axis"]["radius"] = stages["axis"]["radius"] / factor
    stages["chains"] = [place(line) for line in stages["chains"]]
    if stages["mirror_plane"] is not None:
        axis, offset = stages["mirror_plane"]
        stages["mirror_plane"] = (axis, offset / factor)
    return [place(array) for array in points]


def _pruned_tree(graph, merge, prunes, reaches, mirror=None, local_pairs=False):
    """Blob merging and spur pruning of a chordal axis, ``prunes`` and ``reaches`` being ``prune_spurs``' (prune,
    pair_prune) and (min_reach, max_reach), ``mirror`` its reflection and ``local_pairs`` whether pairs of spurs are
    judged without one (the mesh has no mirror plane); its junctions are the blobs that keep a spur ending in one.
    Returns (graph, alive nodes, merged links, kept links): with ``mirror``, the graph whose blobs near the mirror
    line are centred on it (``AxisGraph.centred_on_mirror``), the stages show and the bones follow."""
    representative, merged = merge_discs(graph.points, graph.radius, graph.junction, graph.links, merge)
    alive = np.unique(representative)
    if mirror is not None:
        graph = graph.centred_on_mirror(alive[graph.junction[alive]], mirror)
    _, chains = chains_of(alive.tolist(), merged)
    prune, pair_prune = prunes
    return graph, alive, merged, prune_spurs(graph.points, graph.radius, chains, prune, *reaches, mirror=mirror,
                                             blobs=graph.junction, pair_prune=pair_prune, local_pairs=local_pairs)


def _placed_islands(sil, graph, alive, kept, speck, side, split_layers, mirror):
    """Per island of the pruned axis, largest first: a ``PlacedIsland`` (its chains in 3D), or a ``Blob`` for an
    island that is a single node; islands other than the largest and smaller than ``speck`` are skipped (skinning
    gives them to the nearest bone). ``mirror``: see ``place_chains``."""
    for number, (nodes, links, size) in enumerate(_islands(graph, alive, kept)):
        if number and size < speck:
            continue
        keys, island_chains = chains_of(nodes, links)
        if not island_chains:
            widest = nodes[int(np.argmax(graph.radius[nodes]))]
            yield Blob(graph.points[widest], graph.radius[widest])
            continue
        root, rooted = rooted_chains(graph.points, keys, island_chains, graph.radius)
        yield PlacedIsland(*place_chains(sil, graph.points, graph.radius, root, rooted, side, split_layers, mirror))


def _other_view(vertices, triangles, axis, resolution, spacing, min_hole):
    """(silhouette, chordal axis) along another axis; None where the mesh shows nothing that way (an open tube
    seen end-on)."""
    try:
        view_sil, _, view_graph = planar_axis(vertices, triangles, AXES[axis], resolution, spacing, min_hole)
    except silhouette.NoSilhouette:
        return None
    return view_sil, view_graph


def _hidden_limbs(sil, view_sil, view_graph, lines, merge, prunes, reaches, bone_length, split_layers, mirror,
                  local_pairs):
    """Limbs the primary view hides behind the body, from a perpendicular view's pruned tree (see ``second_view``);
    the view's chains are placed in depth only when a leaf tip lies off the primary skeleton. With ``mirror`` (the
    view's ``reflection_in_view``, None when it does not look across the mirror plane) the tree is pruned as the
    primary view's is: blobs near the mirror line are centred on it, and a spur whose mirror image is kept stays, as
    do mirror pairs of stubbier ones; with ``local_pairs`` (no mirror plane), pairs of such spurs alike in size."""
    view_graph, alive, _, kept = _pruned_tree(view_graph, merge, prunes, reaches, mirror, local_pairs)
    ends, count = np.unique(kept, return_counts=True)
    tips = view_graph.points[ends[count == 1]]
    cover = Cover(lines, view_sil.direction, HIDDEN_REACH * bone_length)
    if cover.covered(view_sil.lift(tips, 0.0)).all():
        return []  # every leaf tip is on the primary skeleton: no need to place the view's chains in depth
    view_sil.share_parts(sil)  # the mesh's welded parts, found once for the primary view, give the view's layers
    limbs = []
    # placed without the plane: only the limbs off the skeleton are kept, and add_limbs completes their mirror pairs
    for placed in _placed_islands(view_sil, view_graph, alive, kept, SPECK * bone_length, None, split_layers, None):
        if isinstance(placed, PlacedIsland):
            limbs += uncovered_limbs(placed.chains, cover, sil, reaches[0])
    return limbs


def _primary_view(mesh, view, resolution, spacing, min_hole):
    """(axis, ``planar_axis`` of the primary view): along the chosen axis, or for AUTO along the first of the
    ``axes_by_spread`` that shows the mesh at all (triangles all standing edge-on to one axis show nothing along
    it); a flat mesh tilted off the axis planes is seen straight on, not edge-on."""
    if view != "AUTO":
        axis = AXIS_NAMES.index(view)
        candidates = [(axis, AXES[axis])]  # (axis, view direction), the first that shows the mesh wins
    else:
        order = axes_by_spread(mesh.vertices, mesh.triangles)
        flat = mesh.flat_normal
        if flat is not None:
            candidates = [(order[0], flat if abs(flat @ AXES[order[0]]) < 1 - 1e-9 else AXES[order[0]])]
        else:
            candidates = [(axis, AXES[axis]) for axis in order]
    first_error = None
    for axis, direction in candidates:
        try:
            return axis, planar_axis(mesh.vertices, mesh.triangles, direction, resolution, spacing, min_hole)
        except silhouette.PartsTooSmall:
            raise  # along every axis alike
        except silhouette.NoSilhouette as error:
            first_error = first_error or error
    raise first_error


def axes_by_spread(vertices, triangles):
    """The axes by how wide their projection spreads the surface, widest first: the sum of the variances of the
    other two coordinates, over triangle centroids weighted by area (so dense regions do not dominate)."""
    variances = _variances(vertices, triangles)
    return [int(a) for a in np.argsort([-(variances.sum() - variances[a]) for a in range(3)], kind="stable")]


def _variances(vertices, triangles):
    """Per-axis variance of the surface (area-weighted triangle centroids)."""
    triangles = triangles[::max(1, len(triangles) // SPREAD_SAMPLES)]  # a regular sample is plenty for a variance
    a, b, c = (np.take(vertices, triangles[:, k], axis=0) for k in range(3))  # take: far faster than indexing
    points = (a + b + c) / 3
    u, w = b - a, c - a
    weights = np.sqrt((u[:, 1] * w[:, 2] - u[:, 2] * w[:, 1]) ** 2 + (u[:, 2] * w[:, 0] - u[:, 0] * w[:, 2]) ** 2
                      + (u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]) ** 2)
    if not weights.sum() > 0:
        return points.var(axis=0)
    mean = weights @ points / weights.sum()
    return weights @ (points - mean) ** 2 / weights.sum()


def planar_axis(vertices, triangles, direction, resolution, spacing, min_hole):
    """Silhouette along ``direction``, its constrained Delaunay triangulation and the chordal axis."""
    sil = silhouette.trace(vertices, triangles, direction, resolution=resolution)
    points, segments = _outline(_without_small_holes(sil.loops, min_hole), spacing)
    tri = cdt.triangulate(points, segments, mode="inside")
    return sil, tri, chordal_axis(tri)


def _without_small_holes(loops, fraction):
    """Drop the holes (clockwise loops) smaller than ``fraction`` of the silhouette's area."""
    areas = [0.5 * float(np.sum(l[:, 0] * np.roll(l[:, 1], -1) - np.roll(l[:, 0], -1) * l[:, 1])) for l in loops]
    total = sum(a for a in areas if a > 0)
    return [l for l, a in zip(loops, areas) if a > 0 or -a >= fraction * total]


def _outline(loops, spacing):
    """Loop points and closing segments, with long edges subdivided (no point moves, so loops stay simple)."""
    everything = np.concatenate(loops)
    step = spacing * float(np.max(everything.max(axis=0) - everything.min(axis=0)))
    points, segments, offset = [], [], 0
    for loop in loops:
        nxt = np.roll(loop, -1, axis=0)
        pieces = np.maximum(1, np.ceil(np.linalg.norm(nxt - loop, axis=1) / step).astype(int))
        t = concatenated_ranges(np.zeros_like(pieces), pieces) / np.repeat(pieces, pieces)
        start = np.repeat(np.arange(len(loop)), pieces)
        dense = loop[start] + t[:, None] * (nxt[start] - loop[start])
        count = len(dense)
        points.append(dense)
        segments.append(offset + np.stack([np.arange(count), (np.arange(count) + 1) % count], axis=1))
        offset += count
    return np.concatenate(points), np.concatenate(segments)


def _islands(graph, alive, links):
    """(nodes, links, size) per island, the largest (most axis length) first."""
    result = []
    node_island = graph.island[alive]
    link_island = graph.island[links[:, 0]] if len(links) else np.zeros(0, graph.island.dtype)  # links join live nodes
    for island in np.unique(node_island):
        nodes = alive[node_island == island]
        sub = links[link_island == island]
        size = float(np.linalg.norm(graph.points[sub[:, 0]] - graph.points[sub[:, 1]], axis=1).sum())
        size += float(graph.radius[nodes].max())
        result.append((size, nodes.tolist(), sub))
    result.sort(key=lambda item: -item[0])
    return [(nodes, sub, size) for size, nodes, sub in result]


def _removed(before, after):
    kept = set(map(tuple, np.sort(after, axis=1).tolist())) if len(after) else set()
    gone = [pair for pair in np.sort(before, axis=1).tolist() if tuple(pair) not in kept]
    return np.array(gone, dtype=np.int64).reshape(-1, 2)


class _BoneBuilder:
    """Accumulates bones island by island; the first island's trunk holds the single root bone. With a mirror
    ``plane``, mirror-image chains get mirror-image joints (their average), so a symmetric mesh gets a symmetric rig."""

    def __init__(self, bone_angle, bone_length, max_bones, plane, tolerance):
        self.bone_angle, self.bone_length, self.max_bones = bone_angle, bone_length, max_bones
        self.plane, self.tolerance = plane, tolerance
        self.heads, self.tails, self.parents = [], [], []
        self.chain_of_bone, self.index_in_chain = [], []
        self.lines = []  # one polyline per chain, indexed by chain number

    def add_island(self, root_point, placed):
        """Bones along the placed chains of one island; the widest chain leaving the root becomes its trunk."""
        roots = [i for i, (_, parent, _) in enumerate(placed) if parent < 0]
        trunk = max(roots, key=lambda i: placed[i][2].mean())
        order = [trunk] + [i for i in range(len(placed)) if i != trunk]
        inner = {parent for _, parent, _ in placed}
        joints = self._joints([(line, widths, i not in inner) for i, (line, _, widths) in enumerate(placed)])
        attach, _ = self._attachment(root_point)
        last_bone, first_bone = {}, {}
        for i in order:
            line, parent, _ = placed[i]
            if parent >= 0:
                up = last_bone[parent]
            elif i == trunk:
                up = attach
            else:
                up = first_bone[trunk]
            added = self._add_chain(line, joints[i], up)
            first_bone[i], last_bone[i] = (added[0], added[-1]) if added else (up, up)

    def add_limbs(self, limbs, views):
        """Bones along extra chains, (polyline, half-widths) each, hung from the nearest bone already there that their
        start reaches within the mesh as all the silhouettes ``views`` see it (the primary one and the one the limbs
        come from); a chain starting far from that bone (a foot below a leg too stubby to show) is extended back
        along the path to it, so the leg between them gets bones of its own, and mirror pairs stay mirror pairs.
        Limbs that far from one bone whose starts, and the points where they meet the bone, all lie within half a
        bone length of each other (a pair of ears, horns on a neck) share that extension: one chain from the middle
        of those points to the middle of their starts, from which each hangs (through a bone to its own start when
        apart), instead of bones lying on each other. Which limbs share does not depend on their order, so mirror
        pairs stay mirror pairs."""
        if not limbs:
            return
        if self.plane is not None:
            limbs = mirror_completed(limbs, self.plane, self.tolerance)
        chains, ups, meets_of = [], [], {}  # meets_of: limb number -> where it meets its bone, for the limbs to extend
        for line, widths in limbs:  # every limb hangs from bones already there, none from another (a right foot
            up, meets = self._attachment(line[0], views)  # from the left one's extension, which passes nearer it)
            if meets is not None and np.linalg.norm(line[0] - meets) > BRIDGE * self.bone_length:
                meets_of[len(chains)] = meets
            chains.append((line, widths, True))
            ups.append(up)
        ends = {}  # limb number -> the bridge chain it hangs from
        for members in self._sharing(meets_of, ups, [line[0] for line, _, _ in chains]):
            meets = np.mean([meets_of[k] for k in members], axis=0)
            shared = len(members) > 1
            start = np.mean([chains[k][0][0] for k in members], axis=0) if shared else meets
            for k in members:
                line, widths, _ = chains[k]
                if np.linalg.norm(line[0] - start) > 1e-9 * self.bone_length:
                    chains[k] = (np.vstack([start, line]), np.r_[0.0, widths], True)  # 0: no disc to leave
            if shared:
                ends.update(dict.fromkeys(members, len(chains)))
                chains.append((np.vstack([meets, start]), np.zeros(2), False))
                ups.append(ups[members[0]])
        joints = self._joints(chains)
        last_bone = {}
        for c in sorted(range(len(chains)), key=lambda c: c in ends):  # bridge chains before the limbs they carry
            line, along = chains[c][0], joints[c]
            up = last_bone[ends[c]] if c in ends else ups[c]
            added = self._add_chain(line, along, up)
            last_bone[c] = added[-1] if added else up

    def _sharing(self, meets, ups, starts):
        """The limbs to extend (the keys of ``meets``, where each meets its bone) in groups that share one
        extension: linked when they hang from the same bone and their starts and meeting points each lie within half
        a bone length; a linked group is kept only when every two of its limbs are linked (else each goes alone), so
        the groups do not depend on the limbs' order."""
        reach = 0.5 * self.bone_length
        limbs = list(meets)

        def linked(a, b):
            return (ups[a] == ups[b] and np.linalg.norm(starts[a] - starts[b]) <= reach
                    and np.linalg.norm(meets[a] - meets[b]) <= reach)

        pairs = [(i, j) for i in range(len(limbs)) for j in range(i) if linked(limbs[i], limbs[j])]
        labels = components(len(limbs), np.array(pairs, dtype=np.int64).reshape(-1, 2))
        groups = []
        for label in np.unique(labels):
            members = [limbs[i] for i in np.flatnonzero(labels == label)]
            whole = all(linked(a, b) for a in members for b in members)
            groups += [members] if whole else [[k] for k in members]
        return groups

    def _joints(self, chains):
        """Joints along each of the (polyline, half-widths, is a leaf) ``chains``, mirror pairs made symmetric."""
        def joints_of(chain, max_bones, min_bones=0):
            """Joints along chain number ``chain`` (``chain_joints``), at most and at least that many bones."""
            line, widths, leaf = chains[chain]
            return chain_joints(line, self.bone_angle, self.bone_length, max_bones, widths, leaf, min_bones)

        joints = [joints_of(chain, self.max_bones) for chain in range(len(chains))]
        if self.plane is None:
            return joints
        return symmetric_joints(joints, [line for line, _, _ in chains], self.plane, self.tolerance, joints_of,
                                leaves=[leaf for _, _, leaf in chains])

    def _add_chain(self, line, joints, up):
        """Bones between consecutive ``joints`` of one chain, the first hanging from bone ``up``; returns the
        indices of the bones added (none where the joints coincide)."""
        chain = len(self.lines)
        self.lines.append(line)
        added = []
        for k in range(len(joints) - 1):
            if np.linalg.norm(joints[k + 1] - joints[k]) <= 1e-9 * self.bone_length:
                continue
            self.heads.append(joints[k])
            self.tails.append(joints[k + 1])
            self.parents.append(up)
            self.chain_of_bone.append(chain)
            self.index_in_chain.append(k)
            up = len(self.heads) - 1
            added.append(up)
        return added

    def add_blob(self, sil, point2d, radius):
        """An island whose axis is a single node (a round speck): one short bone through it, pointing up."""
        front, back = sil.depth(point2d[None])
        depth = 0.5 * (front[0] + back[0]) if not np.isnan(front[0]) else 0.0
        centre = sil.lift(point2d[None], [depth])[0]
        half = max(radius, sil.cell) * sil.v
        ends = np.array([centre - half, centre + half])
        self._add_chain(ends, ends, self._attachment(centre)[0])

    def _attachment(self, point, views=()):
        """(bone, where a path from ``point`` meets it): the bone nearest ``point``, or -1 before the first island,
        met nowhere in particular (None). With silhouettes ``views``, the nearest bone that a straight path from
        ``point`` reaches within the mesh as each of them sees it (``Silhouette.encloses``, sampled every grid cell,
        up to ``PATH_SLACK`` bone lengths outside: a path may graze the surface, but a foot beside a hanging hand
        belongs to the body, not the hand), and the point the path meets it at; the nearest bone, met nowhere (None),
        when no path to the ``PATH_CANDIDATES`` nearest stays in (a soup of triangles strewn at random has a
        thousand bones at a small ``bone_length``, and paths through it rarely stay in)."""
        if not self.heads:
            return -1, None
        targets = nearest_on_segments(point[None], np.array(self.heads), np.array(self.tails))[0]
        distance = np.linalg.norm(targets - point, axis=1)
        order = np.argsort(distance, kind="stable")
        if views:
            cell = min(view.cell for view in views)
            for bone in order[:PATH_CANDIDATES]:
                count = int(np.clip(np.ceil(distance[bone] / cell), 1, MAX_PATH_SAMPLES))
                path = point + (np.arange(1, count + 1) / (count + 1))[:, None] * (targets[bone] - point)
                outside = np.zeros(count, bool)
                for view in views:
                    outside |= ~view.encloses(path, view.cell)
                if outside.sum() * distance[bone] / (count + 1) <= PATH_SLACK * self.bone_length:
                    return int(bone), targets[bone]
        return int(order[0]), None

    def arrays(self):
        return np.array(self.heads), np.array(self.tails), np.array(self.parents, dtype=np.int64)

    def names(self):
        """The bones' names (``bone_names``), mirror-suffixed across the builder's plane."""
        return bone_names(self.chain_of_bone, self.index_in_chain, self.lines, self.plane, self.tolerance)
