"""Table 1 of the paper: repeatability of Manipulator 2 on the path (1,1), (1,2), (0,2), (0,1).

The pseudoinverse column is reproduced to four decimals. The extended column is what the cubic
(38), as printed and with its exact gradient, gives; it differs from the printed column
(docs/paper-errata.md).
"""

from __future__ import annotations

import math

import numpy as np

from ..augmentations import PaperCubic, PaperCubicPrintedGradient
from ..exceptions import InvalidInputError
from ..inverses import ExtendedInverse, Pseudoinverse
from ..kinematics import Manipulator2
from ..repeatability import repeatability
from ..validation import as_points

X0 = (0.0, 0.0, math.pi / 2)
PATH = ((1.0, 1.0), (1.0, 2.0), (0.0, 2.0), (0.0, 1.0))
#: The one target of the paper's Figs. 5-9 (sec. 5.2.1), solved for from X0.
FIGS_5_9_TARGET = (0.0, 2.0)
#: Table 1 as printed (rows x0, x1f, ..., x4f).
PRINTED = {
    "pseudoinverse": [
        [0, 0, 1.5708],
        [0.1132, 0.5379, 1.0904],
        [1.0432, 0.7093, 1.2759],
        [1.0198, 0.1980, 1.7701],
        [0.0529, 0.3210, 1.8976],
    ],
    "extended": [
        [0, 0, 1.5708],
        [0.1208, 0.5235, 1.0741],
        [1.1208, 0.5235, 1.0741],
        [1, 0, 1.5708],
        [0, 0, 1.5708],
    ],
}

#: What the printed row labels A, B, C, D, A name.
ROWS_NOTE = (
    "Row labels as printed: A, B, C, D, A. The rows are x0 (whose task point k(x0) is (0, 1)) "
    "and the configurations after the legs to (1, 1), (1, 2), (0, 2), (0, 1): the paper's "
    "letters name the legs' order, not the square's corners."
)
#: The erratum of the extended column (docs/paper-errata.md), with what :func:`run` gives.
ERRATUM = (
    "Erratum (docs/paper-errata.md, “Table 1 and the cubic (38)”): the printed extended column "
    "is not what the cubic (38) gives. With (38) as printed and its exact gradient, the first leg "
    "ends at (0.0637, 0.6487, 1.2119), where the paper prints (0.1208, 0.5235, 1.0741); the "
    "printed j32, j33 of (39) are not the gradient of (38), and with them the leg ends at "
    "(0.1787, 0.4295, 0.9637), not the printed row either. Both return to x0: the path closes. "
    "jik shows what (38) gives; nothing is tuned to match the print."
)


def row_labels(n: int) -> list[str]:
    """The labels of ``n`` rows, x0 then the leg ends, as Table 1 prints them (``"A  x0"``,
    ``"B  x1f"``, ..., ``"A  x4f"``) and on over more cycles (``"B  x5f"``, ...)."""
    return [f"{'ABCD'[k % 4]}  x{k}f" if k else "A  x0" for k in range(n)]


def corner_letters(targets, start, closed: bool) -> list[str]:
    """The letters of a task's corners (its ``targets`` (L, r), in order), as Table 1 names its
    rows: a ``closed`` path that ends where it starts, at k(x0) = ``start`` (r,), has its start
    as A (Manipulator 2: A = k(x0) = (0, 1), then B = (1, 1), C, D, and A again); any other
    task letters its targets from A (past Z: P27, P28, ...)."""
    targets = np.asarray(targets, dtype=float)
    n = len(targets)
    names = [chr(ord("A") + i) if i < 26 else f"P{i + 1}" for i in range(n)]
    if closed and n > 1 and np.allclose(targets[-1], start, atol=1e-6):
        return names[1:] + names[:1]
    return names


def is_experiment(length: float, x0, path) -> bool:
    """Whether Manipulator 2 with arm length l = ``length`` from ``x0`` on ``path`` is Table 1's
    run: l = 1, x0 = :data:`X0`, the closed path :data:`PATH`."""
    x0, path = np.asarray(x0, dtype=float), np.asarray(path, dtype=float)
    return (
        abs(float(length) - 1.0) < 1e-12
        and x0.shape == np.shape(X0)
        and np.allclose(x0, X0, atol=1e-9)
        and path.shape == np.shape(PATH)
        and np.allclose(path, PATH, atol=1e-12)
    )


def rows(inverse) -> list[list[float]]:
    """x0 and the configuration after each leg of Table 1's path (continuous algorithm (7))."""
    res = repeatability(inverse, np.array(X0), np.array(PATH), cycles=1)
    return [list(X0)] + res.legs.tolist()


def run(printed_gradient: bool = False) -> dict:
    """Table 1 recomputed: {"pseudoinverse": 5 rows, "extended": 5 rows, "augmentation": ...}."""
    kin = Manipulator2()
    h = PaperCubicPrintedGradient() if printed_gradient else PaperCubic()
    return {
        "pseudoinverse": rows(Pseudoinverse(kin)),
        "extended": rows(ExtendedInverse(kin, h)),
        "augmentation": h.name,
    }


def cell(value: float, width: int = 9) -> str:
    """``value`` to four decimals in ``width`` columns (0: as wide as it takes), as Table 1
    prints it: a round-off zero such as -1e-16 prints 0.0000, not -0.0000."""
    return f"{round(float(value), 4) + 0.0:{width}.4f}"


