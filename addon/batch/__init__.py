"""``python -m rigger batch``: rig a library of model files, on this machine's processes or on a Ray cluster.

``inputs`` finds the files lazily and names their results, ``driver`` streams them through an engine with a bounded
number in flight (resume, retries, progress, the summary), ``local`` and ``ray_engine`` are the two engines, ``work``
the per-file work both run in a Blender process. Nothing here imports bpy or ray until an engine needs it.
"""


class BatchError(Exception):
    """A batch that cannot run (bad INPUTS, no model files, no Ray, a worker that cannot start): one line for the
    user."""
