"""The version of exucable: one place (pyproject.toml reads it, exucable.__version__ re-exports it)."""

__version__ = "0.1.0"
