"""Template for a rigging method: copy this file to ``methods/<your_method>.py``, rename the class and its ``name``.

Every module in ``methods/`` whose file name does not start with ``_`` is imported when the add-on loads (this one
is skipped for its underscore), and each ``RigMethod`` subclass it defines becomes a method. From its ``params``
Rigger generates the Blender properties and panel widgets, the CLI's ``--set key=value`` options and the keyword
arguments of ``rigger.rig_mesh``; a module that fails to import is reported in the panel and skipped.

A method never imports bpy: it receives a validated :class:`~rigger.core.mesh.Mesh` (world space, float64
vertices, int32 triangles) and returns a :class:`~rigger.core.skeleton.Skeleton`, so it runs and is tested outside
Blender::

    import rigger
    skeleton = rigger.rig_mesh(vertices, triangles, method="template", bones=4)

This example lays a chain of bones along the mesh's main axis; replace ``rig`` with your algorithm.
"""

import numpy as np

# Import the add-on relatively: inside Blender the package may be named e.g. "bl_ext.user_default.rigger".
from ..core.params import Param
from ..core.registry import RigMethod
from ..core.skeleton import Skeleton
from ..core.timing import StageClock

AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


class TemplateMethod(RigMethod):
    """A chain of equal bones through the centroid along the principal axis (or a chosen one)."""

    name = "template"  # unique; what `rig_mesh(method=...)` and `--method` take
    label = "Template"  # shown in the method dropdown
    description = "A chain of bones along the main axis of the mesh"
    params = (
        Param("bones", "int", 3, min=1, max=64, description="Number of bones in the chain"),
        Param("axis", "enum", "AUTO", items=("AUTO", "X", "Y", "Z"),
              description="Axis of the chain: AUTO follows the largest spread of the vertices"),
    )

    def rig(self, mesh, *, bones, axis):
        """Every declared parameter arrives as a keyword, coerced and range-checked."""
        clock = StageClock()  # seconds per stage, for stages["timings"]
        centred = mesh.vertices - mesh.centroid
        if axis == "AUTO":
            direction = np.linalg.svd(centred, full_matrices=False)[2][0]
        else:
            direction = np.array(AXES[axis])
        clock.lap("axis")

        along = centred @ direction
        cuts = np.linspace(along.min(), along.max(), bones + 1)
        points = mesh.centroid + cuts[:, None] * direction
        clock.lap("chain")

        # Stages: every intermediate result, keyed by name, for the overlays, reports and debugging.
        stages = {"principal_axis": direction, "timings": clock.laps}
        return Skeleton(
            names=[f"chain.{i:03d}" for i in range(bones)],
            heads=points[:-1],
            tails=points[1:],
            parents=np.arange(bones) - 1,  # each bone hangs from the previous one; the first is the root
            stages=stages,
        )

    def draw(self, layout, props):
        """Optional: extra Blender UI below the generated widgets (``props`` has one property per param)."""
        layout.label(text=f"{props.bones} bones along {props.axis}")
