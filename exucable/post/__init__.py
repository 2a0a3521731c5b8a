"""Post-processing of a cable state: tension (paper Eq. 24), sidewall pressure, trust gauges and
mesh convergence. Pure numpy; no Exudyn, no scenario objects."""
