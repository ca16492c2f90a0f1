"""Per-step timings, as methods report them in ``Skeleton.timings`` and the Blender pipeline in its result."""
import time


class StageClock:
    """Seconds spent in each named stage: ``lap(name)`` records the time since the previous lap (or the start)."""

    def __init__(self):
        self.laps = {}
        self._last = time.perf_counter()

    def lap(self, name):
        now = time.perf_counter()
        self.laps[name] = now - self._last
        self._last = now
