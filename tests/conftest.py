"""Test-session set-up shared by every test module."""

# USD builds its schema registry once per process: register physcam's PhysicalCamera plugin
# before any test (in any xdist worker, in any order) creates a stage.
import physcam.usd  # noqa: F401  (registers the PhysicalCamera plugin on import)