def differing(algorithm: str, rows) -> np.ndarray:
    """Which cells of ``rows`` differ from Table 1's printed column of ``algorithm`` when both
    are printed to four decimals (:func:`cell`), as the paper prints them.

    Parameters
    ----------
    algorithm : {"pseudoinverse", "extended"}
    rows : array_like, shape (n, 3)
        x0 and the configurations after the legs (:func:`rows`), of one cycle or more.

    Returns
    -------
    ndarray of bool, shape (min(n, 5), 3)
        True where the printed digits differ, for the rows the paper prints.
    """
    if algorithm not in PRINTED:
        raise InvalidInputError(
            f"algorithm must be one of {', '.join(PRINTED)}, got {algorithm!r}", "algorithm"
        )
    ours = as_points(rows, 3, "rows")[: len(PRINTED[algorithm])]
    printed = np.asarray(PRINTED[algorithm], dtype=float)[: len(ours)]
    text = np.vectorize(lambda v: cell(v, 0))
    return text(ours) != text(printed)


def format_text(result: dict) -> str:
    """Table 1 laid out as in the paper, with the printed values beside ours."""
    labels = row_labels(5)
    out = []
    for alg, title in (
        ("extended", "Extended Jacobian"),
        ("pseudoinverse", "Jacobian pseudoinverse"),
    ):
        extra = f" (augmentation {result['augmentation']})" if alg == "extended" else ""
        out.append(f"Algorithm: {title}{extra}")
        out.append(f"{'':8}{'x1':>9}{'x2':>9}{'x3':>9}   | printed{'':20}")
        for lab, row, pr in zip(labels, result[alg], PRINTED[alg], strict=True):
            ours = "".join(cell(v) for v in row)
            theirs = "".join(cell(v) for v in pr)
            out.append(f"{lab:8}{ours}   |{theirs}")
        out.append("")
    out.append("Rows: x0 = (0, 0, pi/2) (task point (0, 1)), then after the legs to (1,1), (1,2),")
    out.append("(0,2), (0,1). The extended column of the paper is not reproduced by (38): see")
    out.append("docs/paper-errata.md (`jik errata` prints it).")
    return "\n".join(out)


def not_table1(on_experiment: bool, algorithms: str) -> str:
    """Why a table of Manipulator 2's leg ends is not Table 1: on its experiment
    (``on_experiment``) without both of its algorithms (named ``algorithms``), else not on it."""
    if on_experiment:
        return (
            f"Not Table 1: the paper's Table 1 compares {algorithms} on this experiment; choose "
            "both to compare with the printed values."
        )
    return (
        "Not Table 1: the paper's Table 1 is Manipulator 2 (l = 1) from x0 = "
        "(0, 0, π/2) on the closed path (1, 1), (1, 2), (0, 2), (0, 1); set those "
        "to compare with the printed values."
    )


def notes(rows: dict, augmentation: str, mode: str, gamma: float, others: str = "") -> list[str]:
    """What a table of jik's leg ends beside the printed Table 1 needs said under it: how many
    cells differ from the print in the fourth decimal (:func:`differing`) of the ``rows`` of
    each printed algorithm (x0 and the leg ends, (n, 3)), the printed labels
    (:data:`ROWS_NOTE`), that the columns of the ``others`` algorithms (their names, if any)
    have no printed counterpart, the erratum of the cubic (38) (:data:`ERRATUM`) or which map
    ``augmentation`` was used instead, and whether the ``mode`` (with step ``gamma``) is the
    paper's continuous algorithm (7)."""
    counts = {a: int(differing(a, rows[a]).sum()) for a in PRINTED}
    out = [
        f"Beside each of jik's columns, the paper's printed column (continuous algorithm (7), "
        f"one cycle). Highlighted: jik's cells that differ from the print in the fourth decimal "
        f"(pseudoinverse: {counts['pseudoinverse']} of 15, extended Jacobian: "
        f"{counts['extended']} of 15).",
        ROWS_NOTE,
    ]
    if others:
        out.append(
            f"Then jik's columns of {others}: the paper's Table 1 prints the "
            "pseudoinverse and the extended Jacobian only."
        )
    if augmentation == "paper_cubic":
        out.append(ERRATUM)
    else:
        out.append(
            f"The extended columns here use the augmenting map {augmentation}; "
            "the paper's were computed with the cubic (38) (choose paper_cubic to "
            "compare)."
        )
    if mode != "discrete":
        out.append(
            "Continuous mode, as in the paper: the columns do not depend on γ (it only rescales θ)."
        )
        return out
    gap = max(
        (
            float(np.max(np.abs(np.asarray(rows[a])[: len(p)] - np.asarray(p))))
            for a, p in PRINTED.items()
            if len(rows[a]) >= len(p)
        ),
        default=None,
    )
    where = (
        "stopped before the end of the first cycle"
        if gap is None
        else f"ends its legs elsewhere (up to {gap:.3g} from the printed values)"
    )
    out.append(
        f"Discrete mode changes the numbers: the paper's Table 1 is the continuous "
        f"algorithm (7); the iteration with step γ = {gamma:.3g} {where}. Choose "
        "mode = continuous to compare with the print."
    )
    return out
