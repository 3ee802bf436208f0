"""How the engine's objects print and export: one-line reprs and tables of columns.

Reprs are one line: a vector prints as ``[0.1235, -1, 1.571]`` (elided in the middle when long),
an integer as an integer, a string cut and quoted. A result that is a table (a row per point,
member, cycle or run) gives :meth:`Columns.columns` (a dict of equal-length arrays) and, from it,
:meth:`Columns.to_dataframe` (pandas, optional: the ``dataframes`` extra).

Column names mean one thing everywhere: ``x0_1``..``x0_p`` a start configuration x0,
``x_1``..``x_p`` the configuration the row is about (a point of a trajectory, a solve's end, a
cycle's or a leg's end), ``y_1``..``y_r`` the task point k(x), ``y_d_1``..``y_d_r`` a target;
``cycle`` counts from 1, ``leg`` from 1 within its cycle, ``start`` and ``path`` from 0. The
product's other tables (``jik atlas``'s CSV, the dashboard's export) take these names from here
(:func:`coordinate_names`, the results' ``columns()``) and write them with :func:`csv_rows`.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np

from .validation import FloatArray

#: The install line that brings pandas (pyproject.toml's ``dataframes`` extra).
PANDAS_HINT = "pip install 'jik-lab[dataframes]' (or pip install pandas)"


def number(v: Any, digits: int = 4) -> str:
    """A number on one line: an integral value as an integer (``12``), else ``{v:.4g}``."""
    f = float(v)
    if np.isfinite(f) and f == int(f) and abs(f) < 1e15:
        return str(int(f))
    return f"{f:.{digits}g}"


def short_vector(v, digits: int = 4) -> str:
    """A vector on one line, ``[0.1235, -1, 1.571]``; a long one elided in the middle."""
    a = np.asarray(v, dtype=float).ravel()
    items = [f"{t:.{digits}g}" for t in a]
    if len(items) > 8:
        items = [*items[:3], "...", *items[-3:]]
    return "[" + ", ".join(items) + "]"


def plural(n: int, noun: str) -> str:
    """``1 cycle``, ``2 cycles``: a count with its noun."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def short_text(text: str, width: int = 60) -> str:
    """``text`` cut to ``width`` characters, quoted."""
    return repr(text if len(text) <= width else text[: width - 3] + "...")


def short_value(v: Any) -> str:
    """Any parameter's value on one line: numbers, vectors, matrices (rows elided), strings,
    mappings, and other objects by their own repr."""
    if isinstance(v, bool) or v is None:
        return repr(v)
    if isinstance(v, (int, float, np.integer, np.floating)):
        return number(v)
    if isinstance(v, str):
        return short_text(v, 40)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k}: {short_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple, np.ndarray)):
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            return "[" + ", ".join(short_value(x) for x in v) + "]"
        if a.ndim == 2:
            rows = [short_vector(r) for r in a]
            if len(rows) > 4:
                rows = [*rows[:2], "...", rows[-1]]
            return "[" + ", ".join(rows) + "]"
        return short_vector(a)
    return repr(v)


def json_values(v: Any) -> Any:
    """``v`` as JSON values, the one rule of every ``as_dict()``: arrays become nested lists,
    numpy scalars Python ones, and a missing value (NaN, or an infinity) None, as ``null``
    in JSON, which has neither; through dicts, lists and tuples. A table
    (:meth:`Columns.columns`, ``to_dataframe()``) keeps NaN, as pandas does."""
    if isinstance(v, dict):
        return {k: json_values(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [json_values(x) for x in v]
    if isinstance(v, np.ndarray) and v.dtype.kind == "f":
        if np.isfinite(v).all():
            return v.tolist()
        out = v.astype(object)
        out[~np.isfinite(v)] = None
        return out.tolist()
    if isinstance(v, np.ndarray | np.generic):
        return json_values(v.tolist()) if v.dtype.kind in "fO" else v.tolist()
    if isinstance(v, float):
        return v if np.isfinite(v) else None
    return v


def call_repr(name: str, *args: Any, **kwargs: Any) -> str:
    """``name(arg, ..., key=value, ...)`` with each value by :func:`short_value` (positional
    arguments that are already text are kept as they are)."""
    parts = [a if isinstance(a, str) else short_value(a) for a in args]
    parts += [f"{k}={short_value(v)}" for k, v in kwargs.items()]
    return f"{name}({', '.join(parts)})"


def dataframe(columns: dict[str, Any]):
    """A pandas DataFrame of ``columns`` (pandas is imported here, and only here)."""
    try:
        import pandas as pd
    except ImportError:
        raise ImportError(
            f"to_dataframe() needs pandas: {PANDAS_HINT}; columns() gives the same columns as "
            "numpy arrays"
        ) from None
    return pd.DataFrame(columns)


def coordinate_names(name: str, n: int) -> list[str]:
    """``[name_1, ..., name_n]``: the columns of a vector's n coordinates, numbered from 1."""
    return [f"{name}_{k + 1}" for k in range(n)]


def coordinate_columns(name: str, values: FloatArray) -> dict[str, FloatArray]:
    """``{name_1: values[:, 0], name_2: ...}``: one column per coordinate, numbered from 1."""
    values = np.asarray(values, dtype=float)
    names = coordinate_names(name, values.shape[1])
    return {n: values[:, k] for k, n in enumerate(names)}


def csv_rows(columns: dict[str, Any], block: int = 1024) -> Iterator[tuple[str, ...]]:
    """The rows of a table's :meth:`Columns.columns` as text cells for :func:`csv.writer`
    (the header is ``list(columns)``): a number as Python prints it (``repr``, which reads back
    exactly), NaN as an empty cell, a boolean as ``True``/``False`` (as pandas writes them).
    Cells are made ``block`` rows at a time, so a large table's text is never held whole."""

    def cells(column) -> list[str]:
        if column.dtype.kind == "f":
            return ["" if v != v else repr(v) for v in column.tolist()]  # (v != v: NaN)
        return [str(v) for v in column.tolist()]

    arrays = [np.asarray(c) for c in columns.values()]
    rows = len(arrays[0]) if arrays else 0
    for lo in range(0, rows, block):
        yield from zip(*(cells(a[lo : lo + block]) for a in arrays), strict=True)


def csv_text(blocks: Iterable[dict[str, Any]], newline: str = "\r\n") -> Iterator[str]:
    """The CSV text of a table given as blocks of its rows (each a :meth:`Columns.columns`
    dict, all with the same columns): the header (the column names) and the first block's rows,
    then each further block's rows, one block's text at a time (cells by :func:`csv_rows`,
    lines ended by ``newline``, by default ``\\r\\n`` as :func:`csv.writer` ends them)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator=newline)
    for k, block in enumerate(blocks):
        if k == 0:
            writer.writerow(list(block))
        writer.writerows(csv_rows(block))
        yield buffer.getvalue()
        buffer.seek(0)
        buffer.truncate()


class Columns:
    """A result that is a table: :meth:`columns` gives it as arrays, :meth:`to_dataframe` as
    a pandas DataFrame (the same columns, in the same order)."""

    def columns(self) -> dict[str, Any]:
        """One array per column, all of one length: a row per item of the result."""
        raise NotImplementedError

    def to_dataframe(self):
        """:meth:`columns` as a pandas DataFrame (needs pandas: the ``dataframes`` extra)."""
        return dataframe(self.columns())
