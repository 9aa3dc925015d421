"""Commands registered on the gyrocal app (placeholder until filled in)."""

from .app import app  # noqa: F401
