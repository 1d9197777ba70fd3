"""Case files: a researcher's own problem described in TOML and run by ``fenicsfriction run``.

:func:`read_case` reads and checks a file (:mod:`~fenicsfriction.case.schema`, no dolfinx),
:class:`CaseModel` builds its finite element model (:mod:`~fenicsfriction.case.model`) and
:func:`run_case` runs its analyses (:mod:`~fenicsfriction.case.analyses`). Every key is
documented in docs/case-files.md.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Case": "schema", "CaseError": "schema", "read_case": "schema",
    "CaseModel": "model", "Outcome": "analyses", "run_case": "analyses"})

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.case.analyses import Outcome, run_case
    from fenicsfriction.case.model import CaseModel
    from fenicsfriction.case.schema import Case, CaseError, read_case
