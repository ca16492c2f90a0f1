"""The silhouette rigging method (Pan et al. 2009, "Automatic rigging for animation characters with 3D silhouette").

Project the mesh along the axis that shows it widest (``views``), trace and triangulate its outline (``outline``),
take the chordal axis (``chordal``), merge round blobs and prune spurs, root the tree (``tree``), put every axis
point inside the mesh in depth (``depth``), cut the chains into bones (``bones``), and add the limbs the primary
view hides from the perpendicular views (``second_view``). Every tuned number is in ``tuning``.
"""
from types import SimpleNamespace

import numpy as np

from ... import silhouette
from ...core.mirror import sided_symmetry
from ...core.naming import in_name_order
from ...core.params import Param
from ...core.registry import RigMethod
from ...core.skeleton import Skeleton
from ...core.stages import (AxisGraph, Chains, Frame, Joints, MergedAxis, MirrorPlane, Outline, Placement,
                            PrunedBranches, Triangulation)
from ...core.timing import StageClock
from .bones import BoneBuilder
from .depth import Blob, Placing, SideAxis, placed_islands
from .rules import Rules
from .second_view import HiddenLimbs
from .tree import pruned_tree, removed_links
from .tuning import Tuning
from .views import AXIS_NAMES, mirror_in_depth, perpendicular_views, primary_view, view_frame

TUNING = Tuning()


class SilhouetteMethod(RigMethod):
    """Skeleton from the chordal axis of the mesh's silhouette, centred in depth."""

    name = "silhouette"
    label = "Silhouette (Pan 2009)"
    description = "Chordal axis of the 3D silhouette, centred inside the mesh in depth"
    tuning_type = Tuning
    params = (
        Param("view", "enum", "AUTO", items=("AUTO", "X", "Y", "Z", "DIRECTION"),
              description="Projection axis; AUTO picks the axis that shows the mesh widest, DIRECTION looks "
                          "along the view direction (a model tilted off the axes, seen from its front)"),
        Param("view_direction", "vector", (0.0, 1.0, 0.0),
              description="The direction to look along when the view is DIRECTION (its length does not matter)"),
        Param("resolution", "int", 384, min=TUNING.min_view_resolution, max=8192,
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
                          "bumps, not limbs; lower keeps stubbier branches"),
        Param("min_branch", "float", 0.5, min=0.0, max=10.0,
              description="Branches sticking out less than this many bone lengths get no bones, however thin; "
                          "raise it to leave short spikes, claws and toes without bones"),
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

    def rig(self, mesh, **values):
        params, tuning = SimpleNamespace(**values), self.tuning
        clock = StageClock()
        rotation, view = None, params.view
        if view == "DIRECTION":
            rotation, axis = view_frame(params.view_direction, tuning)
            view = AXIS_NAMES[axis]
        # rig at unit size (a power of two away: exact), in the frame where the view is an axis; then map back
        placement = Placement(mesh.unit_factor, rotation)
        mesh = mesh.at_unit_size(rotation)
        # the silhouettes see pieces that abut as the one solid they bound; the rules see the mesh as it is
        traced = mesh.with_vertices(silhouette.sealed(mesh.vertices, mesh.triangles))
        try:
            axis, primary = primary_view(traced, view, params, tuning)
        except silhouette.NoSilhouette as error:
            if rotation is None:
                raise
            raise type(error)(f"along view_direction {tuple(params.view_direction)}: {error}") from None
        sil = primary.sil
        clock.lap("silhouette_cdt_axis")

        rules = Rules.of(mesh, params, tuning)
        pruning = rules.pruning(sil, params.prune, heads=True)
        graph, alive, merged, kept = pruned_tree(primary.axis_graph, params.merge, pruning)
        clock.lap("merge_prune")

        side, other_views = None, []  # side: the side view's axis, for depth where the primary view is occluded
        if params.side_view and mesh.flat_normal is None:  # a flat mesh has nothing to hide in depth
            side_of, end_on = perpendicular_views(traced, axis, params, tuning)
            if side_of is not None:
                side = SideAxis(side_of.sil, side_of.axis_graph.points, side_of.axis_graph.radius, sil)
            other_views = [found for found in (side_of, end_on) if found is not None]
        clock.lap("other_views")

        mirror = None if rules.plane is None else mirror_in_depth(sil, rules.plane, rules.symmetry.tolerance, tuning)
        placing = Placing(tuning, speck=tuning.speck * rules.unit, side_axis=side, split=params.split_layers,
                          mirror=mirror)
        islands = list(placed_islands(sil, graph, alive, kept, placing))
        hidden = [HiddenLimbs(sil, view, rules) for view in other_views]
        builder = _bones(sil, islands, hidden, rules, rules.symmetry)
        sides = rules.symmetry
        if sides is None:  # a body with a left and a right that is no exact mirror image: twins get one bone count
            sides = sided_symmetry(mesh.used_vertices, mesh.bbox, mesh.scale, builder.lines, tuning)
            if sides is not None:
                builder = _bones(sil, islands, hidden, rules, sides)
        clock.lap("depth_bones")

        names, heads, tails, parents = in_name_order(builder.names(), *builder.arrays())
        clock.lap("names")

        view_frame_stage = Frame(sil.origin, sil.u, sil.v, sil.direction,
                                 float((mesh.centroid - sil.origin) @ sil.direction), np.eye(3))
        stages = {
            "frame": view_frame_stage,
            "silhouette": Outline(view_frame_stage, sil.loops),
            "cdt": Triangulation(view_frame_stage, primary.triangulation.vertices, primary.triangulation.triangles,
                                 primary.classes),
            "axis": AxisGraph(view_frame_stage, graph.points, graph.radius, graph.links),
            "merged": MergedAxis(view_frame_stage, graph.points, graph.radius, merged),
            "pruned": PrunedBranches(view_frame_stage, graph.points, graph.radius, removed_links(merged, kept)),
            "chains": Chains(builder.lines),
        }
        if sides is not None:
            axis, offset = sides.twin_plane
            stages["mirror_plane"] = MirrorPlane(axis, offset, np.eye(3)[axis], sides.exact)
        stages = {name: stage.mapped(placement) for name, stage in stages.items()}
        heads, tails = placement.point(heads), placement.point(tails)
        stages["joints"] = Joints(np.unique(np.concatenate([heads, tails]), axis=0))
        return Skeleton(names, heads, tails, parents, stages=stages, timings=clock.laps)


def _bones(sil, islands, hidden, rules, symmetry):
    """A ``BoneBuilder`` with the bones of the placed ``islands`` (``Blob`` or ``PlacedIsland`` each) and of the limbs
    the other views find hidden (``hidden``: a ``HiddenLimbs`` each), twins across ``symmetry``."""
    builder = BoneBuilder(rules.cutting, symmetry, rules.tuning)
    for placed in islands:
        if isinstance(placed, Blob):
            builder.add_blob(sil, placed.point, placed.radius)
        else:
            builder.add_island(placed.root_point, placed.chains, sil)
    for limbs in hidden:
        builder.add_limbs(limbs.limbs(builder.lines), (sil, limbs.view.sil))
    return builder
