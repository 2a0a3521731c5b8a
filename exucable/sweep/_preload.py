"""Imported once by the forkserver of the local pool, so that every case's process, forked
from it, starts with numpy, scipy, Exudyn,
numba's initialised CPU target, the kernels' cached machine code and matplotlib already loaded (about
1.7 s per case otherwise). Nothing
here *uses* Exudyn: a process is forked only from this clean, import-only state, never from one
that has run a model.
"""

try:  # a failed import only costs start-up time in the workers; it must not kill the forkserver
    import matplotlib.backends.backend_agg  # noqa: F401  (figures use their own Agg canvas)
    import exucable.contact  # noqa: F401  (numba, imported lazily by model building)
    import exucable.contact.fast  # noqa: F401
    import exucable.model.build  # noqa: F401  (and Exudyn with it)
    import exucable.plots.results  # noqa: F401
    import exucable.run  # noqa: F401
    import exucable.sweep.worker  # noqa: F401
    import exucable.contact.nearest  # noqa: F401  (the axis gauge's search)
    from numba.core.registry import cpu_target

    # numba's CPU target (its registries, numba.np.linalg and scipy.linalg for BLAS) set up once
    # here: otherwise on the first compiled call of every case, about a fifth of a second each
    cpu_target.target_context.refresh()
    # the kernels' machine code read from numba's disk cache once here, not in every case process
    from exucable.contact.jitcache import load_cached_kernels

    load_cached_kernels()
except Exception:  # pragma: no cover
    pass
