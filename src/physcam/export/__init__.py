"""physcam.export"""
