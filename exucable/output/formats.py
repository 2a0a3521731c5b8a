"""Column tables and JSON Schemas of the files exucable writes for another solver.

Pure data: :mod:`exucable.output.export` (the discrete problem) and :mod:`exucable.output.snapshots` (the state
at requested times) write these files, tests and other tools read them. Field-by-field
documentation with units: ``docs/results-format.md``.
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["FORMAT_VERSION", "SCHEMA_DIR", "NODE_COLUMNS", "ELEMENT_COLUMNS", "CHECK_POINT_COLUMNS",
           "SEGMENT_COLUMNS", "PIECE_COLUMNS", "EXPORT_FILES", "SNAPSHOT_FILES", "INTEGER_COLUMNS", "csv_schema",
           "schema_of"]

#: Bumped when a file's columns or problem.json's fields change meaning.
FORMAT_VERSION = 2

SCHEMA_DIR = Path(__file__).with_name("schemas")

NODE_COLUMNS = ("node", "x_m", "s_conduit_m", "pos_x_m", "pos_y_m", "pos_z_m", "slope_x", "slope_y", "slope_z",
                "vel_x_m_per_s", "vel_y_m_per_s", "vel_z_m_per_s",
                "slope_rate_x_1_per_s", "slope_rate_y_1_per_s", "slope_rate_z_1_per_s")
ELEMENT_COLUMNS = ("element", "node_i", "node_j", "reference_length_m", "x_start_m", "pre_strain_mid",
                   "tension_mid_N")
CHECK_POINT_COLUMNS = ("element", "point", "xi", "weight", "contact_weight", "x_m")
SEGMENT_COLUMNS = ("segment", "piece", "start_x_m", "start_y_m", "start_z_m", "end_x_m", "end_y_m", "end_z_m",
                   "s_start_pull_m", "s_end_pull_m", "s_start_conduit_m", "s_end_conduit_m")
PIECE_COLUMNS = ("piece", "curved", "s_start_pull_m", "length_m", "start_x_m", "start_y_m", "start_z_m",
                 "dir_x", "dir_y", "dir_z", "centre_x_m", "centre_y_m", "centre_z_m",
                 "e1_x", "e1_y", "e1_z", "e2_x", "e2_y", "e2_z", "axis_x", "axis_y", "axis_z",
                 "coil_radius_m", "rise_m_per_rad", "phi_rad")

#: file name -> columns (problem.json: None)
EXPORT_FILES = {
    "problem.json": None,
    "nodes_initial.csv": NODE_COLUMNS,
    "elements.csv": ELEMENT_COLUMNS,
    "check_points.csv": CHECK_POINT_COLUMNS,
    "conduit_segments.csv": SEGMENT_COLUMNS,
    "conduit_pieces.csv": PIECE_COLUMNS,
}


SNAPSHOT_FILES = {
    "snapshot_times.csv": ("time_s", "step_start_s", "step_end_s", "pull_force_N"),
    "snapshot_nodes.csv": ("time_s",) + tuple(c for c in NODE_COLUMNS if c != "s_conduit_m"),
    "snapshot_tension.csv": ("time_s", "element", "xi", "x_m", "tension_N"),
    "snapshot_contact.csv": ("time_s", "element", "x_mid_m", "normal_force_N", "friction_force_N",
                             "normal_force_per_length_N_per_m", "friction_force_per_length_N_per_m",
                             "max_penetration_m", "points_in_contact"),
}

INTEGER_COLUMNS = frozenset({"node", "element", "node_i", "node_j", "point", "segment", "piece", "curved",
                             "points_in_contact"})


def csv_schema(columns, title: str = "") -> dict:
    """JSON Schema of one row of a CSV table read as ``{column: number}``: every column required,
    no other, indices integers >= 0, every other value a number (NaN where a field does not apply,
    e.g. a straight piece's centre). Serves every CSV exucable writes for another solver."""
    props = {c: ({"type": "integer", "minimum": 0} if c in INTEGER_COLUMNS else {"type": "number"})
             for c in columns}
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": title, "type": "object",
            "properties": props, "required": list(columns), "additionalProperties": False}


def schema_of(file_name: str) -> dict:
    """The JSON Schema of an exported or snapshot file (``problem.json``: the shipped schema file)."""
    if file_name == "problem.json":
        return json.loads((SCHEMA_DIR / "problem.schema.json").read_text())
    columns = {**{k: v for k, v in EXPORT_FILES.items() if v is not None}, **SNAPSHOT_FILES}[file_name]
    return csv_schema(columns, title=f"one row of {file_name}")
