"""Several cables' steady solve through a smooth contact onset, continued toward the law without it.

Where three cables cross the duct (an up-bend) the steady solve stalls on grazing contacts: a
check point within micrometres of another cable or the wall, where the Hertz stiffness ∝ δ^(1/2)
vanishes, switches in and out of contact from one Newton iterate to the next, and the pseudo-time
steps that stay within the contacts' micrometre scale remove only newtons of residual
(reference/README.md, "Three cables through an up-bend: where the steady solve stalls").

Here the law itself is made smooth at the onset: contact begins at δ = -s and the law acts on the
blended penetration φ_s(δ) (:func:`exucable.contact.law.onset_blend`, docs/theory.md "A smooth
contact onset"), the Hertz law itself from δ = s on. The bundle is solved at a layer s₀ of tenths
of a millimetre, where a grazing contact is a stiff, smooth spring, and then again at s₀/2, s₀/4, ...
down to ``floor_m`` and at last at s = 0 (the law of one cable, unchanged), each solve started from
the last one's state (:meth:`OnsetContinuation.descend`). The pulling force at every layer is kept
(:attr:`OnsetContinuation.stages`): the layer shifts the contact surfaces by a fraction of s, so
F(s) → F₀ about linearly (halving with s on the study's down- and horizontal bends), and Richardson's
step with p = 1, F₀ ≈ 2 F(s/2) - F(s) for the last two layers, estimates the error |F(s) - F₀| of an
answer at a finite s (within 7e-5 of the solved s = 0 on the study's cases, reference/README.md).

Where the solve at a smaller layer stalls, the state and the law go back to the last layer solved;
that answer stands, with its uncertainty, if the extrapolation says it is within ``tolerance``
(relative) of the s → 0 one (the steady error bar's floor, :data:`exucable.solve.error_bar.RESOLUTION_FLOOR`),
else the solve fails naming the layer reached.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["OnsetSettings", "OnsetStage", "OnsetContinuation", "extrapolate_to_zero"]


@dataclass(frozen=True)
class OnsetSettings:
    """The layers of the onset continuation (:class:`OnsetContinuation`).

    Attributes
    ----------
    first_m : float
        s₀ [m], the first layer.
    factor : float
        Each layer is the last one divided by this [-] (> 1).
    floor_m : float
        The smallest layer above 0 [m]; after it, s = 0.
    min_factor : float
        The smallest factor between two layers [-] (> 1): a layer that stalls is tried again at the
        square root of the factor, down to this (:meth:`OnsetContinuation.descend`).
    tolerance : float
        Relative difference [-] between an answer at a finite layer and the extrapolated s → 0 one
        within which the finite layer's answer stands when the next layer stalls.
    skipped_steps : int
        Each thinner layer's one-iteration continuation begins at the spring rate and axial share
        reached after this many accepted steps (``skip`` of
        :meth:`~exucable.solve.steady.SteadySolver.relax_one_iteration`) [-]. Why 0: a layer
        halved moves every loaded contact, and on the 100 m three-cable route (cradled) the state
        solved at 500 µm has a residual of 1511 N at 250 µm; from there the steps begun as after 3
        accepted ones (c0/512) ran to 2e4-4e4 N, those begun at c0 converged in 15 Newton
        iterations (reference/README.md, "The relaxation handed over early, and the layers' descent
        from c0").
    exact_steps : bool
        Where a thinner layer's one-iteration continuation fails, try the exact-step continuation
        (:meth:`~exucable.solve.steady.SteadySolver.relax`) there before going back to a thicker
        layer. Why not: on the 100 m three-cable route (cradled) the one-iteration steps at 15.6 µm
        alternate at 7.83 mN (stop 2.2 mN), two cables' contact at one node flipping, and the exact
        steps then spent 39 s CPU to stop at 7.8 mN; the layer between (22.1 µm), tried next, solved.
    """

    first_m: float = 5.0e-4
    factor: float = 2.0
    floor_m: float = 2.0e-6
    min_factor: float = 1.05
    # the steady error bar's floor, exucable.solve.error_bar.RESOLUTION_FLOOR (which imports the
    # steady solve, hence not imported here; tests/test_onset_layer.py holds them equal)
    tolerance: float = 1e-4
    skipped_steps: int = 0
    exact_steps: bool = False

    def __post_init__(self):
        from ..errors import SolverError

        if not (np.isfinite(self.first_m) and self.first_m > 0.0):
            raise SolverError(f"OnsetSettings.first_m = {self.first_m!r}: must be a finite layer > 0 m")
        if not (np.isfinite(self.factor) and self.factor > 1.0):
            raise SolverError(f"OnsetSettings.factor = {self.factor!r}: must be > 1")
        if not (0.0 < self.floor_m <= self.first_m):
            raise SolverError(f"OnsetSettings.floor_m = {self.floor_m!r}: must be in (0, first_m = {self.first_m!r}] m")
        if isinstance(self.skipped_steps, bool) or not isinstance(self.skipped_steps, (int, np.integer)) \
                or self.skipped_steps < 0:
            raise SolverError(f"OnsetSettings.skipped_steps = {self.skipped_steps!r}: must be a whole number >= 0")
        if not 1.0 < self.min_factor <= self.factor:
            raise SolverError(f"OnsetSettings.min_factor = {self.min_factor!r}: must be in (1, factor = {self.factor!r}]")
        if not self.tolerance > 0.0:
            raise SolverError(f"OnsetSettings.tolerance = {self.tolerance!r}: must be > 0")

    def layers_m(self) -> list[float]:
        """s₀, s₀/factor, ... down to ``floor_m``, then 0 [m]: the layers of a continuation whose
        every layer converges."""
        out, s = [], float(self.first_m)
        while s >= self.floor_m * (1.0 - 1e-12):
            out.append(s)
            s /= self.factor
        return out + [0.0]


@dataclass
class OnsetStage:
    """One layer's solve: layer s [m], converged?, Newton iterations and CPU time [s] of this stage,
    the last accepted residual [N] and the pulling force [N] at its state (None where it stalled)."""

    layer_m: float
    converged: bool
    newton_iterations: int
    cpu_s: float
    residual_N: float | None
    pull_force_N: float | None


def extrapolate_to_zero(layers_m, forces_N) -> tuple[float, float]:
    """F₀ at s → 0 from the last two converged layers, F(s) = F₀ + a s (Richardson with p = 1), and
    the error |F(s_last) - F₀| [N] of the smaller layer's answer.

    A layer s = 0 among them is the answer itself (error 0); one layer alone gives (F, inf).
    """
    s = np.asarray(layers_m, dtype=float)
    f = np.asarray(forces_N, dtype=float)
    if len(s) and s[-1] == 0.0:
        return float(f[-1]), 0.0
    if len(s) < 2:
        return (float(f[-1]) if len(f) else float("nan")), float("inf")
    s1, s2, f1, f2 = s[-2], s[-1], f[-2], f[-1]
    f0 = f2 - s2 * (f1 - f2) / (s1 - s2)
    return float(f0), float(abs(f2 - f0))


@dataclass
class OnsetContinuation:
    """The onset layer's continuation on one steady solve (module notes).

    Use: :meth:`begin` before the solve (the model's kernels at the first layer), :meth:`descend`
    after it converged there.
    """

    settings: OnsetSettings = field(default_factory=OnsetSettings)
    stages: list = field(default_factory=list)
    #: the layer of the answer [m] (0: the law without a layer)
    layer_m: float = 0.0
    #: F₀ extrapolated to s → 0 [N] and the answer's error from the layer [N]
    extrapolated_N: float = float("nan")
    layer_error_N: float = 0.0

    def summary(self) -> dict:
        """``layer_m`` (the answer's layer [m], 0: the law without one), ``extrapolated_pull_N`` and
        ``layer_error_N`` (None where not known: one layer solved), ``stages`` (one dict per layer
        tried); None before :meth:`descend` (the first layer did not solve)."""
        if not self.stages:
            return None
        known = lambda x: float(x) if np.isfinite(x) else None     # noqa: E731  (JSON has no inf)
        return {"layer_m": self.layer_m, "extrapolated_pull_N": known(self.extrapolated_N),
                "layer_error_N": known(self.layer_error_N), "stages": [dict(vars(st)) for st in self.stages]}

    def begin(self, model) -> None:
        """The model's contact kernels at the first layer."""
        self._set(model, self.settings.layers_m()[0])
        self._cpu = time.process_time()
        self._its = 0

    def _set(self, model, layer_m: float) -> None:
        model.kernel.set_onset_layer(layer_m)
        self.layer_m = float(layer_m)
        if model.coupling is not None:
            model.coupling.forget_evaluation()     # a pass at the same coordinates was of the former layer

    def _stage(self, solver, converged: bool) -> None:
        now = time.process_time()
        trace = solver._trace
        # a stalled layer's state is not an answer: no residual or pull of it
        self.stages.append(OnsetStage(self.layer_m, converged, solver.newton_iterations - self._its, now - self._cpu,
                                      float(trace[-1]) if trace and converged else None,
                                      float(solver.model.steady_forces()[0]) if converged else None))
        self._cpu, self._its = now, solver.newton_iterations

    def descend(self, solver, message: str) -> tuple[str, str]:
        """From the state ``solver`` converged to at the first layer, smaller layers in turn, each
        by its one-iteration continuation at full load from c0 (``skipped_steps``), held to that
        layer's own best residual (then the exact-step continuation where ``exact_steps``): status
        and message.

        The layer falls by ``factor`` while its solves converge; a layer that stalls is tried again
        closer to the last one solved (the factor's square root: a loaded contact sits at
        δ = √(4 s φ) - s, outside the surface by most of a thick layer, and a much thinner layer can
        leave it out of contact altogether), until the factor is below ``min_factor``. Below
        ``floor_m`` the next layer is 0. Leaves the solver's stored state at the last layer solved,
        the kernels at that layer."""
        s = self.settings
        self._stage(solver, True)
        factor, why = s.factor, ""
        while self.layer_m > 0.0 and not solver.timed_out:
            layer = 0.0 if self.layer_m <= s.floor_m * (1.0 + 1e-12) else max(self.layer_m / factor, s.floor_m)
            before, before_layer = solver.store.saved, self.layer_m
            self._set(solver.model, layer)
            # another layer, another residual: the steps are held to this layer's best, not the last one's
            solver.best = (np.inf, None)
            ok, why = solver.relax_one_iteration(1.0, skip=s.skipped_steps)
            if not ok and s.exact_steps and not solver.timed_out:
                solver.store.saved = before
                ok, why = solver.relax(1.0)
            self._stage(solver, ok)
            if ok:
                factor = min(factor * factor, s.factor)
                continue
            solver.store.saved = before
            self._set(solver.model, before_layer)
            solver.at_scale(1.0)
            factor = factor ** 0.5
            if layer == 0.0 or factor < s.min_factor:
                break
        done = [st for st in self.stages if st.converged]
        self.extrapolated_N, self.layer_error_N = extrapolate_to_zero([st.layer_m for st in done],
                                                                       [st.pull_force_N for st in done])
        path = ", ".join(f"{1e6 * st.layer_m:.3g} µm: " + (f"{st.pull_force_N:.6g} N" if st.converged else "stalled")
                         for st in self.stages)
        note = f"{message}; contact onset layer continued ({path})"
        if self.layer_m == 0.0:
            return "ok", note
        answer = done[-1].pull_force_N
        if self.layer_error_N <= s.tolerance * abs(answer):
            return "ok", (f"{note}: the answer at the onset layer {1e6 * self.layer_m:.3g} µm, "
                          f"{self.layer_error_N:.2g} N from the s → 0 extrapolation {self.extrapolated_N:.6g} N")
        return "failed", (f"{note}: stalled below the onset layer {1e6 * self.layer_m:.3g} µm, whose answer is "
                          f"{self.layer_error_N:.3g} N from the s → 0 extrapolation (more than {s.tolerance:g} of it); "
                          f"why: {why}")
