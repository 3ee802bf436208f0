"""The augmenting maps of a robot defined by data (:func:`jik.engine.robot_spec.robot_from_dict`):
formula maps, one per degree of redundancy, and E2-optimal syntheses on a region, eq. (9)."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from . import robot_kinds
from .augmentations import AugmentingMap
from .exceptions import InvalidInputError
from .formula_kinematics import FormulaMap
from .functionals import check_region
from .kernel_frame import check_frame_axes
from .kinematics import Kinematics
from .registry import AugmentationSpec
from .robot_synthesis import (
    MAX_TENSOR_DEGREE,
    MAX_TOTAL_DEGREE,
    default_degree,
    synthesis,
    vector_synthesis,
)
from .validation import count


def augmentations_from_dict(kin: Kinematics, items, key: str | None = None):
    """AugmentationSpecs of ``[{"name": "formula", "h": ...}, {"name": "e2_synthesized", ...}]``,
    the synthesis region of the first e2_synthesized (the robot's functional region), and the
    vectors of p - r formula maps (p > r + 1: ``"h"`` is a list), by label. ``key`` names the
    robot's definition: with it, a synthesized map is computed once per process for it."""
    if not isinstance(items, list):
        raise InvalidInputError("augmentations must be a list of augmenting maps", "augmentations")
    specs: list[AugmentationSpec] = []
    region: dict = {}
    vectors: dict[str, tuple[AugmentingMap, ...] | Callable[[], tuple[AugmentingMap, ...]]] = {}
    k = kin.p - kin.r
    for i, item in enumerate(items):
        where = f"augmentations.{i}"
        if not isinstance(item, Mapping) or item.get("name") not in ("formula", "e2_synthesized"):
            raise InvalidInputError(
                f"{where} must be {{'name': 'formula', 'h': ...}} or "
                "{'name': 'e2_synthesized', 'region': {...}}",
                where,
            )
        if k == 0:
            raise InvalidInputError(
                f"{where}: an augmenting map needs redundancy (p > r), and this robot has "
                f"p = r = {kin.p}: its Jacobian is square, so no map can be added; remove it "
                "(the pseudoinverse is then J^-1)",
                where,
            )
        label = robot_kinds.one_line(item.get("label", item["name"]), f"{where}.label")
        if label in {s.name for s in specs}:
            raise InvalidInputError(
                f"{where}.label must be a new name, got {label!r}", f"{where}.label"
            )
        factory: Callable[..., AugmentingMap]
        if item["name"] == "formula":
            unknown = set(item) - robot_kinds.augmentation_keys("formula")
            maps = _formula_maps(kin, item, where)
            if k == 1:
                factory = lambda kin, amap=maps[0]: amap  # noqa: E731
            else:
                vectors[label] = maps
                factory = _vector_only(label)
            text = "h = " + ", ".join(m.text for m in maps)
        else:
            unknown = set(item) - robot_kinds.augmentation_keys("e2_synthesized")
            box, fix = _region(kin, item, where)
            tensor = len(box) <= 3 and k == 1  # (else a total-degree basis, at most 6)
            given = item.get("degree", default_degree(len(box), k))
            field = f"{where}.degree"
            top = MAX_TENSOR_DEGREE if tensor else MAX_TOTAL_DEGREE
            degree = count(given, field, 1, top, field)
            if tensor:
                text = f"E2-optimal h on {box} by the Ritz solve of (20), degree {degree}"
            else:
                text = (
                    f"E2-optimal h of {len(box)} joints on {box}: Ritz solve of (19) in a "
                    f"total-degree {degree} basis on a Sobol rule"
                )
            axes = check_frame_axes(kin, item.get("frame_axes"), f"{where}.frame_axes")
            if k == 1:
                factory = synthesis(box, fix, degree, key)
            else:
                vectors[label] = vector_synthesis(kin, box, fix, degree, key, axes)
                factory = _vector_only(label)
                text = text.replace("E2-optimal h", f"E2-optimal h_1..h_{k}")
            region = region or box
        if unknown:
            raise InvalidInputError(f"{where}: unknown key(s) {sorted(unknown)}", where)
        specs.append(AugmentationSpec(label, "(9)", text, (), factory))
    return tuple(specs), region, vectors


def _formula_maps(kin: Kinematics, item: Mapping, where: str) -> tuple[FormulaMap, ...]:
    """One map for p = r + 1 (``h`` a formula), p - r of them for more (``h`` a list)."""
    k, h = kin.p - kin.r, item.get("h", "")
    texts = [h] if k == 1 else h
    if not isinstance(texts, list) or len(texts) != k:
        raise InvalidInputError(
            f"{where}.h must be "
            + (
                "a formula"
                if k == 1
                else f"a list of {k} formulas (p - r = {k}: one map per degree of redundancy)"
            ),
            f"{where}.h",
        )
    names, params = kin.variable_names, item.get("parameters")
    fields = [f"{where}.h"] if k == 1 else [f"{where}.h.{j}" for j in range(k)]
    return tuple(FormulaMap(t, names, params, field=f) for t, f in zip(texts, fields, strict=True))


def _vector_only(label: str) -> Callable[..., AugmentingMap]:
    def refuse(kin: Kinematics) -> AugmentingMap:
        raise InvalidInputError(
            f"augmentation {label!r} is a vector of maps (p - r > 1): build its extended "
            "inverse with Robot.inverse",
            "augmentation",
        )

    return refuse


def _region(kin: Kinematics, item: Mapping, where: str):
    if "region" not in item:  # (an arm's maps take its box around home: arm_augmentations)
        raise InvalidInputError(
            f"{where}.region is required: only an arm with a home has a default box to "
            f"synthesize on; give two or more of {list(kin.variable_names)} to [lo, hi]",
            f"{where}.region",
        )
    try:
        box, fix = check_region(kin, item.get("region", {}), item.get("fixed"))
    except InvalidInputError as exc:
        field = f"{where}.{exc.field or 'region'}"  # (region.x2, fixed.x1)
        raise InvalidInputError(f"{field}: {exc}", field) from None
    if len(box) < 2:
        raise InvalidInputError(
            f"{where}.region must have at least two variables", f"{where}.region"
        )
    k = kin.p - kin.r
    if len(box) < k:  # (h_1..h_k of fewer variables: rank dh < k, [J; dh] singular everywhere)
        raise InvalidInputError(
            f"{where}.region must vary at least p - r = {k} of the joints "
            f"{list(kin.variable_names)}, got {sorted(box)}: maps h_1..h_{k} of fewer have a "
            "derivative dh of rank below p - r, so the extended Jacobian [J; dh] of eq. (10) is "
            "singular everywhere",
            f"{where}.region",
        )
    return box, fix
