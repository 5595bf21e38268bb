"""physcam.trace"""
