"""Exporters: translate physcam's optics into renderer and pipeline parameters.

Exporters convert units and parameterisations; they do not compute optics.
"""
