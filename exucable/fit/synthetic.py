"""Synthetic tension logs from the rope (or a given history) with a known friction coefficient, with a
recorder's faults.

For checking the fit (``tests/test_fit.py``) and an installation's own logging chain: the head tension
T(x; μ) of the pull-in history, sampled once per ``sample_interval_s`` at the pull speed, plus white noise,
a slow drift (an AR(1) process: the dynamometer's zero wandering), stops (the winch stands; the reading
relaxes toward a fraction of the tension), spikes (single readings far off) and a tare offset (the
reading of the slack line before the pull, added to every reading).
"""

from __future__ import annotations

import numpy as np

from exucable.io import csv_text
from exucable.plan.pull import PlanSpec, plan_spec, pull_in_rope
from exucable.scenario.specs import Scenario

__all__ = ["synthetic_log", "synthetic_log_csv"]


def synthetic_log(scenario: Scenario, friction: float, *, seed: int = 0, speed_m_per_s: float = 0.5,
                  sample_interval_s: float = 1.0, until_m: float | None = None, noise_N: float = 0.0,
                  drift_N: float = 0.0, drift_time_s: float = 60.0, stops: int = 0, stop_s: float = 30.0,
                  spikes: int = 0, spike_N: float = 0.0, tare_N: float = 0.0, lead_in_s: float = 0.0,
                  friction_after: tuple[float, float] | None = None, bend_friction: float | None = None,
                  spec: PlanSpec | None = None, direction: str | None = None, history=None) -> dict:
    """A synthetic log in SI: ``time_s``, ``pulled_length_m``, ``pull_force_N`` arrays.

    Parameters
    ----------
    scenario : Scenario
    friction : float
        The true μ [-].
    seed : int
        Seed of the noise, drift, stops and spikes.
    speed_m_per_s, sample_interval_s : float
        Pull speed [m/s] and logging interval [s].
    until_m : float, optional
        Pulled length [m] where the log ends (a partial log); default the route's length.
    noise_N : float
        Standard deviation of white noise [N].
    drift_N, drift_time_s : float
        Stationary standard deviation [N] and correlation time [s] of the AR(1) drift.
    stops, stop_s : int, float
        Number of stops and the length of each [s].
    spikes, spike_N : int, float
        Number of single-reading spikes and their size [N] (sign random).
    tare_N : float
        Offset [N] added to every reading, read alone during ``lead_in_s`` seconds before the winch moves.
    bend_friction : float, optional
        A different true μ [-] in bends and helices.
    friction_after : (float, float), optional
        ``(x_m, mu)``: from head position x_m [m] on, the head tension grows as if the friction were mu
        (the friction changed in time: the log's slope steps there).
    spec : PlanSpec, optional
    direction : str, optional
    history : (numpy.ndarray, numpy.ndarray), optional
        Head positions [m] and head tensions [N] of another model's pull-in history at ``friction``
        (the multibody one: :func:`exucable.solve.pull_in.steady_pull_in`), sampled linearly between
        its points instead of the rope (not with ``friction_after`` or ``bend_friction``).

    Returns
    -------
    dict
        ``time_s``, ``pulled_length_m``, ``pull_force_N`` (numpy arrays, SI).
    """
    rng = np.random.default_rng(seed)
    spec = spec or plan_spec(scenario)
    direction = direction or scenario.pull.direction
    rope = pull_in_rope(scenario, spec, direction, friction=friction, bend_friction=bend_friction)
    L = rope.cable_length_m
    end = L if until_m is None else min(float(until_m), L)
    x = np.arange(0.0, end + 1e-9, speed_m_per_s * sample_interval_s)
    T = np.asarray(rope.tension_at(x), dtype=float)
    if history is not None:
        if friction_after is not None or bend_friction is not None:
            raise ValueError("history: not with friction_after or bend_friction (the rope's variations)")
        T = np.interp(x, np.asarray(history[0], dtype=float), np.asarray(history[1], dtype=float))
    if friction_after is not None:
        x_c, mu2 = friction_after
        other = pull_in_rope(scenario, spec, direction, friction=mu2)
        T_c = float(rope.tension_at(min(x_c, L)))
        later = x > x_c
        # the second rope's growth from x_c on, added to this rope's tension at x_c
        T[later] = T_c + np.asarray(other.tension_at(x[later])) - float(other.tension_at(min(x_c, L)))
    # stops: the head holds its position, the reading relaxes to 70-90 % of the sliding tension
    n_lead = int(round(lead_in_s / sample_interval_s))
    xs, Ts, moving = [np.zeros(n_lead)], [np.full(n_lead, np.nan)], [np.zeros(n_lead, bool)]
    at = np.sort(rng.choice(np.arange(5, max(6, x.size - 5)), size=min(stops, max(0, x.size - 10)),
                            replace=False)) if stops else np.array([], int)
    prev = 0
    n_stop = int(round(stop_s / sample_interval_s))
    for i in at:
        xs.append(x[prev:i])
        Ts.append(T[prev:i])
        moving.append(np.ones(i - prev, bool))
        xs.append(np.full(n_stop, x[i - 1]))
        Ts.append(T[i - 1] * np.linspace(1.0, rng.uniform(0.7, 0.9), n_stop))
        moving.append(np.zeros(n_stop, bool))
        prev = i
    xs.append(x[prev:])
    Ts.append(T[prev:])
    moving.append(np.ones(x.size - prev, bool))
    xs, Ts = np.concatenate(xs), np.concatenate(Ts)
    Ts[:n_lead] = 0.0
    n = xs.size
    reading = Ts + tare_N + noise_N * rng.standard_normal(n)
    if drift_N > 0:
        phi = np.exp(-sample_interval_s / drift_time_s)
        e = rng.standard_normal(n) * drift_N * np.sqrt(1 - phi ** 2)
        d = np.empty(n)
        d[0] = drift_N * rng.standard_normal()
        for k in range(1, n):
            d[k] = phi * d[k - 1] + e[k]
        reading += d
    if spikes:
        cand = np.flatnonzero(np.concatenate(moving))
        cand = cand[cand > n_lead + 2]
        hit = rng.choice(cand, size=min(spikes, cand.size), replace=False)
        reading[hit] += spike_N * rng.choice([-1.0, 1.0], size=hit.size)
    return {"time_s": np.arange(n) * sample_interval_s, "pulled_length_m": xs, "pull_force_N": reading}


def synthetic_log_csv(log: dict, *, length_unit: str = "m", force_unit: str = "N", ended: bool = True,
                      comment: str = "") -> str:
    """A synthetic log as CSV text, the columns in ``length_unit`` (``m``/``ft``) and ``force_unit``
    (``N``/``kN``/``lbf``), with an ``# end of pull`` line when ``ended``."""
    from exucable.scenario.units import UNITS

    lf, ff = UNITS[length_unit][1], UNITS[force_unit][1]
    cols = ("time_s", f"pulled_length_{length_unit}", f"tension_{force_unit}")
    data = {cols[0]: np.round(log["time_s"], 3), cols[1]: np.round(log["pulled_length_m"] / lf, 4),
            cols[2]: np.round(log["pull_force_N"] / ff, 4)}
    head = "".join(f"# {line}\n" for line in comment.splitlines())
    return head + csv_text(cols, data) + ("# end of pull\n" if ended else "")
