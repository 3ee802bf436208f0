"""The figures a :class:`~jik.app.dashboard.session.Dashboard` sends, as JSON: the panels of a
result with sticky axes (each against the layout it last went out with, for the same robot and
task), and which panels wait for the second phase (E1/E2 not known yet for the state)."""

from __future__ import annotations

from .figures import figure_specs
from .functionals import functionals_key
from .model import DashboardState
from .plotting import figure_json, keep_ranges
from .runs import DashboardResult


class PanelTexts:
    """The dashboard's panel JSON (a part of :class:`~jik.app.dashboard.session.Dashboard`,
    used by its worker thread only)."""

    _layouts: dict[str, tuple[tuple, dict]]  # panel -> (robot, task), last layout
    # key -> (E1/E2 functionals or None, their sensitivity)
    _functionals_cache: dict[str, tuple[dict | None, dict]]

    def _known_functionals(self, state: DashboardState) -> tuple[tuple | None, set[str]]:
        """E1/E2 and their sensitivity for ``state`` when known (same map, same fixed
        variables), and the panels that wait for the second phase: the E1/E2 panel unless
        known (the page dims it meanwhile instead of redrawing a placeholder, 20-40 ms of its
        redraw)."""
        cached = self._functionals_cache.get(functionals_key(state))
        return cached, (set() if cached else {"sensitivity"})

    def _panel_texts(
        self, result: DashboardResult, functionals, sens, todo: set[str], remember: bool
    ) -> dict[str, str]:
        """The JSON of the panels in ``todo``, with sticky axes (keep_ranges): against the
        layout each panel last went out with, for the same robot and task. ``remember``: these
        panels go out now (a result, not one solved ahead)."""

        layout_key = (result.state.robot, result.state.task)
        texts = {}
        for k, f in figure_specs(result, functionals, todo, sensitivity=sens).items():
            shown = self._layouts.get(k)
            keep_ranges(f, shown[1] if shown is not None and shown[0] == layout_key else None)
            if remember:
                self._layouts[k] = (layout_key, f["layout"])
            texts[k] = figure_json(f)
        return texts
