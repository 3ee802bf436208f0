"""jik: a lab for repeatable Jacobian inverse kinematics.

The installed package holds the computation (:mod:`jik.engine`: numpy, scipy and sympy only), the
web service and dashboard (:mod:`jik.app`, with the ``jik[app]`` extra), the page's files
(:mod:`jik.static`), the benchmarks (:mod:`jik.benchmarks`) and the ``jik`` command
(:mod:`jik.cli`, also ``python -m jik``).
"""

__version__ = "0.1.0"
