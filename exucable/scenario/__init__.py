"""The scenario: one definition of a simulation, validated, with defaults and units.

``fields`` is the one key table (units, defaults, rules, docs); ``specs`` the dataclasses a file or a
script fills; ``units`` reads SI, imperial and ``"value unit"`` strings; ``mesh`` the element rule;
``dotted`` reads and sets ``"table.key"`` names for overrides and sweeps.
"""
