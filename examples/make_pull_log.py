"""Write the example tension log `pull_log_commscope_a_h.csv`: a synthetic recorder's log of the
CommScope run A-H pull (scenarios/industry/commscope_conquest_run_a_h.toml), stopped with the head
250 ft into the conduit, in the units a US winch logs (ft, lbf).

The head tension is the rope's pull-in history at a known friction 0.35 (the scenario's own 0.5 is the
manual's design value), with a tare of 4.5 lbf read for 20 s before the winch moves, white noise, a
drifting zero, three stops and four spikes (exucable.fit.synthetic). Fit it with

    exucable fit scenarios/industry/commscope_conquest_run_a_h.toml examples/pull_log_commscope_a_h.csv --tare auto
"""

from __future__ import annotations

from pathlib import Path

from exucable.fit.synthetic import synthetic_log, synthetic_log_csv
from exucable.io import atomic_write_text
from exucable.scenario.specs import load_scenario

HERE = Path(__file__).resolve().parent
SCENARIO = HERE.parent / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml"
TRUE_FRICTION = 0.35
HEAD_AT_M = 250 * 0.3048


def log_text() -> str:
    """The example log's CSV text (deterministic: fixed seed)."""
    scenario = load_scenario(SCENARIO)
    log = synthetic_log(scenario, TRUE_FRICTION, seed=0, speed_m_per_s=0.25, until_m=HEAD_AT_M, noise_N=3.0,
                        drift_N=2.0, drift_time_s=5.0, stops=3, stop_s=30.0, spikes=4, spike_N=60.0,
                        tare_N=20.0, lead_in_s=20.0)
    comment = ("Synthetic log (examples/make_pull_log.py): CommScope run A-H, QR 715 cable, pulled A -> H;\n"
               f"true friction {TRUE_FRICTION}, tare 4.5 lbf; the head is 250 ft in, the pull goes on.")
    return synthetic_log_csv(log, length_unit="ft", force_unit="lbf", ended=False, comment=comment)


def main(out=HERE / "pull_log_commscope_a_h.csv") -> Path:
    return atomic_write_text(out, log_text())


if __name__ == "__main__":
    main()
