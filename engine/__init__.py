"""jik's engine: repeatable Jacobian inverse kinematics (Tchoń, Karpińska, Janiak, 2009).

One import gives the whole library; each name is loaded from its module when first used, so
``import jik.engine`` itself costs nothing (numpy, scipy and sympy come with what needs them,
yourdfpy only with a URDF robot).

>>> import numpy as np
>>> import jik.engine as jik
>>> arm = jik.Manipulator2()
>>> x0, path = [0, 0, np.pi / 2], [(1, 1), (1, 2), (0, 2)]
>>> pinv = jik.repeatability(jik.Pseudoinverse(arm), x0, path, cycles=3)
>>> ext = jik.repeatability(jik.ExtendedInverse(arm, jik.PaperCubic()), x0, path, cycles=3)
>>> print(pinv.drift.round(3), ext.drift.max() < 1e-9)  # the drift after each cycle
[0.461 0.88  1.254] True

Robots (kinematics k: R^p -> R^r, eq. (4))
    Manipulator1, Manipulator2  the paper's manipulators, eqs. (30) and (37)
    Unicycle                    the unicycle with a Fourier control, eqs. (40)-(42)
    PlanarChain                 a planar chain of revolute and prismatic joints
    FormulaKinematics           a robot given by formulas (parsed, never eval'd)
    UrdfChain                   a serial arm from URDF text (needs yourdfpy)
    robot_from_dict, load_robot a robot and its maps from a dict, a JSON/YAML file or a name
    Robot, Kinematics, ROBOTS   a built robot; the base class; the built-in catalogue
    ARMS                        real arms (panda, iiwa14, gen3, ur5e): {"name": "panda"}
    LimitsReport                whether a run stayed within the joint limits (Robot.limits_report)
    RobotUnits, robot_units     the units of x and y, joint names, limits, home (Robot.units)
Augmenting maps h (eq. (9))
    PaperCubic                  the paper's cubic (38) for Manipulator 2
    E1Optimal, E2Optimal        Manipulator 1's optimal maps, eqs. (32) and (36)
    FormulaMap                  h given by a formula
    CharacteristicsMap, UnicycleCharacteristics  h by the method of characteristics (sec. 4)
    AugmentingMap               the base class
Inverses (right inverses of the Jacobian)
    Pseudoinverse               J# = J^T (J J^T)^-1, eq. (8): fast, not repeatable
    ExtendedInverse             the extended Jacobian inverse, eq. (11): repeatable
    VectorExtendedInverse       the same for p - r > 1, with p - r maps
    DampedInverse               damped least squares J^T (J J^T + lambda^2 I)^-1 (Wampler 1986)
    WeightedInverse             weighted least-norm inverse for joint limits (Chan, Dubey 1995)
    PostureInverse              pseudoinverse plus a null-space pull to a rest posture (Liegeois)
    Inverse, make_inverse       the base class; an inverse by name from the catalogue
    ALGORITHMS                  the catalogue of the five algorithms and their parameters
Solving (the continuation algorithm, eq. (7))
    solve                       one start to one target -> SolveResult
    solve_batch                 many starts or targets at once -> BatchSolveResult
    Trajectory                  a run point by point
Repeatability (sec. 5.2.1, Table 1)
    repeatability               drive a closed path cycle after cycle -> RepeatabilityResult
    repeatable, h_change        whether every cycle came back to x0; how much h changed, eq. (12)
    RepeatabilityResult.findings  what a run found, and why (h kept, eq. (12)), in sentences
    Finding                     one such sentence: text, role, algorithm
    run_findings, extended_why  the same from a run's pieces (drift, h, mode, gamma)
    practical_findings          what a damped, weighted or posture inverse's parameters did
    Resume, Leg                 an earlier run to go on from (as x0); a leg as a progress sees it
    Progress, ProgressCallbacks what a long computation reports, and how to cancel it
Functionals and synthesis (secs. 3-4)
    error_functional_e1, error_functional_e2  E1, eq. (14), and E2, eq. (19), on a region,
                                of one map h or a vector of p - r maps (E2 in a kernel frame)
    functionals_report          both as data on a region of any dimension (Sobol rule past 3)
    synthesize_e2               the E2-optimal h by a Ritz method, eq. (20) -> SynthesisResult
    synthesize_e2_nd            E2-optimal h of all joints, p - r >= 1 -> TotalDegreeSynthesis
    map_singularities           where h or [J; dh] (10) is singular in a box -> MapSingularities
    inert_variables             the joint variables that J, h and dh do not depend on
    map_grid                    h on the plane of a box where it varies most -> MapGrid
The atlas (drift over many starts and paths)
    plan_atlas, run_atlas       plan and run an atlas (here, in processes or on Dask)
    iter_atlas                  the same, chunk by chunk, in bounded memory
    AtlasPlan, AtlasResult      the plan and the gathered result
    manifold_starts             starts on a self-motion manifold of p - r > 1 (no curve)
Errors (jik.engine.exceptions)
    JikError                    the base of every error below but RunCancelled
    InvalidInputError, FormulaError  bad input (``error.field`` names it); a formula's syntax
    SingularConfigurationError, KinematicSingularityError, AlgorithmicSingularityError,
    OneFormUndefinedError       J# undefined at ``error.configuration`` (``error.field``: its input)
    RunCancelled                a Progress said the work is no longer wanted

Every numeric function takes a leading batch axis. Robots, maps and inverses print as what they
compute (``ExtendedInverse(Manipulator2(p=3, r=2, l=1), map=PaperCubic())``); results print on
one line and export their numbers: ``as_dict()`` (JSON-friendly; a run's algorithm, inverse,
mode and gamma included), ``columns()`` (a dict of arrays, a row per item) and ``to_dataframe()``
(the same columns in pandas: ``pip install 'jik-lab[dataframes]'``). Column names mean one thing
everywhere: ``x0_1``.. a start, ``x_1``.. the row's configuration (a trajectory's point, a solve's,
a cycle's or a leg's end), ``y_1``.. its task point, ``y_d_1``.. a target; ``jik atlas``'s CSV and
the dashboard's export use the same names.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

# Each public name and the module (under jik.engine) that defines it.
_EXPORTS = {
    # robots
    "Kinematics": "kinematics",
    "Manipulator1": "kinematics",
    "Manipulator2": "kinematics",
    "Unicycle": "unicycle",
    "PlanarChain": "planar_chain",
    "FormulaKinematics": "formula_kinematics",
    "UrdfChain": "urdf",
    "Robot": "robot_spec",
    "robot_from_dict": "robot_spec",
    "load_robot": "robot_spec",
    "ROBOTS": "registry",
    "ARMS": "arms",
    "LimitsReport": "limits",
    "RobotUnits": "units",
    "robot_units": "units",
    # augmenting maps
    "AugmentingMap": "augmentations",
    "PaperCubic": "augmentations",
    "E1Optimal": "augmentations",
    "E2Optimal": "augmentations",
    "FormulaMap": "formula_kinematics",
    "CharacteristicsMap": "characteristics",
    "UnicycleCharacteristics": "characteristics",
    # inverses
    "Inverse": "inverses",
    "Pseudoinverse": "inverses",
    "ExtendedInverse": "inverses",
    "VectorExtendedInverse": "extended_vector",
    "make_inverse": "registry",
    "ALGORITHMS": "registry",
    "DampedInverse": "practical_inverses",
    "WeightedInverse": "practical_inverses",
    "PostureInverse": "practical_inverses",
    # solving
    "solve": "solver",
    "solve_batch": "solver",
    "SolveResult": "results",
    "BatchSolveResult": "results",
    "Trajectory": "results",
    # repeatability
    "repeatability": "repeatability",
    "RepeatabilityResult": "repeatability_result",
    "Resume": "run_settings",
    "Leg": "repeatability",
    "repeatable": "repeatability",
    "h_change": "augmentations",
    "run_findings": "findings",
    "Finding": "findings",
    "extended_why": "findings",
    "practical_findings": "practical_findings",
    "Progress": "progress",
    "ProgressCallbacks": "progress",
    # functionals and synthesis
    "error_functional_e1": "functionals",
    "error_functional_e2": "functionals",
    "functionals_report": "functional_report",
    "synthesize_e2": "variational",
    "synthesize_e2_nd": "synthesis_nd",
    "TotalDegreeSynthesis": "synthesis_nd_result",
    "SynthesisResult": "variational",
    "map_singularities": "map_singularities",
    "inert_variables": "dependence",
    "MapSingularities": "map_singularities",
    "map_grid": "map_grid",
    "MapGrid": "map_grid",
    # the atlas
    "plan_atlas": "atlas",
    "AtlasPlan": "atlas",
    "run_atlas": "atlas_run",
    "iter_atlas": "atlas_run",
    "manifold_starts": "redundant_starts",
    "AtlasResult": "atlas_table",
    # errors
    "JikError": "exceptions",
    "InvalidInputError": "exceptions",
    "FormulaError": "exceptions",
    "SingularConfigurationError": "exceptions",
    "KinematicSingularityError": "exceptions",
    "AlgorithmicSingularityError": "exceptions",
    "OneFormUndefinedError": "exceptions",
    "RunCancelled": "exceptions",
}

__all__ = [
    "ALGORITHMS",
    "ARMS",
    "ROBOTS",
    "AlgorithmicSingularityError",
    "AtlasPlan",
    "AtlasResult",
    "AugmentingMap",
    "BatchSolveResult",
    "CharacteristicsMap",
    "DampedInverse",
    "E1Optimal",
    "E2Optimal",
    "ExtendedInverse",
    "Finding",
    "FormulaError",
    "FormulaKinematics",
    "FormulaMap",
    "InvalidInputError",
    "Inverse",
    "JikError",
    "KinematicSingularityError",
    "Kinematics",
    "Leg",
    "LimitsReport",
    "Manipulator1",
    "Manipulator2",
    "MapGrid",
    "MapSingularities",
    "OneFormUndefinedError",
    "PaperCubic",
    "PlanarChain",
    "PostureInverse",
    "Progress",
    "ProgressCallbacks",
    "Pseudoinverse",
    "RepeatabilityResult",
    "Resume",
    "Robot",
    "RobotUnits",
    "RunCancelled",
    "SingularConfigurationError",
    "SolveResult",
    "SynthesisResult",
    "TotalDegreeSynthesis",
    "Trajectory",
    "Unicycle",
    "UnicycleCharacteristics",
    "UrdfChain",
    "VectorExtendedInverse",
    "WeightedInverse",
    "error_functional_e1",
    "error_functional_e2",
    "extended_why",
    "functionals_report",
    "h_change",
    "inert_variables",
    "iter_atlas",
    "load_robot",
    "make_inverse",
    "manifold_starts",
    "map_grid",
    "map_singularities",
    "plan_atlas",
    "practical_findings",
    "repeatability",
    "repeatable",
    "robot_from_dict",
    "robot_units",
    "run_atlas",
    "run_findings",
    "solve",
    "solve_batch",
    "synthesize_e2",
    "synthesize_e2_nd",
]  # (the keys of _EXPORTS, written out for tools that read __all__ without running it)


def __getattr__(name: str) -> Any:
    """Load a public name from its module on first use (PEP 562), then keep it here."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'jik.engine' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"jik.engine.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The API, the submodules imported so far and the module's dunders; not the names this
    file imports for its own machinery (``Any``, ``importlib``, ``sys``, ...)."""
    inside = f"{__name__}."
    mine = {
        name
        for name, value in globals().items()
        if name.startswith("__") or getattr(value, "__name__", "").startswith(inside)
    }
    return sorted(mine | set(__all__))


class _Engine(types.ModuleType):
    """The package, whose attribute ``repeatability`` stays the function of that name.

    Importing a submodule sets it as an attribute of its package; the submodule
    ``jik.engine.repeatability`` would then hide the function ``repeatability`` (eagerly
    imported front doors such as pink's and mink's have the function win by importing it last;
    here it wins whenever the submodule is first imported, so imports stay lazy).
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and _EXPORTS.get(name) == name:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Engine


