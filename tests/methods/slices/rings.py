"""A stage type of the test method's own: circles around an axis, drawn as lines."""
import dataclasses

import numpy as np

from rigger.core.stages import Lines, Stage

SIDES = 16  # segments per drawn circle


@dataclasses.dataclass(frozen=True)
class Rings(Stage):
    """Circles of ``radii`` (R,) around ``centres`` (R, 3), perpendicular to world axis ``axis``."""

    centres: np.ndarray
    radii: np.ndarray
    axis: int

    label = "Slab Rings"
    colour = (0.9, 0.3, 0.9)

    def __post_init__(self):
        if np.shape(self.centres) != (len(self.radii), 3) or not np.isfinite(self.radii).all():
            raise ValueError("Rings: one centre (3D) and one finite radius per ring")

    def drawing(self):
        turn = np.linspace(0.0, 2 * np.pi, SIDES, endpoint=False)
        across = np.delete(np.eye(3), self.axis, axis=0)
        circle = np.cos(turn)[:, None] * across[0] + np.sin(turn)[:, None] * across[1]
        points = (self.centres[:, None] + self.radii[:, None, None] * circle[None]).reshape(-1, 3)
        ring = np.stack([np.arange(SIDES), (np.arange(SIDES) + 1) % SIDES], axis=1)
        edges = (np.arange(len(self.radii))[:, None, None] * SIDES + ring[None]).reshape(-1, 2)
        return Lines(points, edges)
