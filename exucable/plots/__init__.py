"""Figures drawn from data: each function takes values (no solver, no file reading) and saves a
:class:`matplotlib.figure.Figure` with :func:`exucable.io.save_figure` (atomic; no pyplot, no
backend switch). Modules here import nothing above them but :mod:`exucable.io` and
:mod:`exucable.data.reference_values`."""
