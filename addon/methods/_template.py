"""Template for a rigging method: copy this file to ``methods/<your_method>.py``, rename the class and its ``name``.

Every module in ``methods/`` whose name does not start with ``_`` is imported when the add-on loads (this one is
skipped for its underscore), and each ``RigMethod`` subclass it defines becomes a method. A method that outgrows one
file becomes a package, ``methods/<your_method>/`` with the class in its ``__init__.py`` and one module per job
(``methods/silhouette/`` is one). From ``params`` Rigger generates the Blender properties and panel widgets, the
CLI's ``--set key=value`` options and the keyword arguments of ``rigger.rig_mesh``; a method that fails to import is
reported in the panel and skipped.

A method never imports bpy: it receives a validated :class:`~rigger.core.mesh.Mesh` (world space, float64
vertices, int32 triangles) and returns a :class:`~rigger.core.skeleton.Skeleton`, so it runs and is tested outside
Blender::

    import rigger
    skeleton = rigger.rig_mesh(vertices, triangles, method="template", bones=4)

Every intermediate result goes into the skeleton's ``stages`` as a ``rigger.core.stages`` type (or a subclass of
``Stage`` of your own that says how it is drawn): the overlays draw each one, with a toggle in the panel. Tuned
numbers go into a tuning table (``rigger.core.tuning``), so tests and benchmarks can change them by name::

    rigger.rig_mesh(vertices, triangles, method=TemplateMethod(tuning={"margin": 0.1}))

This example lays a chain of bones along the mesh's main axis; replace ``rig`` with your algorithm.
"""
from dataclasses import dataclass

import numpy as np

# Import the add-on relatively: inside Blender the package may be named e.g. "bl_ext.user_default.rigger".
from ..core.params import Param
from ..core.registry import RigMethod
from ..core.skeleton import Skeleton
from ..core.stages import Chains, Joints
from ..core.timing import StageClock
from ..core.tuning import TuningTable, tuned

AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class TemplateTuning(TuningTable):
    """Every tuned number of the method, each with its reason."""

    margin: float = tuned(0.0, "the chain stops this share of the mesh's extent short of each end")


class TemplateMethod(RigMethod):
    """A chain of equal bones through the centroid along the principal axis (or a chosen one)."""

    name = "template"  # unique; what `rig_mesh(method=...)` and `--method` take
    label = "Template"  # shown in the method dropdown
    description = "A chain of bones along the main axis of the mesh"
    tuning_type = TemplateTuning  # self.tuning holds the table a run uses
    params = (
        Param("bones", "int", 3, min=1, max=64, description="Number of bones in the chain"),
        Param("axis", "enum", "AUTO", items=("AUTO", "X", "Y", "Z"),
              description="Axis of the chain: AUTO follows the largest spread of the vertices"),
    )

    def rig(self, mesh, *, bones, axis):
        """Every declared parameter arrives as a keyword, coerced and range-checked."""
        clock = StageClock()  # seconds per step, for the skeleton's timings
        centred = mesh.vertices - mesh.centroid
        if axis == "AUTO":
            direction = np.linalg.svd(centred, full_matrices=False)[2][0]
        else:
            direction = np.array(AXES[axis])
        clock.lap("axis")

        along = centred @ direction
        low, high = along.min(), along.max()
        margin = self.tuning.margin * (high - low)
        cuts = np.linspace(low + margin, high - margin, bones + 1)
        points = mesh.centroid + cuts[:, None] * direction
        clock.lap("chain")

        # Stages: every intermediate result, by name, for the overlays, reports and debugging.
        ends = mesh.centroid + np.array([low, high])[:, None] * direction
        stages = {"principal_axis": Chains([ends]), "joints": Joints(points)}
        return Skeleton(
            names=[f"chain.{i:03d}" for i in range(bones)],
            heads=points[:-1],
            tails=points[1:],
            parents=np.arange(bones) - 1,  # each bone hangs from the previous one; the first is the root
            stages=stages,
            timings=clock.laps,
        )

    def draw(self, layout, props):
        """Optional: extra Blender UI below the generated widgets (``props`` has one property per param)."""
        layout.label(text=f"{props.bones} bones along {props.axis}")
