"""Request and response models of the REST API (JSON, snake_case), one module per job.

- :mod:`.fields`: the shared field types and size limits;
- :mod:`.robots`: the robots and augmenting maps (generated from the engine's catalogue, and the
  robots a user defines), as requests name them and responses echo them;
- :mod:`.variants`: a request model made exact for each robot (what a route takes);
- :mod:`.runs`: ``/solve`` and ``/repeatability``; :mod:`.synthesis`: ``/synthesize``;
- :mod:`.info`: ``/robots``, ``/health`` and the error body.

What the other modules use is re-exported here, by the imports below: ``from jik.app.compute
import schemas as S`` (``pyproject.toml`` lets ruff keep them unused here); the rest is imported
from its module.
"""

from ....engine.solve_rules import Mode
from .algorithms import Algorithm
from .fields import (
    INTEGRAL,
    MAX_DIMENSION,
    MAX_ITERATIONS_CAP,
    MAX_TRAJECTORY_POINTS,
    Coordinate,
    FreeObject,
    Gamma,
    MaybeFloat,
    Tolerance,
    Vector,
)
from .info import (
    BUSY,
    AlgorithmInfo,
    ErrorResponse,
    HealthResponse,
    Limits,
    RobotInfo,
    RobotsResponse,
)
from .robots import (
    AUGMENTATION_MODELS,
    ROBOT_MODELS,
    ROBOT_NAMES,
    USER_AUGMENTATION_MODELS,
    USER_ROBOT_MODELS,
    AnyAugmentation,
    AnyRobot,
    AugmentationUsed,
    RobotUsed,
    UnitsInfo,
)
from .runs import (
    RepeatabilityBody,
    RepeatabilityRequest,
    RepeatabilityResponse,
    Sentence,
    SolveBody,
    SolveRequest,
    SolveResponse,
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
