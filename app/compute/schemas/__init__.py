"""Request and response models of the REST API (JSON, snake_case), one module per job.

- :mod:`.fields`: the shared field types and size limits;
- :mod:`.robots`: the robots and augmenting maps (generated from the engine's catalogue, and the
  robots a user defines), as requests name them and responses echo them;
- :mod:`.variants`: a request model made exact for each robot (what a route takes);
- :mod:`.runs`: ``/solve`` and ``/repeatability``; :mod:`.synthesis`: ``/synthesize``;
- :mod:`.info`: ``/robots``, ``/health`` and the error body.

Everything is re-exported here, by the imports below: ``from jik.app.compute import schemas as
S`` (their names are this package's API; ``pyproject.toml`` lets ruff keep them unused here).
"""

from .algorithms import Algorithm, AlgorithmParameters
from .fields import (
    COORDINATE_BOUND,
    GAMMA_MIN,
    INTEGRAL,
    MAX_DIMENSION,
    MAX_ITERATIONS,
    MAX_TRAJECTORY_POINTS,
    Bound,
    Coordinate,
    FiniteFloat,
    Gamma,
    MaybeFloat,
    Mode,
    Tolerance,
    Vector,
)
from .info import (
    BUSY,
    AlgorithmInfo,
    AugmentationInfo,
    ErrorResponse,
    HealthResponse,
    Limits,
    ParameterInfo,
    RobotInfo,
    RobotsResponse,
)
from .robots import (
    AUGMENTATION_MODELS,
    MAX_FORMULA_CHARS,
    MAX_URDF_CHARS,
    ROBOT_MODELS,
    ROBOT_NAMES,
    USER_AUGMENTATION_MODELS,
    USER_ROBOT_MODELS,
    AnyAugmentation,
    AnyRobot,
    Augmentation,
    AugmentationUsed,
    E2SynthesisAugmentation,
    FormulaMapAugmentation,
    FormulaRobot,
    PlanarChainRobot,
    Robot,
    RobotUsed,
    UnitsInfo,
    UrdfRobot,
    UserAugmentation,
)
from .runs import (
    LimitsInfo,
    LimitViolationInfo,
    RepeatabilityBody,
    RepeatabilityRequest,
    RepeatabilityResponse,
    Sentence,
    SolveBody,
    SolveRequest,
    SolveResponse,
    Trajectory,
)
from .synthesis import (
    METHODS,
    FunctionalInfo,
    MapSingularitiesInfo,
    SynthesisGrid,
    SynthesisMethod,
    SynthesisMethodsResponse,
    SynthesizeBody,
    SynthesizeRequest,
    SynthesizeResponse,
    TotalDegreeInfo,
)
from .variants import per_robot
