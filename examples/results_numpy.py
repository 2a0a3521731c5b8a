"""Reading results into numpy: from the Result object in memory, and from the files on disk.

``xc.run(sc, out_dir=...)`` writes the documented results format (README "Results format"):
summary.json and CSV files with a header row, readable by ``np.genfromtxt(names=True)``.
"""

import json
import sys
from pathlib import Path

import numpy as np

import exucable as xc


def main(out_dir="out/results_numpy", end_time=0.5):
    sc = xc.load_scenario(Path(__file__).resolve().parent.parent / "scenarios/fast/paper_ex2_bend90.toml")
    sc = sc.replace(**{"solver.end_time": end_time})
    res = xc.run(sc, out_dir=out_dir)

    # in memory: numpy arrays
    t, F = res.history.time_s, res.history.pull_force_N
    x, N = res.tension_profile.x_m, res.tension_profile.tension_N
    print(f"{len(t)} records; pulling force at the end {F[-1]:.3f} N; tension from {N[0]:.1f} N at x = 0 "
          f"to {N[-1]:.1f} N at x = {x[-1]:.3f} m (along the cable from its trailing end)")

    # on disk: the same numbers, column names from the header
    history = np.genfromtxt(Path(out_dir) / "history.csv", delimiter=",", names=True, comments="#")
    profile = np.genfromtxt(Path(out_dir) / "tension_profile.csv", delimiter=",", names=True, comments="#")
    summary = json.loads((Path(out_dir) / "summary.json").read_text())
    steady = history["time_s"] >= summary["steady_from_s"]
    mean_from_csv = float(np.mean(history["pull_force_N"][steady]))
    print(f"steady mean from history.csv {mean_from_csv:.4f} N = summary.json {summary['pull_force_N']:.4f} N")
    print(f"largest tension {profile['tension_N'].max():.2f} N at x = "
          f"{profile['x_m'][np.argmax(profile['tension_N'])]:.3f} m")
    return res, mean_from_csv, summary


if __name__ == "__main__":
    main(*sys.argv[1:2])
