"""Dotted keys into a scenario's TOML tables: ``contact.friction``, ``conduit.path[1].helix_turns``.

A sweep names the scenario values it sets, unsets and varies with the same dotted keys that
:class:`~exucable.errors.ScenarioError` uses in its messages, so an error about a case and the
sweep file's own key read alike. The functions here edit the *raw* scenario dict (as read from
TOML, before defaults are filled in), so that defaults derived from other values (e.g.
``solver.output_interval`` from ``solver.end_time``) follow the varied value.
"""

from __future__ import annotations

import copy
import re

from ..errors import ScenarioError

__all__ = ["parse_key", "format_key", "set_value", "unset_value", "keys_overlap"]

_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$")
_INDEX = re.compile(r"\[(\d+)\]")

_EXAMPLE = "like contact.friction or conduit.path[1].helix_turns"


def parse_key(key: str, where: str) -> tuple[str | int, ...]:
    """Split a dotted key into table names (str) and array indices (int).

    Parameters
    ----------
    key : str
        E.g. ``"conduit.path[1].helix_turns"`` → ``("conduit", "path", 1, "helix_turns")``.
    where : str
        The sweep-file key to name in an error (e.g. ``'vary."contact.friction"'``).

    Raises
    ------
    ScenarioError
        If ``key`` is not a well-formed dotted key.
    """
    if not isinstance(key, str) or not key:
        raise ScenarioError(where, f"must be a dotted key {_EXAMPLE}, got {key!r}")
    tokens: list[str | int] = []
    for part in key.split("."):
        m = _PART.match(part)
        if m is None:
            raise ScenarioError(where, f"not a dotted key {_EXAMPLE}: {key!r}")
        tokens.append(m.group(1))
        tokens.extend(int(i) for i in _INDEX.findall(m.group(2)))
    return tuple(tokens)


def format_key(tokens) -> str:
    """The dotted key of ``tokens`` (inverse of :func:`parse_key`)."""
    out = ""
    for t in tokens:
        out += f"[{t}]" if isinstance(t, int) else (f".{t}" if out else t)
    return out


def _parent(data: dict, tokens, where: str, create: bool):
    """The container holding the last token, creating missing tables when ``create``."""
    node = data
    for depth, tok in enumerate(tokens[:-1]):
        here = format_key(tokens[: depth + 1])
        nxt = tokens[depth + 1]
        if isinstance(tok, int):
            if not isinstance(node, list):
                raise ScenarioError(where, f"{format_key(tokens[:depth])} is not an array: cannot take [{tok}]")
            if tok >= len(node):
                raise ScenarioError(
                    where, f"{here}: index out of range, {format_key(tokens[:depth])} has {len(node)} item(s)"
                )
            node = node[tok]
        else:
            if not isinstance(node, dict):
                raise ScenarioError(where, f"{format_key(tokens[:depth])} is not a table: cannot take .{tok}")
            if tok not in node:
                if not create or isinstance(nxt, int):
                    raise ScenarioError(where, f"{here} is not in the base scenario")
                # A missing optional table (e.g. [gravity], [contact]) is created; the scenario
                # parser then refuses any key it does not know.
                node[tok] = {}
            node = node[tok]
    return node


def set_value(data: dict, tokens, value, where: str) -> None:
    """Set ``tokens`` in the raw scenario dict ``data`` to a deep copy of ``value``.

    Missing tables on the way are created; array indices must exist.
    """
    node = _parent(data, tokens, where, create=True)
    last = tokens[-1]
    if isinstance(last, int):
        if not isinstance(node, list):
            raise ScenarioError(where, f"{format_key(tokens[:-1])} is not an array: cannot take [{last}]")
        if last >= len(node):
            raise ScenarioError(
                where, f"index out of range, {format_key(tokens[:-1])} has {len(node)} item(s)"
            )
        node[last] = copy.deepcopy(value)
    else:
        if not isinstance(node, dict):
            raise ScenarioError(where, f"{format_key(tokens[:-1])} is not a table: cannot set .{last}")
        node[last] = copy.deepcopy(value)


def unset_value(data: dict, tokens, where: str) -> None:
    """Remove ``tokens`` from the raw scenario dict (the scenario's default then applies).

    Raises
    ------
    ScenarioError
        If the key is not in ``data`` (an unset that removes nothing is most likely a typo).
    """
    node = _parent(data, tokens, where, create=False)
    last = tokens[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise ScenarioError(where, f"{format_key(tokens)} is not in the base scenario")
        del node[last]
    else:
        if not isinstance(node, dict) or last not in node:
            raise ScenarioError(where, f"{format_key(tokens)} is not in the base scenario (nothing to unset)")
        del node[last]


def keys_overlap(a, b) -> bool:
    """True if one token tuple is a prefix of the other (the two keys touch the same value)."""
    n = min(len(a), len(b))
    return tuple(a[:n]) == tuple(b[:n])
