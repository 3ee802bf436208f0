"""jik: a lab for repeatable Jacobian inverse kinematics.

The installed package holds the computation (:mod:`jik.engine`: numpy, scipy and sympy only), the
web service and dashboard (:mod:`jik.app`, with the ``app`` extra), the page's files
(:mod:`jik.static`), the benchmarks (:mod:`jik.benchmarks`) and the ``jik`` command
(:mod:`jik.cli`, also ``python -m jik``). Its distribution is named ``jik-lab`` (the name ``jik``
on the package index belongs to another project): ``pip install 'jik-lab[app]'``.
"""

__version__ = "0.1.0"

#: The distribution's name on the package index; the import package and the command are ``jik``.
DISTRIBUTION = "jik-lab"


def install_hint(extra: str) -> str:
    """The command that adds ``extra``, from the package index or in a source checkout."""
    return f"pip install '{DISTRIBUTION}[{extra}]' (in a source checkout: pip install '.[{extra}]')"
