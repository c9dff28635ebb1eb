"""sgtool: language-grounded interactive object search on 3D scene graphs, built around logs."""

__version__ = "0.1.0"
