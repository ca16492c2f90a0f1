"""Rigging methods, one per module; discovered at load time."""
