"""exucable: cable pulling tension through 3D conduits on the Exudyn multibody engine.

After Yang, Hong, Ren & Zhao, "Cable installation simulation by using a multibody
dynamic model", Multibody Syst Dyn 30 (2013) 433-447. SI units throughout.

The Python API (see ``examples/``)::

    import exucable as xc
    route = xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0)
    sc = xc.Scenario(route=route, cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                     contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=150.0),
                     solver=xc.Solver(end_time=0.5))
    res = xc.run(sc)

Importing exucable imports neither Exudyn nor matplotlib and changes no global state.
"""

from .version import __version__

# The submodule exucable.run first: importing it after the function of the same name below would
# rebind the package attribute to the module (Python sets it when a submodule is first loaded).
# It is light (no Exudyn, matplotlib or dask at import).
from . import run as _run_module  # noqa: F401
from .api import (
    Cable,
    Contact,
    Gravity,
    History,
    Output,
    Pull,
    Result,
    Route,
    Solver,
    TensionProfile,
    run,
    vary,
)
from .errors import ExucableError, GeometryError, ModelError, ScenarioError, SolverError
from .scenario.specs import Scenario, load_scenario

# The plugin face on Exudyn, imported on first use so that "import exucable" does not load Exudyn.
_PLUGIN = {"add_cable_in_conduit", "CableInConduit", "JoinToMarker", "ReelOnto"}
_LAYOUT = {"initial_layout", "InitialLayout"}  # Exudyn-free, but in the model package


def __getattr__(name):
    if name in _PLUGIN:
        from .model import build
        return getattr(build, name)
    if name in _LAYOUT:
        from .model import layout
        return getattr(layout, name)
    raise AttributeError(f"module 'exucable' has no attribute {name!r}")

__all__ = [
    "__version__",
    "Route", "Cable", "Contact", "Pull", "Gravity", "Solver", "Output", "Scenario", "load_scenario",
    "run", "vary", "Result", "History", "TensionProfile",
    "add_cable_in_conduit", "CableInConduit", "JoinToMarker", "ReelOnto", "initial_layout", "InitialLayout",
    "ExucableError", "ScenarioError", "GeometryError", "ModelError", "SolverError",
]
