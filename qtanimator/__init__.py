"""qtanimator: a desktop program for 2D and 3D character animation."""

__version__ = "0.1.0"
