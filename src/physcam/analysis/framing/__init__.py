"""Framing: the field of view from real chief rays, focus breathing (real rays and its plot) and a zoom
lens's breathing and parfocality figure."""
