"""The Exudyn side of exucable: cable elements, pulling rig, contact coupling, assembly.

Only this package and :mod:`exucable.solve.dynamic` import :mod:`exudyn` (``tests/test_architecture.py``
checks it); geometry, contact kernel, rope and post-processing stay engine-free.
"""
