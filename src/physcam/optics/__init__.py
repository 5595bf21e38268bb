"""physcam.optics"""
