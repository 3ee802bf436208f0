"""jik: a lab for repeatable Jacobian inverse kinematics.

The installed package holds the computation (:mod:`jik.engine`: numpy, scipy and sympy only), the
web service and dashboard (:mod:`jik.app`, with the ``app`` extra), the page's files
(:mod:`jik.static`), the benchmarks (:mod:`jik.benchmarks`) and the ``jik`` command
(:mod:`jik.cli`, also ``python -m jik``). Its distribution is named ``jik-lab`` (the name ``jik``
on the package index belongs to another project): ``pip install 'jik-lab[app]'``.
"""

import os as _os

__version__ = "0.1.0"

# In a source checkout, jik's subpackages are the top-level folders engine/, app/, static/ and
# benchmarks/ (pyproject.toml's package-dir). Where this jik/ is imported from such a checkout
# without an editable install (a notebook started at its root, where the folder comes first on
# sys.path), the checkout's root is searched for them too; an installed jik holds them inside.
_HERE = _os.path.dirname(_os.path.abspath(__file__))
if not _os.path.isdir(_os.path.join(_HERE, "engine")) and _os.path.isfile(
    _os.path.join(_os.path.dirname(_HERE), "engine", "__init__.py")
):
    __path__.append(_os.path.dirname(_HERE))

#: The distribution's name on the package index; the import package and the command are ``jik``.
DISTRIBUTION = "jik-lab"


def install_hint(extra: str) -> str:
    """The command that adds ``extra``, from the package index or in a source checkout."""
    return f"pip install '{DISTRIBUTION}[{extra}]' (in a source checkout: pip install '.[{extra}]')"
