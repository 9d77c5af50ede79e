"""The library's enumerations as names: the tables that map option strings to C enum values."""
from __future__ import annotations

from typing import Any, Dict

from ._lib import lib
from ._util import bad

#: ``method``: how the scales are selected (C ``amscr_method``).
METHODS: Dict[str, int] = {
    'acma': lib.AMSCR_METHOD_ACMA, 'amscr': lib.AMSCR_METHOD_AMSCR,
    'binary-em': lib.AMSCR_METHOD_BINARY_EM, 'multiclass-em': lib.AMSCR_METHOD_MULTICLASS_EM}
#: ``parametrization``: how the curve is sampled (C ``amscr_parametrization``).
PARAMETRIZATIONS: Dict[str, int] = {
    'affine': lib.AMSCR_PARAM_AFFINE, 'euclidean': lib.AMSCR_PARAM_EUCLIDEAN,
    'whitened': lib.AMSCR_PARAM_WHITENED}
#: ``invariance``: the group of maps the distance ignores (C ``amscr_invariance``).
INVARIANCES: Dict[str, int] = {
    'affine': lib.AMSCR_INVARIANCE_AFFINE, 'similarity': lib.AMSCR_INVARIANCE_SIMILARITY,
    'penalized': lib.AMSCR_INVARIANCE_PENALIZED}

#: which scores params rank a collection by (C ``amscr_ranking``, :attr:`Params.ranking`).
RANKINGS: Dict[str, int] = {'distance': lib.AMSCR_RANKING_DISTANCE, 'retrieval': lib.AMSCR_RANKING_RETRIEVAL}


def enum_in(table: Dict[str, int], value: Any, what: str) -> int:
    """The C value of the name `value` ('Binary_EM' and 'binary-em' are the same name)."""
    if isinstance(value, str):
        key = value.strip().lower().replace('_', '-')
        if key in table:
            return table[key]
    raise bad('%s: expected one of %s, got %r' % (what, ', '.join(repr(k) for k in table), value))


def enum_out(table: Dict[str, int], value: int) -> str:
    """The name of the C value `value` (its decimal digits when the table has no name for it)."""
    for k, v in table.items():
        if v == int(value):
            return k
    return str(int(value))
