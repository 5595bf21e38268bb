"""Test-session set-up shared by every test module."""

from hypothesis import HealthCheck, settings

# USD builds its schema registry once per process: register physcam's PhysicalCamera plugin
# before any test (in any xdist worker, in any order) creates a stage.
import physcam.usd  # noqa: F401  (registers the PhysicalCamera plugin on import)

# CI machines are small and shared: no per-example deadline (a JIT compile or a loaded core must
# not fail a property), and a fixed derandomised run so CI results repeat.
settings.register_profile("physcam", deadline=None, suppress_health_check=[HealthCheck.too_slow],
                          derandomize=True)
settings.load_profile("physcam")
