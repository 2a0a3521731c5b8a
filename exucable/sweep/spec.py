"""Sweep files: a base scenario, keys to unset and set, and parameters to vary (grid or zip).

A sweep file (TOML) reads::

    base = "../paper_ex2_bend90.toml"     # scenario file, relative to this file or absolute
    name = "ex2-friction"                 # optional; default: the file's stem
    description = "..."                   # optional
    mode = "grid"                         # "grid" (default): every combination; "zip": i-th with i-th
    output = "pull_force_N"               # optional: the quantity plotted in sweep.png
    unset = ["pull.force"]                # optional: keys removed from the base (their default applies)

    [set]                                 # optional: fixed overrides applied to every case
    "pull.back_tension" = 10.0

    [vary]                                # required: one array of values per dotted key
    "contact.friction" = [0.1, 0.2, 0.3]
    "conduit.path[1].helix_turns" = [1, 2, 3, 4, 5]

Each case's scenario is the base file's tables with, in this order, the ``unset`` keys removed,
the ``[set]`` values and then the case's ``[vary]`` values written in (missing tables such as
``[gravity]`` are created; array indices must exist; nested TOML tables under ``[set]``/``[vary]``
are read as dotted keys and merged key by key). Every case is then validated by
:func:`~exucable.scenario.specs.parse_scenario` before anything runs; a refusal is re-raised as a
:class:`~exucable.errors.ScenarioError` that names the sweep key that caused it, e.g.
``vary."contact.friction"[2]: contact.friction: must be >= 0, got -0.1``.

A case is identified by :func:`scenario_hash`: the first 16 hex digits of the sha256 of the
canonical JSON of its full scenario (``Scenario.to_dict()``, defaults filled in), so the same
physical case has the same directory whichever sweep file or order produced it.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

from ..errors import ScenarioError

# Cases of one sweep: each is validated (a route built) before the first runs, ~10 ms apiece, so
# 10 000 cases take minutes to check and a sweep of hours at the least
MAX_CASES = 10_000
from ..scenario.specs import Scenario, parse_scenario, read_toml
from ..scenario.dotted import keys_overlap, parse_key, set_value, unset_value

__all__ = ["Case", "Sweep", "MODES", "OUTPUTS", "load_sweep", "parse_sweep", "scenario_hash",
           "canonical_json", "format_params"]

MODES = ("grid", "zip")

# Plottable outputs (summary.json / case.json keys) -> their rope-reference counterpart, if any.
OUTPUTS: dict[str, str | None] = {
    "pull_force_N": "rope_pull_force_N",
    "trailing_tension_N": "rope_trailing_tension_N",
    "max_tension_N": None,
    "max_sidewall_pressure_N_per_m": "rope_max_sidewall_pressure_N_per_m",
    "wall_time_s": None,
}

_TOP_KEYS = ("base", "name", "description", "mode", "output", "unset", "set", "vary")


class Case(NamedTuple):
    """One case of a sweep: its varied values and its validated scenario.

    Attributes
    ----------
    params : dict
        Dotted key → value of the sweep's ``[vary]`` keys for this case.
    scenario : Scenario
        The case's full, validated scenario.
    """

    params: dict
    scenario: Scenario

    @property
    def case_id(self) -> str:
        """The case's key: :func:`scenario_hash` of its scenario (16 hex digits)."""
        return scenario_hash(self.scenario)


@dataclass(frozen=True)
class Sweep:
    """A validated sweep.

    Attributes
    ----------
    name, description : str
    base_path : Path
        The base scenario file (absolute).
    mode : str
        ``"grid"`` or ``"zip"``.
    output : str
        Quantity plotted in ``sweep.png`` (a key of :data:`OUTPUTS`).
    unset : tuple of str
        Dotted keys removed from the base.
    set : dict
        Dotted key → value applied to every case.
    vary : dict
        Dotted key → tuple of values, in file order (the first key is the plot's x axis).
    cases : list of Case
        Grid order: the first key varies slowest.
    source_path : Path or None
        The sweep file, if read from one.
    """

    name: str
    description: str
    base_path: Path
    mode: str
    output: str
    unset: tuple
    set: dict
    vary: dict
    cases: list = field(default_factory=list)
    source_path: Path | None = None

    @property
    def keys(self) -> tuple[str, ...]:
        """The varied dotted keys (the parameter columns of ``sweep.csv``)."""
        return tuple(self.vary)

    @property
    def base_dir(self) -> Path:
        """Directory of the base scenario (relative paths in it resolve against it)."""
        return self.base_path.parent

    def case_ids(self) -> list[str]:
        """:attr:`Case.case_id` of every case, in case order."""
        return [c.case_id for c in self.cases]


