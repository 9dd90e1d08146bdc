"""gcmesh desktop app: draw or import a boundary, assign borders, watch the solver, export.

Nothing heavy is imported here; run ``python -m app`` (or ``gcmesh``).
"""
