"""Rigger's Blender layer: everything that needs ``bpy`` lives in this package, so ``import rigger`` never does."""
