"""What a lens is, on a page: the lens diagram, the lens card (one printed page per lens, like a maker's
data sheet) and the ray-traced probes of ``physcam lens check`` (docs/lens-card.md)."""
