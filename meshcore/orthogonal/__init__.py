"""Orthogonal grids with shore nodes that slide (see :mod:`.driver`)."""

from .driver import OrthoResult, iterate_orthogonalize, orthogonalize

__all__ = ["OrthoResult", "iterate_orthogonalize", "orthogonalize"]
