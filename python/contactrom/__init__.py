"""contactrom: projection-based reduced-order models of contact problems.

The classes and functions are those of the C++ library (module ``_contactrom``);
see docs/python.md. Bad input raises ValueError with the one-line message the
command-line tool prints; a solver that returns no solution at all raises
RuntimeError; numerical non-convergence is a ``status`` of the result.
"""
from ._contactrom import __version__  # the C++ library's version
from ._contactrom import (
    FallbackModel,
    FomSolution,
    FullOrderSolver,
    Problem,
    ReducedModel,
    RomSolution,
    SnapshotDatabase,
    SparseResult,
    adaptive_options,
    focuss,
    load_database,
    nnfocuss,
    nnls,
    offline,
    offline_adaptive,
    omp,
    online_methods,
    problem,
    verify,
)

__all__ = [
    "FallbackModel",
    "FomSolution",
    "FullOrderSolver",
    "Problem",
    "ReducedModel",
    "RomSolution",
    "SnapshotDatabase",
    "SparseResult",
    "adaptive_options",
    "focuss",
    "load_database",
    "nnfocuss",
    "nnls",
    "offline",
    "offline_adaptive",
    "omp",
    "online_methods",
    "problem",
    "verify",
]
