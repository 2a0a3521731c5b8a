"""Figures (matplotlib, Agg backend; files written atomically)."""
