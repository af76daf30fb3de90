"""Your own finite-element model: matrices in, clearance joints between DOFs, reduction.

``from_matrices`` (matrices.py) checks M, C, K and the joints and returns the
:class:`~clearjoint.system.VibrationSystem` every solver takes; ``reduce``
(reduction.py) is the Craig-Bampton reduction onto the joints, with ``expand`` back to
every DOF and ``check`` of its modes against the full model's; ``read_matrix``
(readers.py) reads Matrix Market, MATLAB, Abaqus and OP4 files, and a model TOML
names them (model_file.py; ``clearjoint.structure.read_model`` reads one);
``from_opensees`` (opensees.py) pulls the matrices of the model defined in OpenSees.
"""

from clearjoint.structure.fe.matrices import FEModelError, MatrixModel, from_matrices
from clearjoint.structure.fe.opensees import from_opensees
from clearjoint.structure.fe.readers import read_matrix
from clearjoint.structure.fe.reduction import ReducedSystem, ReductionCheck, reduce

__all__ = [
    "FEModelError",
    "MatrixModel",
    "ReducedSystem",
    "ReductionCheck",
    "from_matrices",
    "from_opensees",
    "read_matrix",
    "reduce",
]
