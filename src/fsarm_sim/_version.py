"""The package version (one place; ``fsarm_sim.__version__`` re-exports it)."""

__version__ = "0.8.0"
