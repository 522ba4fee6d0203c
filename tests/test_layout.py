"""The named layouts of kernels/layout.py: the kernels read each body column where its name says, the scenes
name the columns the same way, and a named column compiles to the same machine code as a literal index."""

from __future__ import annotations

import re
from fractions import Fraction

import numba
import numpy as np
import pytest
from numba import types

from stabmap import kernels
from stabmap.kernels import layout
from stabmap.systems.gyroscopes.parameters import BODY_COLUMNS
from stabmap.systems.gyroscopes.points import chain_positions


def test_the_scenes_name_the_columns_as_the_kernels_do():
    assert BODY_COLUMNS is layout.BODY_COLUMNS
    named = dict(zip(("m", "A", "C", "c", "s", "omega"), (layout.M, layout.A, layout.C, layout.CM, layout.S, layout.OMEGA)))
    assert [BODY_COLUMNS[col] for col in named.values()] == list(named)
    assert sorted(named.values()) == list(range(layout.NBODY))
    assert layout.OMEGA not in layout.STRUCTURE and len(layout.STRUCTURE) == layout.NBODY - 1


@pytest.mark.parametrize("c", [0.125, -0.25])  # standing and hanging top
def test_one_top_reads_each_column_by_its_name(c):
    """A Lagrange top on a fixed point: p(lambda) = (A + m c^2) lambda^2 + C omega lambda + g m c - K_0 (docs/model.md,
    n = 1 without liquid), in exact rationals.  The columns are filled by name with values no two alike, so reading
    any column at another's index breaks the enclosure."""
    values = {"m": 1.5, "A": 0.02, "C": 0.035, "c": c, "s": 0.7, "omega": 40.0}
    body = np.empty((1, 1, layout.NBODY))
    for name, v in values.items():
        body[0, 0, layout.BODY_COLUMNS.index(name)] = v
    g, K0 = 9.81, 3.0
    joint, at = np.array([[K0]]), chain_positions(body)
    out = np.empty((1, 3, 3))
    kernels.charpoly_block(body, joint, np.array([g]), np.zeros((1, 1, 1)), np.ones((1, 1, 1)), np.zeros(1, np.int64), False,
                           np.array([-1]), at, out)
    m, A, C, cm, w = (Fraction(values[k]) for k in ("m", "A", "C", "c", "omega"))
    expected = [Fraction(g) * m * cm - Fraction(K0), C * w, A + m * cm * cm]
    for (hi, lo, rad), e in zip(out[0], expected):
        mid = Fraction(hi) + Fraction(lo)
        assert mid - Fraction(rad) <= e <= mid + Fraction(rad)


def _code(f, sig):
    """Machine code of ``f`` without its own name and the assembler's directives."""
    text = re.sub(r"[\w.$]*" + f.__name__ + r"[\w.$]*", "F", numba.njit(sig)(f).inspect_asm(sig))
    return [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith((".", "#"))]


def _named(body, k):
    return body[k, layout.OMEGA] * body[k, layout.C]


def _literal(body, k):
    return body[k, 5] * body[k, 2]


def _other(body, k):
    return body[k, 4] * body[k, 2]


def test_a_named_column_compiles_to_a_constant_index():
    """numba freezes a module's int into the code: ``body[k, OMEGA]`` is ``body[k, 5]``, instruction for
    instruction (and another column is not)."""
    sig = (types.float64[:, ::1], types.int64)
    named = _code(_named, sig)
    assert named == _code(_literal, sig)
    assert named != _code(_other, sig)


def test_the_workspaces_are_named():
    nmodes, parent = np.array([1, 0]), np.array([-1, 0])
    ws = kernels.certify.allocate(2, nmodes, parent)
    assert type(ws) is layout.CertifyWork and type(ws.pws) is layout.PencilWork and type(ws.aw) is layout.AllatonceWork
    assert ws.state.shape == (layout.CERTIFY_STATE,) and ws.aw.state.shape == (layout.ALLATONCE_STATE,)
    assert ws.costs[layout.WARM_HITS] == 1.0 and ws.costs[layout.WARM_COST] == ws.costs[layout.COLD_COST] == 0.0
    degree = int((nmodes + 2).sum())
    assert ws.C.shape == (degree, degree) and ws.pws.beta.shape == (2, 2, 1)
    assert type(kernels.charpoly.allocate(2, 1, degree, parent)) is layout.CharpolyWork
