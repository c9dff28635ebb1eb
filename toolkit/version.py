"""The sgtool version: one string, importable from the core without the public facade.

Core modules (the log writer, the benchmark, the CLI) import it from here; the facade
``sgtool`` re-exports it as ``sgtool.__version__``.
"""

__version__ = "0.1.0"
