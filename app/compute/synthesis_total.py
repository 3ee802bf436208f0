"""``POST /synthesize`` with ``'e2_total_degree'``: E2-optimal maps over any number of joint
variables (:func:`jik.engine.synthesis_nd.synthesize_e2_nd`, eq. (19) on a total-degree Legendre
basis with a scrambled Sobol rule; for p - r >= 2 the maps h_1 ... h_(p-r) of the functional
generalised in ``docs/e2-vector.md``), and the grid of a map on two axes of its box that every
method's response draws.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...engine.exceptions import JikError
from ...engine.map_singularities import map_singularities
from ...engine.robot_synthesis import TOTAL_DEGREE
from ...engine.synthesis_nd import synthesize_e2_nd
from . import schemas as S
from .documents import nullable
from .exceptions import RequestError

#: The engine's fields of a total-degree synthesis, as the request names them (others: region).
_FIELDS = {"degree": "degree", "nodes": "qmc_nodes", "frame_axes": "frame_axes"}


def _grid_axes(amap, names, region, base) -> list[str]:
    """The two region variables along which h varies most (mean |dh/dx_i| on seeded samples)."""
    if len(region) <= 2:
        return list(region)
    rng = np.random.default_rng(0)
    x = np.broadcast_to(base, (64, len(base))).copy()
    for k, (lo, hi) in region.items():
        x[:, names.index(k)] = rng.uniform(lo, hi, 64)
    with np.errstate(all="ignore"):
        try:
            g = np.abs(np.asarray(amap.gradient(x), dtype=float))
        except JikError:
            return list(region)[:2]
    score = {k: float(np.nanmean(g[:, names.index(k)])) for k in region}
    top = sorted(region, key=lambda k: -(score[k] if np.isfinite(score[k]) else -1.0))[:2]
    return [k for k in region if k in top]


def grid(amap, names, region, fixed, p: int, n: int) -> S.SynthesisGrid | None:
    if len(region) < 2:
        return None
    base = np.zeros(p)
    for k, v in fixed.items():
        base[names.index(k)] = v
    for k, (lo, hi) in region.items():
        base[names.index(k)] = 0.5 * (lo + hi)
    axes = _grid_axes(amap, names, region, base)
    a, b = (np.linspace(region[k][0], region[k][1], n) for k in axes)
    x = np.broadcast_to(base, (n, n, p)).copy()
    x[..., names.index(axes[0])] = a[:, None]
    x[..., names.index(axes[1])] = b[None, :]
    with np.errstate(all="ignore"):
        try:
            h = np.asarray(amap.value(x), dtype=float)
        except JikError:  # a map that raises where it is undefined: evaluate point by point
            h = np.full((n, n), np.nan)
            for i in range(n):
                for j in range(n):
                    try:
                        h[i, j] = float(amap.value(x[i, j]))
                    except JikError:
                        pass
    return S.SynthesisGrid(axes={axes[0]: a.tolist(), axes[1]: b.tolist()}, h=nullable(h))


def singularities(
    kin, amap, region, fixed, nodes: int
) -> tuple[S.MapSingularitiesInfo | None, list[str], bool]:
    """Where h is singular in the box (:func:`jik.engine.map_singularities.map_singularities`
    on a grid of ``nodes`` points per variable, as many as E1's and E2's Gauss rule: a
    polynomial map costs as much there), what the response's message says of it, and whether
    it was searched: not for a map that solves a problem per point (a characteristic's, eq.
    (28): seconds for a grid), as the dashboard does not either, nor where the search does
    not apply (a vector of maps, too large a grid)."""
    if amap.solves_per_point:
        return None, ["singularities of h not searched: each value of h solves a problem"], False
    try:
        found = map_singularities(kin, amap, region, fixed=fixed, nodes=nodes)
    except JikError as exc:
        return None, [f"singularities of h not searched: {exc}"], False
    if found is None:
        return None, [], True
    info = S.MapSingularitiesInfo.model_validate(found.as_dict())
    return info, [f"h is singular in the box: {found}"], True


def total_degree_response(
    req: S.SynthesizeRequest, spec, kin, robot_used: S.RobotUsed, box: tuple[list[str], dict, dict]
) -> S.SynthesizeResponse:
    """The E2-optimal map(s) of ``req`` on its box (names, region, fixed values): E2 on the
    fitting rule and on an independent one, its convergence with the degree and the nodes,
    h_1 on a grid, the basis and coefficients."""
    names, region, fixed = box
    if req.augmentation is not None:
        raise RequestError("augmentation", "'e2_total_degree' synthesizes h; give no map")
    degree = TOTAL_DEGREE if req.degree is None else req.degree
    try:
        res = synthesize_e2_nd(
            kin,
            region,
            degree=degree,
            nodes=req.qmc_nodes,
            fixed=fixed,
            seed=req.seed,
            frame_axes=req.frame_axes,
            convergence_degrees=range(1, degree),
        )
    except JikError as exc:
        raise RequestError(
            _FIELDS.get(getattr(exc, "field", None) or "", "region"), str(exc)
        ) from None
    info: dict[str, Any] = {
        k: v for k, v in res.as_dict().items() if k not in ("region", "fixed", "convergence")
    }
    info["basis"] = res.maps[0].index.tolist()
    info["coefficients"] = [m.coefficients.tolist() for m in res.maps]
    all_fixed = {n: float(res.fixed.get(n, fixed.get(n, 0.0))) for n in names if n not in region}
    notes = [
        f"E2 {res.e2:.6g} on the fitting rule, {res.e2_check:.6g} on an independent rule "
        f"of {res.nodes} nodes ({len(info['coefficients'][0])} unknowns per map)"
    ]
    if res.single_joint:
        j, best = min(res.single_joint.items(), key=lambda item: item[1]["e2"])
        notes.append(
            f"the best single joint, h = {'-' if best['sign'] < 0 else ''}{j}, has "
            f"E2 {best['e2']:.6g}"
        )
    if len(res.maps) > 1:
        notes.append(f"{len(res.maps)} maps h_1 ... h_{len(res.maps)}; the grid shows h_1")
    notes.append("E1 is not evaluated (its Gauss rule grows as nodes^d)")
    found, more, searched = singularities(kin, res.maps[0], res.region, all_fixed, req.nodes)
    return S.SynthesizeResponse(
        robot=robot_used,
        method=req.method,
        augmentation=S.AugmentationUsed(
            name=res.maps[0].name,
            parameters={
                "degree": float(degree),
                "unknowns": float(len(res.maps[0].index)),
                "maps": float(len(res.maps)),
            },
        ),
        region={k: [float(lo), float(hi)] for k, (lo, hi) in res.region.items()},
        fixed=all_fixed,
        grid=grid(res.maps[0], names, res.region, all_fixed, spec.p, req.grid),
        coefficients={},
        functionals={
            "e1": None,
            "e2": S.FunctionalInfo(
                value=nullable(res.e2_check), n_points=res.nodes, n_singular=0, min_abs_dh_k=None
            ),
        },
        convergence=[{k: float(v) for k, v in row.items()} for row in res.convergence],
        singularities=found,
        singularities_searched=searched,
        total_degree=S.TotalDegreeInfo(**info),
        message="; ".join(notes + more),
    )
