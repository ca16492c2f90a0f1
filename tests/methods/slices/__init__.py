"""A test-only method written as a package, with a stage type of its own: the mesh cut into slabs along its main
axis, a bone through each slab's centre, and each slab's outline ring as a ``Rings`` stage. It shows that a new
method's stages get overlays, toggles included, without a line of the Blender layer knowing them."""
import numpy as np

from rigger.core.params import Param
from rigger.core.registry import RigMethod
from rigger.core.skeleton import Skeleton
from rigger.core.stages import Joints

from .rings import Rings
from .slabs import slab_centres, slab_rings


class SlicesMethod(RigMethod):
    name = "slices"
    label = "Slices (test)"
    description = "A chain through the centres of slabs cut along the main axis"
    params = (Param("slabs", "int", 4, min=2, max=32, description="How many slabs"),)

    def rig(self, mesh, *, slabs):
        axis = int(np.argmax(mesh.bbox[1] - mesh.bbox[0]))
        centres, members = slab_centres(mesh.used_vertices, axis, slabs)
        stages = {"rings": Rings(*slab_rings(mesh.used_vertices, centres, members, axis)), "centres": Joints(centres)}
        return Skeleton([f"slab.{i:02d}" for i in range(slabs - 1)], centres[:-1], centres[1:],
                        np.arange(slabs - 1) - 1, stages=stages)