if TYPE_CHECKING:  # what the names are, for type checkers and editors (no import at run time)
    from .arms import ARMS
    from .atlas import AtlasPlan, plan_atlas
    from .atlas_run import iter_atlas, run_atlas
    from .atlas_table import AtlasResult
    from .augmentations import AugmentingMap, E1Optimal, E2Optimal, PaperCubic, h_change
    from .characteristics import CharacteristicsMap, UnicycleCharacteristics
    from .dependence import inert_variables
    from .exceptions import (
        AlgorithmicSingularityError,
        FormulaError,
        InvalidInputError,
        JikError,
        KinematicSingularityError,
        OneFormUndefinedError,
        RunCancelled,
        SingularConfigurationError,
    )
    from .extended_vector import VectorExtendedInverse
    from .findings import Finding, extended_why, run_findings
    from .formula_kinematics import FormulaKinematics, FormulaMap
    from .functional_report import functionals_report
    from .functionals import error_functional_e1, error_functional_e2
    from .inverses import ExtendedInverse, Inverse, Pseudoinverse
    from .kinematics import Kinematics, Manipulator1, Manipulator2
    from .limits import LimitsReport
    from .map_grid import MapGrid, map_grid
    from .map_singularities import MapSingularities, map_singularities
    from .planar_chain import PlanarChain
    from .practical_findings import practical_findings
    from .practical_inverses import DampedInverse, PostureInverse, WeightedInverse
    from .progress import Progress, ProgressCallbacks
    from .registry import ALGORITHMS, ROBOTS, make_inverse
    from .repeatability import Leg, repeatability, repeatable
    from .repeatability_result import RepeatabilityResult
    from .results import BatchSolveResult, SolveResult, Trajectory
    from .robot_spec import Robot, load_robot, robot_from_dict
    from .run_settings import Resume
    from .solver import solve, solve_batch
    from .synthesis_nd import synthesize_e2_nd
    from .synthesis_nd_result import TotalDegreeSynthesis
    from .unicycle import Unicycle
    from .units import RobotUnits, robot_units
    from .urdf import UrdfChain
    from .variational import SynthesisResult, synthesize_e2
