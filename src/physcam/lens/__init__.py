"""Lens prescriptions: the model, its file formats and the bundled library."""

from .prescription import AIR, Focus, LensMetadata, Medium, Prescription, Surface, VariableGap

__all__ = ["AIR", "Focus", "LensMetadata", "Medium", "Prescription", "Surface", "VariableGap"]
