"""The Exudyn side of exucable: cable elements, pulling rig, contact coupling, assembly.

Only this package imports :mod:`exudyn`; geometry, contact kernel, rope and post-processing
stay engine-free.
"""
