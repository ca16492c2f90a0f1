"""Skeleton extraction building blocks: chordal axis, tree surgery, depth placement, bones (bpy-free)."""
