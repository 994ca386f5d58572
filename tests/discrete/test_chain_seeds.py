"""``Chain.from_sections_seeds``: bit for bit the chains of ``Chain.from_sections``.

The batch builder draws only the disorder's factors per seed on geometry built once;
every array (masses, Hertz constants, static overlaps, diameters) and the ``params``
must equal those of ``from_sections`` with the seed set (``array_equal``: no
tolerance), in the fast path and in the fallbacks (diameter disorder, gravity).
"""

import numpy as np
import pytest

import theory
from discrete import Chain, Disorder, Periodic, Section

STEEL = theory.Material(7800.0, 2e11, 0.3)
GLASS = theory.Material(2500.0, 6e10, 0.22)


def _with_seed(sections, i, seed):
    out = list(sections)
    d = out[i].disorder
    out[i] = Section(out[i].n, out[i].diameter, out[i].material, out[i].profile,
                     Disorder(d.mass, d.stiffness, d.diameter, seed))
    return out


CASES = [
    ([Section(40, 5e-3, STEEL, disorder=Disorder(mass=0.1, stiffness=0.05))], 0,
     {"delta0": 5e-6}),
    ([Section(40, 5e-3, STEEL, disorder=Disorder(mass=0.2))], 0,
     {"delta0": 0.0, "left_wall": None, "right_wall": None}),
    ([Section(10, 5e-3, STEEL),  # an interface on both sides of the disordered section
      Section(30, 4e-3, GLASS, profile=Periodic(((1.0, None), (0.8, STEEL))),
              disorder=Disorder(mass=0.1, stiffness=0.1)),
      Section(5, 5e-3, STEEL)], 1, {"wall_force": 2.0, "right_wall": "hertz"}),
    ([Section(30, 5e-3, STEEL, disorder=Disorder(mass=0.1, diameter=0.05))], 0,
     {"delta0": 5e-6}),  # diameters change: the fallback
    ([Section(30, 5e-3, STEEL, disorder=Disorder(mass=0.1, stiffness=0.1))], 0,
     {"gravity": 9.81, "wall_force": 0.0, "left_wall": None}),  # gravity: the fallback
    ([Section(30, 5e-3, STEEL, disorder=Disorder(mass=0.1, stiffness=0.1))], 0,
     {"delta0": 5e-6, "exponent": 1.0}),  # another exponent of the static overlaps
]


@pytest.mark.parametrize("sections, i, kw", CASES)
def test_bitwise_equal_to_from_sections(sections, i, kw):
    seeds = [0, 7, 123456]
    batch = Chain.from_sections_seeds(sections, seeds, section=i, **kw)
    assert len(batch) == len(seeds)
    for seed, c in zip(seeds, batch, strict=True):
        ref = Chain.from_sections(_with_seed(sections, i, seed), **kw)
        for name in ("mass", "k", "delta0", "diameter", "section"):
            assert np.array_equal(getattr(c, name), getattr(ref, name)), (seed, name)
        assert c.params == ref.params
    assert not np.array_equal(batch[0].mass, batch[1].mass)  # the seeds differ


def test_bad_section():
    secs = [Section(10, 5e-3, STEEL), Section(10, 5e-3, STEEL, disorder=Disorder(mass=0.1))]
    assert len(Chain.from_sections_seeds(secs, [1, 2])) == 2  # the only disordered one
    with pytest.raises(ValueError, match="section must be the index"):
        Chain.from_sections_seeds(secs, [1], section=0)
    with pytest.raises(ValueError, match="section must name"):
        Chain.from_sections_seeds(secs[:1], [1])
