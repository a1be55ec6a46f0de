"""ROS-free physics of the notched TD-CM (never imports rclpy).

Typical use::

    from tdcm_ros.model import preset, solve
    result = solve(preset("paper-experiment"), 20.0)
    result.tip_position  # m, frame tdcm_base
    solve_inverse(preset("paper-experiment"), tip_angle=0.3).tension_n  # N

Separate entry points, kept out of this face because they pull scipy:
:mod:`tdcm_ros.model.baselines` (the other models, by name) and :mod:`tdcm_ros.model.accuracy`
(the accuracy/speed benchmark behind ``tdcm bench``).
"""

from tdcm_ros.model.body_file import (
    BodySpec,
    body_file_text,
    body_from_mapping,
    is_body_file,
    named_design,
    read_body_file,
)
from tdcm_ros.model.compiled import one_shot, use_compiled
from tdcm_ros.model.design import (
    FIELD_SPECS,
    PARAMETER_SPECS,
    PRESETS,
    Design,
    parameter_specs,
    parse_field,
    preset,
)
from tdcm_ros.model.design_sampling import FREE_FIELDS, SAMPLINGS, candidate
from tdcm_ros.model.design_space import (
    DEFAULT_ALLOWABLE_STRAIN,
    STATUSES,
    DesignSpace,
    design_curves,
    sweep,
)
from tdcm_ros.model.design_variables import Variable, VariableSet
from tdcm_ros.model.errors import (
    InvalidDesignError,
    InvalidSettingsError,
    ModelError,
    ModelLimitError,
    NotchClosureError,
    StrainLimitError,
    TendonSingularityError,
    TensionRangeError,
)
from tdcm_ros.model.friction import (
    FrictionState,
    FrictionTrack,
    StickSlipTension,
    check_mu,
)
from tdcm_ros.model.inverse import (
    DEFAULT_TENSION_MAX_N,
    DEFAULT_TOL,
    InvalidTargetError,
    InverseResult,
    Sensitivity,
    UnreachableTargetError,
    solve_inverse,
)
from tdcm_ros.model.inverse_design import (
    DEFAULT_DESIGN_LADDER,
    DEFAULT_DESIGN_SAMPLES,
    DEFAULT_TENSION_BUDGET_N,
    DesignSearch,
    NoDesignMeetsTargetError,
    search_designs,
)
from tdcm_ros.model.limits import check_tension
from tdcm_ros.model.loading import (
    MAX_MU,
    Capstan,
    InvalidLoadingError,
    Loading,
    NotchContact,
    TensionProfile,
)
from tdcm_ros.model.markers import MARKER_SPECS, MarkerLayout
from tdcm_ros.model.mesh_export import (
    InvalidExportError,
    mesh_body_file_text,
    write_body_stl,
)
from tdcm_ros.model.model_file import ModelSpec, read_model
from tdcm_ros.model.outline import BodyOutline, body_outline
from tdcm_ros.model.profiles import (
    PROFILE_NAMES,
    CircularProfile,
    CustomProfile,
    PolygonProfile,
    RectangularProfile,
)
from tdcm_ros.model.progress import Progress, report_progress, within
from tdcm_ros.model.result import ConvergenceError, SolveResult
from tdcm_ros.model.roll import (
    InvalidRollError,
    RollHistory,
    StampedHistory,
    check_roll,
    depends_on_roll,
    roll_loading,
    roll_points,
    roll_poses,
    roll_quaternions,
)
from tdcm_ros.model.settings import SOLVER_SPECS, SolverSettings
from tdcm_ros.model.shape_file import ShapeFile, problem_from_mapping, read_problem_file
from tdcm_ros.model.shape_problem import Evaluation, Goal, Load, ShapeProblem
from tdcm_ros.model.shape_search import (
    NoShapeDesignError,
    ShapeDesign,
    design_for_shape,
)
from tdcm_ros.model.shape_targets import (
    CurveTarget,
    Limits,
    NotchAngleTarget,
    StopAngleTarget,
    TipTarget,
)
from tdcm_ros.model.solver import DEFAULT_SETTINGS, solve, warm_up
from tdcm_ros.model.surface import offset_points, surface_points
from tdcm_ros.model.tendons import Tendon, require_paper_tendon
from tdcm_ros.model.uncertainty import (
    MU,
    InvalidUncertaintyError,
    ParameterCovariance,
    band_half_widths,
    fittable_names,
    inside_band,
    linearised_covariances,
    prediction_covariances,
)
from tdcm_ros.model.urdf import body_urdf, body_xacro, joint_names, joint_positions

