"""Every script in benchmarks/ and studies/ runs its ``--quick`` smoke mode and prints its table.

A smoke test, not a measurement: each script runs in its own process on its smallest case (coarse
scenario, one repeat, one length) through the same code path as its full run; the test asserts that
it exits 0 and printed the header of its table. The figures are the scripts' business
(docs/performance.md, reference/README.md). A script that is new to either folder must be listed here
(``test_every_script_is_smoke_tested``).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# script -> a line fragment of the table header it prints (how a reader finds the table)
SCRIPTS = {
    "benchmarks/bundle_route.py": "ratio bundle / one cable",
    "benchmarks/bundle_budget.py": "relaxation cap 300 steps",
    "benchmarks/bundle_iteration.py": "| tree | cable element |",
    "benchmarks/bundle_start.py": "CPU clearance / axis",
    "benchmarks/cable_element.py": "| part (CPU per call, median) | exudyn [ms] | compiled [ms]",
    "benchmarks/contact_kernel.py": "ms/eval",
    "benchmarks/figure_cost.py": "| mode | figures | wall, median [s]",
    "benchmarks/fixed_cost.py": "| command | wall, median [s]",
    "benchmarks/industry_suite.py": "pull force [N]",
    "benchmarks/long_routes.py": "everything but the solve",
    "benchmarks/naive_baseline.py": "| | whole process [s] | simulation [s]",
    "benchmarks/newton_cost.py": "| case | check points | steps | Newton its",
    "benchmarks/newton_floor.py": "| part (CPU per call, median) | before [ms] | after [ms]",
    "benchmarks/newton_spread.py": "| family | largest neighbour ratio: solved mesh |",
    "benchmarks/newton_trace.py": "| accepted steps | rejected attempts",
    "benchmarks/run_examples.py": "| example | status | wall [s]",
    "benchmarks/steady_error_bar.py": "| case | elements (coarse) | F [N] | u [N] (u/F)",
    "benchmarks/steady_iterations.py": "exact steps",
    "benchmarks/steady_scale.py": "ms/element",
    "benchmarks/sweep_scaling.py": "cases/min",
    "benchmarks/sweep_throughput.py": "cases/min/core",
    "studies/beam_conduit_study.py": "| case | EJ [N m²] | model: stiff vs its EJ → 0 limit",
    "studies/bundle_upbend_study.py": "| bend | arrangement | cable friction | status",
    "studies/bundle_route_onset.py": "| check | result |",
    "studies/bundle_curvature_study.py": "| eigenvalue [1/s²] | mode largest on cable |",
    "studies/bundle_relax_handover.py": "| relaxed state below [N] | its residual [N] | one-iteration continuation",
    "studies/bundle_block_sweeps.py": "| sweep | coupled residual [N]",
    "studies/bundle_plan_stall.py": "| steps | CPU [s] | residual [N] | cable 3's height",
    "studies/bundle_start_masses.py": "| start | masses | status | solve CPU [s]",
    "studies/bending_stiffness_study.py": "| case | gravity | c [mm] | EJ [N m²] | √(EJ/T_in)/R",
    "studies/contact_flips.py": "| t [s] | touching | contact in/out",
    "studies/ex4_study.py": "| clearance R − r [mm] | E [Pa] | pulling force [N]",
    "studies/industry_dynamic.py": "| route | dynamic | steady from [s]",
    "studies/jacobian_check.py": "|J - J_fd|/|J_fd|",
    "studies/mesh_study.py": "| route | default mesh | default [N]",
    "studies/newton_iterates.py": "force calls in",
    "studies/rope_difference_study.py": "| case | gravity | c [mm] | c/R | EJ [N m²]",
    "studies/slow_pull.py": "force [N]",
    "studies/tension_profile.py": "| route | refine | elements | pull [N]",
    "studies/fit_engines.py": "mu_rope",
    "benchmarks/pull_in_history.py": "CPU per point [s]",
    "studies/bundle_bend_study.py": "p/formula",
    "studies/bundle_jam_study.py": "F/formula",
    "studies/bundle_settle_start.py": "| start | dynamic pull CPU [s] |",
    "studies/bundle_dynamic_judge.py": "| from | start's steady pull [N] | status |",
    "studies/bundle_physics_study.py": "| place | arrangement | D/d | μ_c |",
    "studies/checkpoint_study.py": "| case | rule's count | factor | per element |",
    "studies/wall_compliance_study.py": "| case | c [mm] | K [N/m^1.5] | δ/c [-]",
}

# the slowest smoke runs, 10-35 s each on the shared 2-core machine (several processes each importing
# Exudyn and numba, or an industry route of hundreds of elements): run with -m slow
SLOW = {"benchmarks/naive_baseline.py", "benchmarks/run_examples.py", "benchmarks/sweep_scaling.py",
        "benchmarks/sweep_throughput.py",
        "benchmarks/industry_suite.py", "studies/industry_dynamic.py", "benchmarks/bundle_start.py",
        # minutes even in their smoke runs: two cables through four bends; multibody steady runs both ways
        "benchmarks/bundle_route.py", "studies/fit_engines.py",
        # three processes each building a bundle and solving it for 2 s; a dynamic bundle and two steady solves
        "benchmarks/bundle_iteration.py", "studies/bundle_settle_start.py"}


def test_every_script_is_smoke_tested():
    found = {p.relative_to(ROOT).as_posix() for folder in ("benchmarks", "studies")
             for p in (ROOT / folder).glob("*.py")}
    assert found == set(SCRIPTS)


@pytest.mark.parametrize("script", [pytest.param(s, marks=[pytest.mark.slow] if s in SLOW else [], id=Path(s).stem)
                                    for s in SCRIPTS])
def test_quick_mode_prints_its_table(script, tmp_path):
    # a temporary working directory: a script that writes relative paths writes there, not into the tree
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run([sys.executable, str(ROOT / script), "--quick"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"{script} --quick exited {done.returncode}:\n{done.stderr[-3000:]}"
    assert SCRIPTS[script] in done.stdout, f"{script} --quick printed no table header:\n{done.stdout[-3000:]}"
