from pathlib import Path


# Copies of ../shared/reference/lenses (see SOURCES.md there), so CI needs nothing beside the checkout.
REFERENCE = Path(__file__).resolve().parents[1] / "data" / "reference_lenses"
PBRT_FILES = sorted((REFERENCE / "pbrt-dat").glob("*.dat"))
ISET_FILES = sorted((REFERENCE / "iset-json").glob("*.json"))
SEED_FILES = sorted((REFERENCE / "physical-camera-toml").glob("*.toml"))
# The six shared seed-TOML files that do not describe a buildable lens as published
# (see docs/lens-formats.md, "Corrections"): they must be refused, and the library fixes them.
SEED_INVALID = {
    "canon_rf_85mm_f1_2.toml", "cooke_triplet_50mm_f4_5.toml", "neil_front_anamorphic_2x.toml",
    "nikkor_fisheye_16mm_f2_8.toml", "tessar_50mm_f2_8.toml", "zuiko_18mm_f3_5.toml",
}
SEED_VALID = [f for f in SEED_FILES if f.name not in SEED_INVALID]


