"""physcam.live: OpenTrackIO camera tracking in and out (docs/live.md).

Modules: ``protocol`` (packets: header, Fletcher-16, segmentation), ``sample`` (JSON/CBOR samples
validated against the shipped 1.0.1 schema), ``frames`` (a sample in physcam's units and back),
``lens_data`` (distortion in OpenTrackIO's millimetre form), ``camera`` (samples from physcam's
camera and lens), ``receiver`` and ``sender`` (UDP), ``record`` (time-sampled USD and the per-frame
lens report), ``usd_io`` (frames read back from a PhysicalCamera), ``frustum`` (the LED wall's inner
frustum). Layer 8.5: above ``usd`` (whose authoring it uses), below ``cli``.

The 'live' extra (jsonschema, fastjsonschema, cbor2) is needed where samples are validated or carried as CBOR
(:mod:`physcam.live.sample`, which says so in one line); the rest (frames, lens data, the per-frame
lens report) runs in the core, so ``physcam metadata report`` does not need it.
"""
