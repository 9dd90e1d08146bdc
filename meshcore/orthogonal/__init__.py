"""Orthogonal grids with shore nodes that slide (see :mod:`.driver`)."""

from .driver import OrthoResult, orthogonalize

__all__ = ["OrthoResult", "orthogonalize"]
