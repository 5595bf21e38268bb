"""physcam.onset"""
