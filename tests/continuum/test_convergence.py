"""Measured convergence orders of the compiled (fused) continuum steppers, in h and in dt.

Problem: a precompressed (δ0/d = 1e-3) periodic chain of 12 grains carrying a smooth
two-mode wave (dynamic strain about 0.07 δ0: weakly nonlinear), run for the time sound
needs to cross 20 grains.  Errors are max |u - u'| at the grain centres (a node for
every odd n).  Every run goes through :func:`continuum.run` with the numba backend, i.e.
the fused chunks of :mod:`continuum._stepper` (asserted).

Measured on this problem:

* space, three grids n = 3, 9, 27 (Yoshida-4 at T/4000: time error ~5e-10 relative, ~2e-16 m,
  extrapolated from the measured fourth order below):
  |u_3 - u_9| and |u_9 - u_27| = 3.1e-10 and 3.9e-12 m for Eq. 7's fourth-order
  stencil (order 3.99), 2.1e-8 and 2.3e-9 m for its second-order one without the h²
  correction (1.98), 2.0e-8 and 2.3e-9 m for Eq. 4 without it (1.98);
* time, n = 5, T/200, T/400, T/800 against Blanes–Moan-4 at T/8000 (its own error
  ~1e-14 relative), relative to max |u| = 3.7e-7 m: Eq. 7 Verlet 5.3e-3, 1.3e-3,
  3.3e-4 (order 2.00), Yoshida-4 7.8e-5, 4.8e-6, 3.0e-7 (4.00), Blanes–Moan-4
  1.7e-8, 1.1e-9, 6.7e-11 (4.00); Eq. 4 Verlet 6.0e-3, 1.5e-3, 3.7e-4 (2.00),
  Yoshida-4 9.1e-5, 5.7e-6, 3.6e-7 (4.00), Blanes–Moan-4 2.0e-8, 1.3e-9, 7.9e-11
  (4.00).  Velocity Verlet (kick first) equals position Verlet's errors to 2 digits.

Tolerances: ±0.1 on the time orders (measured within 0.002 of 2 and 4), ±0.2 on the
space orders (measured within 0.02; the three-grid estimate carries the next-order
term).  The h²-corrected defaults are more accurate but of mixed order (Eq. 4: 2.5
here); Eq. 4's default is tested against the exact travelling wave in
``test_boussinesq.py`` (also through the fused path).
"""

import numpy as np
import pytest

import theory
from continuum import BoussinesqPDE, Medium, NesterenkoPDE, run
from continuum.solver import splitting_method

D0 = 1e-3 * theory.PAPER_DIAMETER
L = 12  # grains (periodic)


def _state(pde):
    x = pde.disc.x_nodes
    kx = 2 * np.pi / L
    u = 0.05 * D0 / kx * (np.sin(kx * x) + 0.5 * np.sin(2 * kx * x + 1.0))
    return pde.get_initial_condition(u, np.zeros_like(x))


def _pde(model, n, space_order=4, correct_h2=True):
    med = Medium.uniform(L, D0)
    if model == "eq4":
        return BoussinesqPDE(med, n, bc="periodic", correct_h2=correct_h2)
    return NesterenkoPDE(med, n, bc="periodic", delta_floor=0.0, space_order=space_order,
                         correct_h2=correct_h2)


def _t_end():
    pde = _pde("eq4", 1)
    c = np.sqrt(pde.disc.stiffness[0] / pde.disc.mass[0])  # grains/s
    return 20.0 / c


def _centres(model, n, steps, order, **kw):
    """u at the grain centres after the run (compiled path, ``steps`` steps).

    ``order``: 2 or 4 (the drift-first methods) or a method name of theory.splitting.
    """
    pde = _pde(model, n, **kw)
    t_end = _t_end()
    how = {"order": order} if isinstance(order, int) else {"method": order}
    res = run(pde, _state(pde), t_end, dt=t_end / steps, interval=t_end, **how)
    assert res["info"]["fused"]
    return np.asarray(res["state"][0].data)[(n - 1) // 2::n]


def _order(errors, sizes):
    return float(np.polyfit(np.log(sizes), np.log(errors), 1)[0])


@pytest.mark.parametrize(("model", "space_order", "expected", "tol"),
                         [("eq7", 4, 4.0, 0.2), ("eq7", 2, 2.0, 0.2), ("eq4", 2, 2.0, 0.2)])
def test_order_in_h(model, space_order, expected, tol):
    """Error ∝ h^p with p the stencil's order, from three grids n = 3, 9, 27 (h ratio 3):
    p = log(|u_3 - u_9| / |u_9 - u_27|) / log 3 (no reference solution needed).
    Measured: Eq. 7 fourth order 3.99, second order 1.98; Eq. 4 (plain) 2.0."""
    u = {n: _centres(model, n, 4000, 4, space_order=space_order, correct_h2=False)
         for n in (3, 9, 27)}
    e1, e2 = np.abs(u[3] - u[9]).max(), np.abs(u[9] - u[27]).max()
    p = np.log(e1 / e2) / np.log(3.0)
    assert abs(p - expected) < tol, (e1, e2, p)


@pytest.mark.parametrize("method", [2, 4, "verlet", "blanes_moan4"])
@pytest.mark.parametrize("model", ["eq4", "eq7"])
def test_order_in_dt(model, method):
    """Position Verlet (order 2), Yoshida-4 (order 4), and the kick-first velocity
    Verlet and Blanes–Moan-4 (FSAL-merged kicks) keep their order in the compiled
    chunks: error ∝ dt^order within ±0.1 (measured 2.00 and 4.00 for both equations)."""
    order = method if isinstance(method, int) else splitting_method(method).order
    ref = _centres(model, 5, 8000, "blanes_moan4")  # time error ~1e-14 relative
    steps = np.array([200, 400, 800])
    errs = [np.abs(_centres(model, 5, m, method) - ref).max() / np.abs(ref).max()
            for m in steps]
    p = _order(errs, 1.0 / steps)
    assert abs(p - order) < 0.1, (errs, p)
