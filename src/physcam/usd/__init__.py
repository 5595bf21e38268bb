"""physcam.usd"""
