"""The physcam Blender extension's shader variants: one OSL source per lens in the zip
(``shaders/<slug>.osl``), four shaders in Blender (dispersion off/on x Fresnel off/on).

The source (:func:`physcam.export.blender_focus.focus_table_shader` with ``dispersion=None,
fresnel=None``) holds what the four need, the settings' parts in ``#ifdef PHYSCAM_DISPERSION`` and
``#ifdef PHYSCAM_FRESNEL`` blocks; a variant is the source with its ``#define`` lines in front, so
OSL's preprocessor keeps the code the variant runs (the shader physcam wrote per variant before,
four times the zip's size). The add-on embeds a variant in the .blend as a text named
:func:`variant_text_name`, the name the extension's four-shader zips gave it (.blend files saved with
them keep their texts).

Plain Python, no physcam, no Blender: the zip carries this file as ``shader_variant.py``, and the
add-on imports it there.
"""

__all__ = ["SWITCHES", "variant_source", "variant_text_name"]

#: The preprocessor names of dispersion and Fresnel, defined (as 1) in front of the source when on.
SWITCHES = ("PHYSCAM_DISPERSION", "PHYSCAM_FRESNEL")


def variant_text_name(slug: str, dispersion: bool, fresnel: bool) -> str:
    """The Blender text holding the lens ``slug``'s variant: ``physcam_<slug>__d<0|1>f<0|1>.osl``."""
    return f"physcam_{slug}__d{int(bool(dispersion))}f{int(bool(fresnel))}.osl"


def variant_source(source: str, *, dispersion: bool, fresnel: bool) -> str:
    """The variant's shader: a comment naming it, the ``#define`` lines of the settings that are on
    (:data:`SWITCHES`), then ``source``."""
    on = [name for name, want in zip(SWITCHES, (dispersion, fresnel)) if want]
    head = [f"// physcam shader variant: dispersion {'on' if dispersion else 'off'}, "
            f"Fresnel {'on' if fresnel else 'off'} (the lens's one source follows)"]
    return "\n".join(head + [f"#define {name} 1" for name in on]) + "\n" + source
