"""Cable-conduit contact (paper Sects. 2.4-2.5): check points, AABB broad phase, Hertz normal force,
regularised Coulomb friction, generalized forces and their exact Jacobians.

:class:`ContactKernel` (:mod:`.kernel`) is the facade; one switch, its ``backend``, sends every call
(profiles included) to the numpy reference (:mod:`.numpy_kernel`, the tested definition) or the numba
fast path (:mod:`.fast`, the default; its per-point profiles in :mod:`.profiles`). The compiled
dynamic kernel and the steady-sliding one (:mod:`.steady`) are built from the same parts
(:mod:`.kernel_parts`). Nothing here imports Exudyn; the model layer wraps :class:`ContactKernel` in
Exudyn user functions.
"""

from .checkpoints import check_points
from .kernel import CheckPointState, ContactKernel, ContactResult, assemble_blocks_dense, block_sparsity
from .law import ContactLaw

__all__ = [
    "ContactLaw",
    "check_points",
    "ContactKernel",
    "ContactResult",
    "CheckPointState",
    "assemble_blocks_dense",
    "block_sparsity",
]
