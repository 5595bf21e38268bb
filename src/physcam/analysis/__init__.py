"""physcam.analysis"""
