"""The bpy-free core every entry point shares.

- ``mesh``: :class:`Mesh`, the validated input (``triangulate_polygons`` for polygon faces).
- ``skeleton``: :class:`Skeleton`, the validated output tree plus the method's intermediate ``stages``.
- ``params``: :class:`Param` declarations and ``resolve``, shared by the UI, the CLI and the API.
- ``registry``: the :class:`RigMethod` base class and ``discover`` of the methods folder, isolating broken methods.
"""
