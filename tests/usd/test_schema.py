"""The checked-in plugin is what usd-core's usdGenSchema makes of schema.usda; names follow USD rules."""

import subprocess
import sys
from pathlib import Path

from pxr import Usd

ROOT = Path(__file__).resolve().parents[2]


def test_generated_plugin_is_current():
    res = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen_usd_schema.py"), "--check"],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stdout + res.stderr


def test_schema_kinds_and_names():
    reg = Usd.SchemaRegistry
    for api in ("PhysicalCameraSensorAPI", "PhysicalCameraLensAPI"):
        t = reg.GetTypeFromSchemaTypeName(api)
        assert reg.IsMultipleApplyAPISchema(t)
    assert reg().FindConcretePrimDefinition("PhysicalCamera")
    assert reg.IsAbstract(reg.GetTypeFromSchemaTypeName("PhysicalCameraLensModel"))
    # seed 001 fixes: camelCase, uint, f-stop default f/8 on a 50 mm lens -> 6.25 mm iris
    d = reg().FindAppliedAPIPrimDefinition("PhysicalCameraLensAPI")
    names = d.GetPropertyNames()
    assert "lens:__INSTANCE_NAME__:shutterBlades" in names and "lens:__INSTANCE_NAME__:apertureDistance" in names
    assert d.GetSchemaAttributeSpec("lens:__INSTANCE_NAME__:shutterBlades").typeName.cppTypeName == "unsigned int"
    assert d.GetAttributeFallbackValue("lens:__INSTANCE_NAME__:iris") == 50.0 / 8.0
    assert not any("_" in n.split(":")[-1] for n in names)
