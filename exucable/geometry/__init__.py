"""Conduit geometry (pure numpy; nothing here knows of Exudyn).

A conduit is an inner radius plus a smooth centreline, built from primitives
(:func:`centreline_from_path`) or filleted survey points (:func:`centreline_from_survey`),
and approximated by straight hollow-cylinder segments for the contact kernel (paper Sect. 2.3).
"""

from .centreline import Centreline, Piece
from .conduit import Conduit, discretise
from .path import Bend, Helix, Straight, centreline_from_path
from .segments import Segments
from .survey import centreline_from_survey, read_survey_csv

__all__ = [
    "Straight",
    "Bend",
    "Helix",
    "Piece",
    "Centreline",
    "Segments",
    "Conduit",
    "centreline_from_path",
    "centreline_from_survey",
    "read_survey_csv",
    "discretise",
]
