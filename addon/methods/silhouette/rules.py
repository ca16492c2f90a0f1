"""What one rig works with: the parameters and the tuning, and the lengths and rules they come to for its mesh."""
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from ...core.joints import Cutting
from ...core.mirror import Symmetry, mirror_plane
from .outline import loop_edges, without_small_holes
from .tree import Pruning
from .views import reflection_in_view


@dataclass(frozen=True)
class Rules:
    """One rig's settings: the method's ``params`` (by attribute), its ``tuning``, the mesh's ``size`` and bone
    length (``unit``, both in mesh units), and its mirror plane (``plane``: (axis, offset), or None)."""

    params: SimpleNamespace
    tuning: object
    size: float
    unit: float
    plane: tuple

    @classmethod
    def of(cls, mesh, params, tuning):
        """The rules for ``mesh`` (at the size the method works at)."""
        plane = mirror_plane(mesh.used_vertices, mesh.bbox, tuning.plane_match * mesh.scale, tuning)
        return cls(params, tuning, mesh.scale, params.bone_length * mesh.scale, plane)

    @property
    def symmetry(self):
        """How chains twin across the mirror plane (None without one)."""
        if self.plane is None:
            return None
        return Symmetry(self.plane, self.tuning.twin_tolerance * self.size, self.tuning,
                        self.tuning.side_share * self.size)

    @property
    def cutting(self):
        """How chains are cut into bones."""
        return Cutting(np.radians(self.params.bone_angle), self.unit, self.params.max_chain_bones, self.tuning)

    def pruning(self, sil, prune, heads=False):
        """Spur pruning in view ``sil`` at ``prune`` times a branch's width: the primary view's is the ``prune``
        parameter and keeps ``heads`` (``Pruning.heads``), the perpendicular views' ``hidden_prune`` of it."""
        corners = np.concatenate(sil.loops)
        ground = (corners.min(axis=0), corners.max(axis=0), self.tuning.ground_reach * self.size)
        triangulated = without_small_holes(sil.loops, self.params.min_hole)  # the loops the axis was made from
        return Pruning(prune, min_reach=self.params.min_branch * self.unit,
                       max_reach=self.tuning.keep_reach * self.size,
                       pair_prune=self.tuning.pair_prune * self.params.prune,
                       mirror=reflection_in_view(sil, self.plane, self.tuning), local_pairs=self.plane is None,
                       ground=ground, heads=heads, outline=loop_edges(triangulated), tuning=self.tuning)
