"""The dashboard: one live state per session, solved by its chosen algorithms, drawn as figures.

Modules: :mod:`~jik.app.dashboard.controls` (the controls, described once),
:mod:`.control_changes` (a change of controls as a change of the state), :mod:`.model` (the
state), :mod:`.algorithms` (the chosen algorithms, one style each), :mod:`.runs` and
:mod:`.results` (a state solved), :mod:`.offload` (the shared compute processes),
:mod:`.analysis` (h on a grid), :mod:`.functionals` (E1/E2), :mod:`.figures` (plotly panels),
:mod:`.messages` (events and listeners), :mod:`.session` (the live :class:`Dashboard`),
:mod:`.sessions` (one per tab, bounded), :mod:`.export` (JSON and CSV). The names below are the
public surface.
"""

from .algorithms import COLORS, LABELS, runs_key
from .algorithms import DEFAULT_ALGORITHMS as ALGORITHMS  # (the algorithms of a new state)
from .export import export_csv, export_file, export_json
from .messages import Event
from .model import DashboardState, default_state, updated_state
from .offload import OffloadLane
from .results import compute
from .runs import AlgorithmRun, Cancelled, DashboardResult
from .session import Dashboard

__all__ = [
    "ALGORITHMS",
    "COLORS",
    "LABELS",
    "AlgorithmRun",
    "Cancelled",
    "Dashboard",
    "DashboardResult",
    "DashboardState",
    "Event",
    "OffloadLane",
    "compute",
    "default_state",
    "export_csv",
    "export_file",
    "export_json",
    "runs_key",
    "updated_state",
]