__all__ = [
    "DEFAULT_ALLOWABLE_STRAIN",
    "DEFAULT_DESIGN_LADDER",
    "DEFAULT_DESIGN_SAMPLES",
    "DEFAULT_SETTINGS",
    "DEFAULT_TENSION_BUDGET_N",
    "DEFAULT_TENSION_MAX_N",
    "DEFAULT_TOL",
    "FIELD_SPECS",
    "FREE_FIELDS",
    "MARKER_SPECS",
    "MAX_MU",
    "MU",
    "PARAMETER_SPECS",
    "PRESETS",
    "PROFILE_NAMES",
    "SAMPLINGS",
    "SOLVER_SPECS",
    "STATUSES",
    "BodyOutline",
    "BodySpec",
    "Capstan",
    "CircularProfile",
    "ConvergenceError",
    "CurveTarget",
    "CustomProfile",
    "Design",
    "DesignSearch",
    "DesignSpace",
    "Evaluation",
    "FrictionState",
    "FrictionTrack",
    "Goal",
    "InvalidDesignError",
    "InvalidExportError",
    "InvalidLoadingError",
    "InvalidRollError",
    "InvalidSettingsError",
    "InvalidTargetError",
    "InvalidUncertaintyError",
    "InverseResult",
    "Limits",
    "Load",
    "Loading",
    "MarkerLayout",
    "ModelError",
    "ModelLimitError",
    "ModelSpec",
    "NoDesignMeetsTargetError",
    "NoShapeDesignError",
    "NotchAngleTarget",
    "NotchClosureError",
    "NotchContact",
    "ParameterCovariance",
    "PolygonProfile",
    "Progress",
    "RectangularProfile",
    "RollHistory",
    "Sensitivity",
    "ShapeDesign",
    "ShapeFile",
    "ShapeProblem",
    "SolveResult",
    "SolverSettings",
    "StampedHistory",
    "StickSlipTension",
    "StopAngleTarget",
    "StrainLimitError",
    "Tendon",
    "TendonSingularityError",
    "TensionProfile",
    "TensionRangeError",
    "TipTarget",
    "UnreachableTargetError",
    "Variable",
    "VariableSet",
    "band_half_widths",
    "body_file_text",
    "body_from_mapping",
    "body_outline",
    "body_urdf",
    "body_xacro",
    "candidate",
    "check_mu",
    "check_roll",
    "check_tension",
    "depends_on_roll",
    "design_curves",
    "design_for_shape",
    "fittable_names",
    "inside_band",
    "is_body_file",
    "joint_names",
    "joint_positions",
    "linearised_covariances",
    "mesh_body_file_text",
    "named_design",
    "offset_points",
    "one_shot",
    "parameter_specs",
    "parse_field",
    "prediction_covariances",
    "preset",
    "problem_from_mapping",
    "read_body_file",
    "read_model",
    "read_problem_file",
    "report_progress",
    "require_paper_tendon",
    "roll_loading",
    "roll_points",
    "roll_poses",
    "roll_quaternions",
    "search_designs",
    "solve",
    "solve_inverse",
    "surface_points",
    "sweep",
    "use_compiled",
    "warm_up",
    "within",
    "write_body_stl",
]
