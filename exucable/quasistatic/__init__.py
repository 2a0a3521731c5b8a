"""Exudyn-free quasi-static models of a cable in a conduit, the references exucable is checked against.

``rope`` (the centreline rope equation), ``clearance`` (the rope free in its clearance), ``beam``
(a stiff cable in the conduit, nonlinear: planar or 3D chains, the gravity terms on horizontal and
vertical bends), ``stiff_bend`` (the analytic bend-end point loads), ``closed_forms`` (exact rope tensions),
``extent`` (references at the cable's current extent), ``engineering`` (the calculators' formulas for
several cables in a duct and the pull limits).
"""