def canonical_json(data) -> str:
    """JSON with sorted keys and no whitespace: equal dicts give equal text."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)


def scenario_hash(scenario: Scenario | dict) -> str:
    """First 16 hex digits of the sha256 of the canonical JSON of the full scenario dict."""
    d = scenario.to_dict() if isinstance(scenario, Scenario) else scenario
    return hashlib.sha256(canonical_json(d).encode("utf-8")).hexdigest()[:16]


def format_params(params: dict) -> str:
    """``key=value, ...`` with values as JSON (for messages and plot legends)."""
    return ", ".join(f"{k}={json.dumps(v)}" for k, v in params.items())


def load_sweep(path) -> Sweep:
    """Read and validate a sweep file; every case's scenario is validated too.

    Raises
    ------
    ScenarioError
        Naming the sweep-file key at fault (``base``, ``vary."k"[i]``, ``set."k"``, ``unset[i]``,
        ``mode``, ...), before anything runs.
    """
    from ..data import resolve_scenario_path

    path = resolve_scenario_path(path)       # README's scenarios/sweeps/... paths work from anywhere
    data = read_toml(path, "sweep")
    sweep = parse_sweep(data, path.parent, default_name=path.stem)
    object.__setattr__(sweep, "source_path", path.resolve())
    return sweep


def _string(data: dict, key: str, default=None) -> str:
    value = data.get(key, default)
    if not isinstance(value, str):
        raise ScenarioError(key, f"must be a string, got {value!r}")
    return value


def _flatten(table: dict, prefix: str = "") -> dict:
    """Nested TOML tables under [set]/[vary] as dotted keys (``[vary.contact]`` → ``contact.x``)."""
    out = {}
    for k, v in table.items():
        full = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict):
            out.update(_flatten(v, full))
        else:
            out[full] = v
    return out


def _read_base(value, sweep_dir: Path) -> tuple[Path, dict]:
    if not isinstance(value, str) or not value.strip():
        raise ScenarioError("base", f"required: the base scenario file (relative to the sweep file), got {value!r}")
    path = (sweep_dir / value).resolve()
    try:
        return path, read_toml(path, "scenario")
    except ScenarioError as exc:
        raise ScenarioError("base", exc.message) from None


def parse_sweep(data: dict, base_dir, default_name: str = "sweep") -> Sweep:
    """Validate a sweep given as a dict (as read from TOML) and build its cases.

    Parameters
    ----------
    data : dict
        The sweep file's keys.
    base_dir : Path
        Directory against which ``base`` is resolved (the sweep file's directory).
    default_name : str
        Name used when ``data`` has no ``name``.
    """
    sweep_dir = Path(base_dir)
    if not isinstance(data, dict):
        raise ScenarioError("", "a sweep must be a table")
    for k in data:
        if k not in _TOP_KEYS:
            hint = difflib.get_close_matches(str(k), _TOP_KEYS, n=1)
            raise ScenarioError(
                str(k), f"unknown key; allowed in a sweep file: {', '.join(_TOP_KEYS)}"
                + (f" (did you mean '{hint[0]}'?)" if hint else ""))
    base_path, base_raw = _read_base(data.get("base"), sweep_dir)
    name = _string(data, "name", default_name)
    if not name.strip():
        raise ScenarioError("name", "must be a non-empty string")
    description = _string(data, "description", "")
    mode = data.get("mode", "grid")
    if mode not in MODES:
        raise ScenarioError("mode", f'must be "grid" or "zip", got {mode!r}')
    output = data.get("output", "pull_force_N")
    if output not in OUTPUTS:
        raise ScenarioError("output", f"must be one of {', '.join(OUTPUTS)}, got {output!r}")

    # --- unset / set: applied once to a copy of the base
    unset_raw = data.get("unset", [])
    if not isinstance(unset_raw, list) or not all(isinstance(k, str) for k in unset_raw):
        raise ScenarioError("unset", f'must be an array of dotted keys like ["pull.force"], got {unset_raw!r}')
    set_raw = data.get("set", {})
    if not isinstance(set_raw, dict):
        raise ScenarioError("set", "must be a table of dotted keys and values")
    vary_raw = data.get("vary")
    if not isinstance(vary_raw, dict) or not vary_raw:
        raise ScenarioError("vary", 'required: a table of dotted keys and arrays, e.g. "contact.friction" = [0.1, 0.2]')
    set_values = _flatten(set_raw)
    vary_values = _flatten(vary_raw)

    # (tokens, where) of every sweep key, for blaming scenario errors on the key that caused them
    unset_keys = [(parse_key(k, f"unset[{i}]"), f"unset[{i}]") for i, k in enumerate(unset_raw)]
    set_keys = {k: (parse_key(k, f'set."{k}"'), f'set."{k}"') for k in set_values}
    vary_keys = {k: parse_key(k, f'vary."{k}"') for k in vary_values}

    for k, values in vary_values.items():
        if not isinstance(values, list) or not values:
            raise ScenarioError(f'vary."{k}"', f"must be a non-empty array of values, got {values!r}")
    keys = list(vary_values)
    for a, b in itertools.combinations(keys, 2):
        if keys_overlap(vary_keys[a], vary_keys[b]):
            raise ScenarioError(f'vary."{b}"', f'overlaps vary."{a}": vary each value through one key only')
    for k, (toks, where) in set_keys.items():
        for vk in keys:
            if keys_overlap(toks, vary_keys[vk]):
                raise ScenarioError(where, f'overlaps vary."{vk}": a key is either set or varied')
    if mode == "zip":
        lengths = {k: len(vary_values[k]) for k in keys}
        if len(set(lengths.values())) > 1:
            raise ScenarioError(
                "vary", 'mode = "zip" needs arrays of equal length; got '
                + ", ".join(f'"{k}": {n}' for k, n in lengths.items()))

    prepared = copy.deepcopy(base_raw)
    for toks, where in unset_keys:
        unset_value(prepared, toks, where)
    for k, (toks, where) in set_keys.items():
        set_value(prepared, toks, set_values[k], where)

    n_cases = math.prod(len(vary_values[k]) for k in keys) if mode == "grid" else len(vary_values[keys[0]])
    if n_cases > MAX_CASES:
        raise ScenarioError("vary", f"gives {n_cases} cases, more than {MAX_CASES} (each is a run of its own, and "
                                    "every case is checked before the first runs); split the sweep or vary fewer values")
    if mode == "grid":
        combos = list(itertools.product(*(range(len(vary_values[k])) for k in keys)))
    else:
        combos = [(i,) * len(keys) for i in range(len(vary_values[keys[0]]))]

    default_scenario_name = base_path.stem
    cases: list[Case] = []
    seen: dict[str, int] = {}
    for n, combo in enumerate(combos):
        params = {k: vary_values[k][i] for k, i in zip(keys, combo)}
        case_data = copy.deepcopy(prepared)
        for k, i in zip(keys, combo):
            set_value(case_data, vary_keys[k], vary_values[k][i], f'vary."{k}"[{i}]')
        try:
            scenario = parse_scenario(case_data, base_path.parent, default_name=default_scenario_name)
        except ScenarioError as exc:
            where = _blame(exc.key, [(vary_keys[k], f'vary."{k}"[{i}]') for k, i in zip(keys, combo)]
                           + list(set_keys.values()) + unset_keys)
            if where is None:
                where = _blame_base(prepared, base_path, exc, n, params)
            raise ScenarioError(where, str(exc)) from None
        case = Case(params, scenario)
        cid = case.case_id
        if cid in seen:
            m = seen[cid]
            raise ScenarioError(
                "vary", f"cases {m} ({format_params(cases[m].params)}) and {n} ({format_params(params)}) "
                "are the same scenario: give distinct values")
        seen[cid] = n
        cases.append(case)

    return Sweep(
        name=name, description=description, base_path=base_path, mode=mode, output=output,
        unset=tuple(unset_raw), set=set_values, vary={k: tuple(vary_values[k]) for k in keys}, cases=cases,
    )


def _blame(error_key: str, candidates) -> str | None:
    """The sweep key (``where``) of the first candidate touching ``error_key``, or None."""
    try:
        etoks = parse_key(error_key, "")
    except ScenarioError:
        return None
    for toks, where in candidates:
        if keys_overlap(toks, etoks):
            return where
    return None


def _blame_base(prepared: dict, base_path: Path, exc: ScenarioError, n: int, params: dict) -> str:
    """An error no sweep key touches: the base's own (if the base with [set]/unset fails alike) or the case's."""
    try:
        parse_scenario(copy.deepcopy(prepared), base_path.parent, default_name=base_path.stem)
    except ScenarioError as base_exc:
        if base_exc.key == exc.key:
            return f"base ({base_path})"
    return f"case {n} ({format_params(params)})"

